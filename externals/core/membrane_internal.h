/* membrane_internal.h -- shared between membrane.c, contact.c and the kernels.
 * Not public API: the layout may change at any time. */
#ifndef ICTUS_MEMBRANE_INTERNAL_H
#define ICTUS_MEMBRANE_INTERNAL_H

#include <math.h>
#include "contact.h"
#include "membrane.h"

/* Arrays are padded to this many floats and aligned to 64 bytes so that the
 * kernels can run whole 8-wide vectors with no remainder loop. */
#define MEMBRANE_PAD 16

/* Arguments of one sample of the modal update (see membrane_kernel.inc). */
typedef struct membrane_kernel_args {
    int count; /* modes to update, a multiple of MEMBRANE_PAD */
    float *q, *p;
    const float *c1, *c2, *c3, *eq, *ep, *dm;
    const float *psi_strike;
    const float *psi_pick[MEMBRANE_PICKUPS];
    float strike_force; /* N, at the strike point, during this sample */
    int contacts;       /* contacts whose displacement is wanted */
    /* Per contact: eq * psi, ep * psi (input vectors) and dm * psi (displacement
     * weights), precomputed when the stroke or the coefficients change. */
    const float *contact_gq[MEMBRANE_MAX_CONTACTS], *contact_gp[MEMBRANE_MAX_CONTACTS];
    const float *contact_wd[MEMBRANE_MAX_CONTACTS];
    float contact_force_pending[MEMBRANE_MAX_CONTACTS]; /* last sample's forces, not yet in q, p */
    double pick_sum[MEMBRANE_PICKUPS];                  /* out: sum psi_pick * p */
    double contact_w[MEMBRANE_MAX_CONTACTS];            /* out: sum wd * q */
} membrane_kernel_args;

void membrane_kernel_generic(membrane_kernel_args *a);
void membrane_kernel_avx2(membrane_kernel_args *a);

struct contact {
    double mass_kg, stiffness, alpha, damping;
    membrane *owner;
    int slot; /* index in owner's contact table */
    /* Mode weights (mass-normalised shapes) at the stroke point, and at the
     * point of a hit that has not landed yet. Owned by the contact, sized by
     * the owner's capacity. */
    float *psi, *psi_next;
    float *gq, *gp, *wd; /* eq psi, ep psi, dm psi at the stroke point */
    int psi_cap;
    /* A hit waiting to land. */
    int hit_pending, hit_offset;
    double hit_velocity, hit_r, hit_theta;
    /* Stroke state (double: the contact law is stiff and nonlinear). */
    int active, touching, ever_touched;
    double r_over_a, theta_deg;
    double stick_x, stick_v; /* m, m/s, positive into the membrane */
    double compression;      /* m */
    double force;            /* N, during the last sample */
    double force_pending;    /* N, not yet added to the modal state */
    double self_compliance;  /* K = d w_c / d F over one sample (m/N) */
    double pick_coupling[MEMBRANE_PICKUPS];
    long stroke_samples;
    double first_touch, last_release; /* samples since the stroke began (interpolated) */
    double peak_force, impulse;
    int report_ready;
    contact_report report;
    float *force_out;
    int force_cap;
};

/* Benchmarks only: run the portable kernel even on an AVX2 machine. */
void membrane_use_generic_kernel_(membrane *m);

/* Internal membrane services used by contact.c. */
int membrane_capacity_(const membrane *m);
/* Fills psi[0 .. capacity) with the mass-normalised mode shapes at (r/a, theta). */
void membrane_mode_shapes_(const membrane *m, double r_over_a, double theta_deg, float *psi);
/* Discrete-gradient Hunt-Crossley force for a compression step x0 -> x1 (contact.c). */
double contact_force_law_(const contact *c, double x0, double x1, double dt);
/* Solves x1 = x_free - compliance * F(x0, x1) for the compression x1; returns F.
 * force_guess (e.g. the last sample's force, or 0) only speeds it up. */
double contact_solve_(const contact *c, double x0, double x_free, double compliance, double dt,
                      double force_guess, double *x1);

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
