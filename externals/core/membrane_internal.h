/* membrane_internal.h -- the membrane's internals shared with the modal kernels and
 * with what attaches to a membrane (contact.c). Not public API: the layout may
 * change at any time. Includes go one way: contact.c includes this file, the
 * membrane never includes contact.h (docs/externals.md, "Layout"). */
#ifndef ICTUS_MEMBRANE_INTERNAL_H
#define ICTUS_MEMBRANE_INTERNAL_H

#include <math.h>
#include "ictus_clamp.h"
#include "membrane.h"
#include "mode_table.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Arrays are padded to this many floats and aligned to 64 bytes so that the
 * kernels can run whole pairs of 16-wide vectors with no remainder loop. */
#define MEMBRANE_PAD 32

/* Arguments of one sample of the modal update (see membrane_kernel.inc). */
typedef struct membrane_kernel_args {
    int count; /* modes to update, a multiple of MEMBRANE_PAD */
    /* r / sc and p / sc, sc = sqrt(cd) per mode (r = q / (h w'); membrane_modes.c,
     * membrane_update_coefficients_): in these coordinates a point's force goes in, and its
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

/* Arguments of the tension update's rebuild (membrane_kernel.inc, membrane_modes.c): the
 * coefficients of the sounding modes at w' = g wm0, the state converted so that each
 * mode's energy is kept and the pickups' shapes in the new sc, in one pass; and of the
 * couplings kernel: the points' shapes in sc and their sums over sc and ep. */
typedef struct membrane_tension_args {
    int count;       /* lanes to run, a multiple of MEMBRANE_PAD */
    int live;        /* modes below this whose wm is > 0 are rebuilt (the sounding ones) */
    float g, h, ept; /* frequency factor, T / 2, scale T (ep = scale T / D) */
    const float *wm0, *sm0;
    float *wm; /* w' now (0: silent), in and out */
    float *q, *p, *c1, *cd, *c3, *ep, *sc, *ep_k;
    const float *psi_pick[MEMBRANE_PICKUPS];
    float *pick_k[MEMBRANE_PICKUPS]; /* out: psi_pick sc */
    int points;
    const float *psi[MEMBRANE_MAX_POINTS];
    float *psi_k[MEMBRANE_MAX_POINTS];                           /* out: psi sc */
    double self_sum[MEMBRANE_MAX_POINTS];                        /* out: sum psi^2 ep */
    double pick_coupling[MEMBRANE_MAX_POINTS][MEMBRANE_PICKUPS]; /* out: sum psi_pick psi ep */
} membrane_tension_args;

void membrane_kernel_generic(membrane_kernel_args *a);
void membrane_kernel_avx2(membrane_kernel_args *a);
void membrane_kernel_pair_generic(membrane_kernel_args *a);
void membrane_kernel_pair_avx2(membrane_kernel_args *a);
void membrane_tension_kernel_generic(membrane_tension_args *a);
void membrane_tension_kernel_avx2(membrane_tension_args *a);
void membrane_couplings_kernel_generic(membrane_tension_args *a);
void membrane_couplings_kernel_avx2(membrane_tension_args *a);
void membrane_kernel_avx512(membrane_kernel_args *a);
void membrane_kernel_pair_avx512(membrane_kernel_args *a);
void membrane_tension_kernel_avx512(membrane_tension_args *a);
void membrane_couplings_kernel_avx512(membrane_tension_args *a);
/* Energy (J) of modes 0 .. live-1 from the stored state: sum (h wm sc q)^2 + (sc p)^2, / 2. */
double membrane_energy_kernel_generic(const float *q, const float *p, const float *wm,
                                      const float *sc, float h, int live);
double membrane_energy_kernel_avx2(const float *q, const float *p, const float *wm, const float *sc,
                                   float h, int live);
double membrane_energy_kernel_avx512(const float *q, const float *p, const float *wm,
                                     const float *sc, float h, int live);

/* Run the kernels of this level (ictus_simd.h): membrane_new() picks the widest the CPU
 * runs; tests and benchmarks compare the others. A level this build or CPU lacks is not
 * checked here: ask ictus_simd_level() first. */
void membrane_use_kernel_(membrane *m, int level);
/* Benchmarks only: run the portable kernel even on an AVX2 machine. */
void membrane_use_generic_kernel_(membrane *m);

/* ---------------------------------------------------------------- the membrane
 *
 * Its rooms: membrane.c (life cycle, pickups, the processing loop, read-back),
 * membrane_modes.c (mode arrays and coefficients), membrane_points.c (strikes and
 * coupling points), membrane_params.c (the one-number parameters). */

#define STRIKE_QUEUE  64
#define FADE_S        0.03 /* s: ring-out of modes dropped by membrane_set_modes() */
#define IMPULSE_CACHE 4

typedef struct pending_strike {
    double r_over_a, theta_deg, impulse_ns;
    int offset;
} pending_strike;

typedef struct impulse_shape {
    double r_over_a, theta_deg;
    int valid;
    float *psi;
} impulse_shape;

typedef struct membrane_point membrane_point;

/* Tension modulation: the frequency factor is recomputed from the modal energy every
 * TM_INTERVAL samples of absolute time (block-size independent), and the coefficients
 * rebuilt when it moved by more than TM_THRESHOLD (relative; 0.035 cent). */
#define TM_INTERVAL  128
#define TM_THRESHOLD 2.0e-5
#define TM_G_MAX     2.0 /* frequency factor cap: tension at most 4 T0 */

/* The energy cascade (membrane_band_cascade.c): updated every BC_INTERVAL samples of
 * absolute time (block-size independent), over bands a third of an octave wide. */
#define BC_INTERVAL 32
/* A drum head's: its rate changes with the tension's (TM_INTERVAL); at ff it can exceed
 * 1 / (128 samples), and each update then equalises the pairs it relaxes. */
#define BC_DRUM_INTERVAL 128
#define BC_MAX_BANDS     64

struct membrane {
    double sample_rate, radius, tension, density, t60, hf_damping, output_gain;
    double tension_mod;            /* dimensionless, MEMBRANE_PARAM_TENSION_MOD */
    double radiation, loss_factor; /* MEMBRANE_PARAM_RADIATION, MEMBRANE_PARAM_LOSS_FACTOR */
    double air_mass;               /* MEMBRANE_PARAM_AIR_MASS (table.scale carries it) */
    double patch;                  /* m, MEMBRANE_PARAM_PATCH */
    /* A free-edge plate instead of a membrane (membrane_set_plate): its modes are the
     * plate's (mode_table.h) and ring at j c / (2 pi a) with c = sqrt(bending / density)
     * / a, bending its bending stiffness D (N m, MEMBRANE_PARAM_BENDING); the tension,
     * the tension modulation, the air radiation and the contact patch are a membrane's
     * and do nothing. */
    int plate;
    double bending;
    /* The energy cascade of a plate or a head (membrane_band_cascade.c,
     * MEMBRANE_PARAM_CASCADE): its amount, whether the loop runs it, the samples to its next
     * update and between two (absolute time), its bands of modes (set at message time: band b
     * holds modes bc_start[b] .. bc_start[b + 1] - 1) and, for a plate, Gamma per unit of
     * sum e_k / w_k (1/(J s^2)); a head's rate reads the tension modulation's tm_g. */
    double cascade;
    int bc_on, bc_countdown, bc_bands, bc_interval;
    int bc_start[BC_MAX_BANDS + 1];
    double bc_e[BC_MAX_BANDS], bc_gamma_per_ew, bc_dt;
    /* A plate's von Karman coupling of its lowest modes (membrane_cascade.c,
     * MEMBRANE_PARAM_VON_KARMAN): the factor on E h, the coupling built at message time,
     * and whether the processing loop runs it. */
    double von_karman;
    /* A hi-hat's second plate (MEMBRANE_PARAM_OPENNESS, MEMBRANE_PARAM_EDGE_DAMP): the
     * loss it puts on the edge, in each mode's decay rate (membrane_modes.c). */
    double openness, edge_damp;
    struct plate_cascade *pc;
    int vk_on;
    /* The radiation integral of each mode depends on ka = j c / c_air alone: kept for
     * rad_valid modes at the wave speed rad_c (recomputed when either changes). */
    double *rad_int, rad_c;
    int rad_valid;
    double tm_g;          /* frequency factor sqrt(T / T0) in the coefficients now */
    int tm_countdown;     /* samples until the next tension update */
    double gain_smoothed; /* output gain as applied, follows output_gain in ~5 ms */
    int modes;            /* requested mode count */
    /* After the count shrinks, the dropped modes ring out over FADE_S (no input,
     * T60 of FADE_S) before they go: modes .. fading_modes-1, fade_left samples. */
    int fading_modes;
    long fade_left;
    int count;    /* modes rounded up to MEMBRANE_PAD: the kernel's loop length */
    int capacity; /* floats allocated per array */
    /* Mode table, capacity entries; entries >= modes are padding. */
    mode_table table;
    mode_tuning tuning;  /* frequency and decay corrections (count 0: the ideal membrane) */
    double *omega_model; /* model stiffness w' per mode (0: silent) */
    /* w' and the damping s' of each mode at the base tension T0 (float, for the
     * tension update's vector loop); w' = tm_g wm0 for the sounding modes. wm is
     * omega_model in float (0: silent), what the tension update reads and writes. */
    float *wm0, *sm0, *wm;
    /* SoA float state and coefficients (see membrane_kernel.inc): q holds the
     * scaled displacement r = q / (h w'), h = T / 2 (the energy coordinate q is
     * h w' r); cd = 2 / D is r's coefficient of p; ep the input gain of both. */
    float *q, *p, *c1, *cd, *c3, *ep;
    /* The kernel's coordinates: q and p above hold r / sc and p / sc, sc = sqrt(cd)
     * (0 for silent modes); ep_k = ep / sc, pick_k = psi_pick sc, and each point's
     * psi_k = psi sc (membrane_kernel.inc). */
    float *sc, *ep_k, *pick_k[MEMBRANE_PICKUPS];
    double coef_h; /* h of the coefficients (and of r) now in place */
    /* The tension update changed sc and ep since the points' couplings (psi_k,
     * self_compliance, pick_coupling) were computed: they are brought up to date before
     * a point next takes part in a sample (membrane_refresh_point_couplings_). */
    int couplings_stale;
    float *psi_strike, *psi_pick[MEMBRANE_PICKUPS];
    /* A moved pickup crossfades from its old shapes over a few ms (no click). */
    float *psi_pick_old[MEMBRANE_PICKUPS];
    int pick_fade_left[MEMBRANE_PICKUPS], pick_fade_len;
    double mass_scale; /* 1 / sqrt(density * radius^2) */
    double strike_r, strike_theta;
    double pick_r[MEMBRANE_PICKUPS], pick_theta[MEMBRANE_PICKUPS];
    pending_strike *queue; /* queue_cap entries (membrane_reserve_strikes) */
    int queued, queue_cap;
    long dropped;
    impulse_shape impulse_cache[IMPULSE_CACHE];
    int impulse_next;
    membrane_point *points[MEMBRANE_MAX_POINTS];
    int point_count;
    void (*kernel)(membrane_kernel_args *);
    void (*kernel_pair)(membrane_kernel_args *); /* two samples per pass, same instruction set */
    void (*tension_kernel)(membrane_tension_args *); /* the same instruction set again */
    void (*couplings_kernel)(membrane_tension_args *);
    double (*energy_kernel)(const float *, const float *, const float *, const float *, float, int);
};

/* Aligned, zeroed floats for the kernels (NULL when memory cannot be had). Allocates. */
float *membrane_alloc_floats_(int n);

/* The wave speed c of f_k = j_k c / (2 pi a) (mode_table.h): sqrt(T / sigma) for a
 * membrane, sqrt(D / sigma) / a for a plate (whose j_k is lambda_k^2). */
static inline double membrane_wave_speed_(const membrane *m)
{
    return m->plate ? sqrt(m->bending / m->density) / m->radius : sqrt(m->tension / m->density);
}

static inline int membrane_padded_(int n)
{
    return (n + MEMBRANE_PAD - 1) / MEMBRANE_PAD * MEMBRANE_PAD;
}

/* The displacement per unit of sum psi r: w = sum dm psi q = scale h sum psi r. */
static inline double membrane_displacement_scale_(const membrane *m)
{
    return m->mass_scale * m->coef_h;
}

/* Shapes of the sounding modes (the fading ones included) at a point; see mode_table.h.
 * For the pickups, which hear the fading modes ring out. */
static inline void membrane_mode_shapes_(const membrane *m, double r_over_a, double theta_deg,
                                         float *psi)
{
    mode_table_shapes(&m->table, m->fading_modes, r_over_a, theta_deg, psi);
}

/* Shapes at an input point (strikes, coupling points): zero for the fading modes,
 * which take no input and are invisible to the points (the kernel folds a point's
 * force in through cd, which the fading modes keep for their ring-out). */
static inline void membrane_input_shapes_(const membrane *m, double r_over_a, double theta_deg,
                                          float *psi)
{
    mode_table_shapes(&m->table, m->modes, r_over_a, theta_deg, psi);
    mode_table_patch_filter(&m->table, m->modes, m->patch / m->radius, psi);
}

/* The shapes of coupling point pt, at its place or its own (membrane_point_ops.shapes). */
void membrane_point_shapes_(const membrane *m, const membrane_point *pt, float *psi);

/* membrane_modes.c. Recomputes every coefficient from the physics; with rescale, the
 * modal state follows so that each mode's displacement and velocity stay continuous. */
void membrane_update_coefficients_(membrane *m, int rescale);
/* Builds the mode arrays for `modes` modes, keeping the state of the modes in both
 * the old and the new table. Allocates when growing. */
ictus_status membrane_build_modes_(membrane *m, int modes);
/* The shapes at the strike point, the pickups and the points, for the modes now in
 * place, and the strikes' cache emptied (membrane_modes.c). */
void membrane_refresh_shapes_(membrane *m);
/* Frees the arrays built for the capacity (not the points'). */
void membrane_free_mode_arrays_(membrane *m);

/* The tension update (membrane_modes.c): from the modal energy, the frequency factor,
 * and when it moved, the coefficients, the state (energy kept: passive) and the
 * couplings. Audio thread: no allocation, O(modes). 0 when it has to wait (a point
 * carries a force), 1 when done. */
int membrane_tension_update_(membrane *m);

/* membrane_cascade.c. Builds the coupling (message time: allocates) and sets it to the
 * physics and the state now; off unless a plate with cascade > 0 and enough modes. */
void membrane_cascade_refresh_(membrane *m);
void membrane_cascade_free_(membrane *m);
/* The state was cleared or set from outside: the cascade's variables follow it. */
void membrane_cascade_cleared_(membrane *m);
/* After the band-level cascade rescaled modes between samples: Y, psi and g follow V
 * there, and the scheme's energy does not grow. Audio thread: no allocation. */
void membrane_cascade_rescaled_(membrane *m);
/* One sample of the coupling, after the kernel's step and the strikes (audio thread: no
 * allocation); input: a force acted on the plate this sample. Its force's direct path to
 * the pickups goes into extra, to the points' displacements into a->point_w. */
void membrane_cascade_step_(membrane *m, membrane_kernel_args *a, int input, double *extra,
                            int picks);

/* membrane_band_cascade.c. The bands and the rate for the modes and physics now
 * (message time, no allocation; off unless cascade > 0 on a plate, or on a membrane
 * whose tension modulation is on). */
void membrane_band_cascade_refresh_(membrane *m);
/* One update: energy moved between neighbouring bands (audio thread: no allocation,
 * O(modes)). 0 when it has to wait (a point carries a force), 1 when done. */
int membrane_band_cascade_update_(membrane *m);

/* membrane_points.c. The points' pending forces into the state (message time only:
 * before coefficients or shapes change). */
void membrane_flush_points_(membrane *m);
/* The shapes and couplings in the kernel's coordinates, after the coefficients, the
 * pickups or the shapes changed. */
void membrane_refresh_couplings_(membrane *m);
/* The points' couplings after the tension update changed sc and ep (audio thread: no
 * allocation, O(modes)); a point's residual compliance does not depend on them. */
void membrane_refresh_point_couplings_(membrane *m);
/* The cached input shapes at (r, theta), computed into the cache when missing. */
impulse_shape *membrane_impulse_shape_(membrane *m, double r, double theta);
/* An impulse of `force` N over one sample along psi, after the kernel's step. */
void membrane_add_input_(membrane *m, const float *psi, double force, membrane_kernel_args *a);
/* A point's pending move lands now (from the processing loop). */
void membrane_land_point_(membrane *m, membrane_point *pt);

/* ---------------------------------------------------------------- coupling points
 *
 * A coupling point is where an object attached to the membrane (a stick: contact.c)
 * exchanges a force with the modes, solved implicitly sample by sample
 * (docs/membrane.md, "The contact"). The membrane owns the mode-space side: the
 * shapes at the point, the couplings derived from them, and folding the force into
 * the modal state one sample late (the kernel does it). The object owns the force:
 * the membrane calls it through membrane_point_ops at fixed places of
 * membrane_process(), and never sees its type. */
typedef struct membrane_point_ops {
    /* A pending move has just landed (membrane_point_move_): the point is at its
     * new place, displacement_m and velocity_mps are the membrane's displacement and
     * velocity there (positive into the head). */
    void (*landed)(membrane_point *pt, double displacement_m, double velocity_mps);
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
    /* Optional (NULL: the shapes at r_over_a, theta_deg): the point's own mode weights
     * for the modes of m, `live` of them (zero beyond), for a force spread over the
     * head (the snare's air: snare_wires.c). Message time; such a point never moves. */
    void (*shapes)(const membrane *m, const membrane_point *pt, int live, float *psi);
} membrane_point_ops;

struct membrane_point {
    const membrane_point_ops *ops;
    membrane *owner; /* NULL while detached */
    int slot;        /* index in the owner's table */
    /* Mode weights (mass-normalised shapes, zero for fading modes) at the point and
     * at the place of a pending move. Allocated by the membrane at its capacity
     * (psi_cap floats each), freed by membrane_point_free_. */
    float *psi, *psi_next;
    /* psi sc (membrane_points.c): the kernel's copy, in the coordinates of its stored state. */
    float *psi_k;
    int psi_cap;
    double r_over_a, theta_deg;
    /* A move waiting to land move_offset samples into the next membrane_process(). */
    int move_pending, move_offset;
    double move_r, move_theta;
    int active;             /* set by the object: solve this point every sample */
    double force_pending;   /* N, the last force, not yet added to the modal state */
    double self_compliance; /* K = d w / d F over one sample (m/N) */
    /* Set by the object: the point is a stick's contact, which feels the static
     * compliance of the modes left out (residual_compliance, m/N, membrane_points.c). */
    int static_correction;
    double residual_compliance;
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

/* Clamps a point on the head: r/a into [0, 1] (NaN: 0), theta (deg) wrapped into
 * [0, 360) so that cos/sin stay accurate (not finite: 0). ICTUS_CLAMPED when either
 * changed (a wrapped angle is no change). */
static inline ictus_status membrane_clamp_point_(double *r_over_a, double *theta_deg)
{
    ictus_status s =
        ictus_clamp(r_over_a, MEMBRANE_R_OVER_A_MIN, MEMBRANE_R_OVER_A_MAX, MEMBRANE_R_OVER_A_MIN);
    if (!isfinite(*theta_deg)) {
        *theta_deg = 0.0;
        return ICTUS_CLAMPED;
    }
    *theta_deg = fmod(*theta_deg, 360.0);
    if (*theta_deg < 0.0)
        *theta_deg += 360.0;
    return s;
}

#endif
