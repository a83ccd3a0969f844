/* membrane_internal.h -- the membrane's internals shared with the modal kernels and
 * with what attaches to a membrane (contact.c). Not public API: the layout may
 * change at any time. Includes go one way: contact.c includes this file, the
 * membrane never includes contact.h (docs/externals.md, "Layout"). */
#ifndef ICTUS_MEMBRANE_INTERNAL_H
#define ICTUS_MEMBRANE_INTERNAL_H

#include <math.h>
#include "membrane.h"

/* Arrays are padded to this many floats and aligned to 64 bytes so that the
 * kernels can run whole 8-wide vectors with no remainder loop. */
#define MEMBRANE_PAD 16

/* Arguments of one sample of the modal update (see membrane_kernel.inc). */
typedef struct membrane_kernel_args {
    int count; /* modes to update, a multiple of MEMBRANE_PAD */
    /* r / sc and p / sc, sc = sqrt(cd) per mode (r = q / (h w'); membrane.c,
     * update_coefficients): in these coordinates a point's force goes in, and its
     * displacement comes out, through one array, psi sc (membrane_kernel.inc). */
    float *q, *p;
    const float *c1, *cd, *c3;
    const float *ep;   /* strike input gain, ep / sc = input_scale sc */
    float input_scale; /* scale h: ep = input_scale cd, w = input_scale sum psi r */
    const float *psi_strike;
    const float *psi_pick[MEMBRANE_PICKUPS];
    float strike_force; /* N, at the strike point, during this sample */
    int points;         /* coupling points whose displacement is wanted */
    /* Per point: its mode shapes times sc (psi_k), zero for fading modes. A force F
     * goes in as F input_scale psi cd into r and p, i.e. F input_scale psi_k into
     * r / sc and p / sc; the displacement is input_scale sum psi r = input_scale
     * sum psi_k (r / sc). The pickups' shapes come times sc too. */
    const float *point_psi[MEMBRANE_MAX_POINTS];
    float point_force_pending[MEMBRANE_MAX_POINTS]; /* last sample's forces, not yet in q, p */
    double pick_sum[MEMBRANE_PICKUPS];              /* out: sum psi_pick * p */
    double point_w[MEMBRANE_MAX_POINTS];            /* out: sum psi * r (unscaled) */
    /* out, membrane_kernel_pair_*: the second sample's sums (ringing freely). */
    double pick_sum2[MEMBRANE_PICKUPS];
} membrane_kernel_args;

void membrane_kernel_generic(membrane_kernel_args *a);
void membrane_kernel_avx2(membrane_kernel_args *a);
void membrane_kernel_pair_generic(membrane_kernel_args *a);
void membrane_kernel_pair_avx2(membrane_kernel_args *a);

/* Benchmarks only: run the portable kernel even on an AVX2 machine. */
void membrane_use_generic_kernel_(membrane *m);

/* ---------------------------------------------------------------- coupling points
 *
 * A coupling point is where an object attached to the membrane (a stick: contact.c)
 * exchanges a force with the modes, solved implicitly sample by sample
 * (docs/membrane.md, "The contact"). The membrane owns the mode-space side: the
 * shapes at the point, the couplings derived from them, and folding the force into
 * the modal state one sample late (the kernel does it). The object owns the force:
 * the membrane calls it through membrane_point_ops at fixed places of
 * membrane_process(), and never sees its type. */
typedef struct membrane_point membrane_point;

typedef struct membrane_point_ops {
    /* A pending move has just landed (membrane_point_move_): the point is at its
     * new place, displacement_m is the membrane's displacement there. */
    void (*landed)(membrane_point *pt, double displacement_m);
    /* Solves the forces of the `count` active points for sample `sample` together:
     * w_free[i] is point i's displacement without this sample's forces, and
     * K[i][j] the change of w_i per newton of F_j over the sample. Sets each
     * point's force_pending (N, over this sample) and adds force * pick_coupling
     * into extra (the forces' direct path to the pickups). The points of one
     * membrane are solved by the first one's ops: they couple through the modes,
     * so a joint solve needs them all (every point is a contact today). */
    void (*solve)(membrane_point *const *pts, int count, const double *w_free,
                  const double (*K)[MEMBRANE_MAX_POINTS], double dt, int sample,
                  double extra[MEMBRANE_PICKUPS]);
    /* A block of n samples begins (once per point per membrane_process() call). */
    void (*block_begin)(membrane_point *pt, int n);
    /* membrane_clear() ran: the pending move and force are gone already. */
    void (*cleared)(membrane_point *pt);
    /* The point has just been detached from its membrane. */
    void (*detached)(membrane_point *pt);
} membrane_point_ops;

struct membrane_point {
    const membrane_point_ops *ops;
    membrane *owner; /* NULL while detached */
    int slot;        /* index in the owner's table */
    /* Mode weights (mass-normalised shapes, zero for fading modes) at the point and
     * at the place of a pending move. Allocated by the membrane at its capacity
     * (psi_cap floats each), freed by membrane_point_free_. */
    float *psi, *psi_next;
    /* psi sc (membrane.c): the kernel's copy, in the coordinates of its stored state. */
    float *psi_k;
    int psi_cap;
    double r_over_a, theta_deg;
    /* A move waiting to land move_offset samples into the next membrane_process(). */
    int move_pending, move_offset;
    double move_r, move_theta;
    int active;             /* set by the object: solve this point every sample */
    double force_pending;   /* N, the last force, not yet added to the modal state */
    double self_compliance; /* K = d w / d F over one sample (m/N) */
    double pick_coupling[MEMBRANE_PICKUPS];
};

/* Attaches pt (ops set, arrays NULL or from an earlier attach) to m: computes its
 * shapes and couplings; detaches it from another membrane first. ICTUS_OK when it
 * was attached already; ICTUS_ENOMEM when m's table is full or memory cannot be had.
 * Allocates. */
ictus_status membrane_point_attach_(membrane *m, membrane_point *pt);
/* Detaches pt if it is attached to m, folding its pending force into the modes. */
void membrane_point_detach_(membrane *m, membrane_point *pt);
/* Detaches pt from its membrane, if any, and frees its arrays. */
void membrane_point_free_(membrane_point *pt);
/* Asks for pt to move to (r/a, theta) `sample_offset` samples into the next
 * membrane_process() call (later blocks when past it); the shapes of the new place
 * are computed here, in the message handler, when pt is attached. */
void membrane_point_move_(membrane_point *pt, double r_over_a, double theta_deg, int sample_offset);

/* Clamps *v into [lo, hi]; NaN becomes `fallback`. ICTUS_CLAMPED when *v changed.
 * Every setter of the core validates through this one rule. */
static inline ictus_status ictus_clamp(double *v, double lo, double hi, double fallback)
{
    if (isnan(*v)) {
        *v = fallback;
        return ICTUS_CLAMPED;
    }
    if (*v < lo) {
        *v = lo;
        return ICTUS_CLAMPED;
    }
    if (*v > hi) {
        *v = hi;
        return ICTUS_CLAMPED;
    }
    return ICTUS_OK;
}

#endif
