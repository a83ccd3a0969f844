/* membrane.c -- modal circular membrane (see membrane.h, docs/membrane.md): the
 * coefficients, the strike queue, the coupling points' mode-space side and the
 * processing loop. The table of modes is in mode_table.c, the modal update in
 * membrane_kernel.inc, and the stick's stroke in contact.c, which the membrane only
 * calls through membrane_point_ops (membrane_internal.h). */
#define _POSIX_C_SOURCE 200112L
#include "membrane_internal.h"
#include "mode_table.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#if defined(__x86_64__) || defined(__i386__)
#include <xmmintrin.h>
#define MEMBRANE_X86 1
#endif

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

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

struct membrane {
    double sample_rate, radius, tension, density, t60, hf_damping, output_gain;
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
    double *omega_model; /* model stiffness w' per mode (0: silent) */
    /* SoA float state and coefficients (see membrane_kernel.inc): q holds the
     * scaled displacement r = q / (h w'), h = T / 2 (the energy coordinate q is
     * h w' r); cd = 2 / D is r's coefficient of p; ep the input gain of both. */
    float *q, *p, *c1, *cd, *c3, *ep;
    /* The kernel's coordinates: q and p above hold r / sc and p / sc, sc = sqrt(cd)
     * (0 for silent modes); ep_k = ep / sc, pick_k = psi_pick sc, and each point's
     * psi_k = psi sc (membrane_kernel.inc). */
    float *sc, *ep_k, *pick_k[MEMBRANE_PICKUPS];
    double coef_h; /* h of the coefficients (and of r) now in place */
    float *psi_strike, *psi_pick[MEMBRANE_PICKUPS];
    /* A moved pickup crossfades from its old shapes over a few ms (no click). */
    float *psi_pick_old[MEMBRANE_PICKUPS];
    int pick_fade_left[MEMBRANE_PICKUPS], pick_fade_len;
    double mass_scale; /* 1 / sqrt(density * radius^2) */
    double strike_r, strike_theta;
    double pick_r[MEMBRANE_PICKUPS], pick_theta[MEMBRANE_PICKUPS];
    pending_strike queue[STRIKE_QUEUE];
    int queued;
    long dropped;
    impulse_shape impulse_cache[IMPULSE_CACHE];
    int impulse_next;
    membrane_point *points[MEMBRANE_MAX_POINTS];
    int point_count;
    void (*kernel)(membrane_kernel_args *);
    void (*kernel_pair)(membrane_kernel_args *); /* two samples per pass, same instruction set */
};

/* ---------------------------------------------------------------- helpers */

static ictus_status clamp_point(double *r_over_a, double *theta_deg)
{
    ictus_status s =
        ictus_clamp(r_over_a, MEMBRANE_R_OVER_A_MIN, MEMBRANE_R_OVER_A_MAX, MEMBRANE_R_OVER_A_MIN);
    if (!isfinite(*theta_deg)) {
        *theta_deg = 0.0;
        return ICTUS_CLAMPED;
    }
    /* Angles wrap; keep them in [0, 360) so cos/sin stay accurate. */
    *theta_deg = fmod(*theta_deg, 360.0);
    if (*theta_deg < 0.0)
        *theta_deg += 360.0;
    return s;
}

static float *alloc_floats(int n)
{
    void *ptr = NULL;
    if (posix_memalign(&ptr, 64, sizeof(float) * (size_t)n) != 0)
        return NULL;
    memset(ptr, 0, sizeof(float) * (size_t)n);
    return ptr;
}

static int padded(int n)
{
    return (n + MEMBRANE_PAD - 1) / MEMBRANE_PAD * MEMBRANE_PAD;
}

/* Shapes of the sounding modes (the fading ones included) at a point; see mode_table.h.
 * For the pickups, which hear the fading modes ring out. */
static void mode_shapes(const membrane *m, double r_over_a, double theta_deg, float *psi)
{
    mode_table_shapes(&m->table, m->fading_modes, r_over_a, theta_deg, psi);
}

/* Shapes at an input point (strikes, coupling points): zero for the fading modes,
 * which take no input and are invisible to the points (the kernel folds a point's
 * force in through cd, which the fading modes keep for their ring-out). */
static void input_shapes(const membrane *m, double r_over_a, double theta_deg, float *psi)
{
    mode_table_shapes(&m->table, m->modes, r_over_a, theta_deg, psi);
}

/* Damping law sigma_k = s0 + s1 w_k^2 with s0 + s1 w_1^2 = ln(1000)/t60 and
 * s1 w_ref^2 = hf * s0 at w_ref = 2 pi 1 kHz. */
static double mode_decay_rate(const membrane *m, double omega)
{
    double omega1 = m->table.j[0] * sqrt(m->tension / m->density) / m->radius;
    double w_ref = 2.0 * M_PI * 1000.0;
    double rate1 = log(1000.0) / m->t60;
    double s0 = rate1 / (1.0 + m->hf_damping * (omega1 / w_ref) * (omega1 / w_ref));
    double s1 = m->hf_damping * s0 / (w_ref * w_ref);
    return s0 + s1 * omega * omega;
}

/* Recomputes every coefficient from the physics. When rescale is set, the modal
 * state is rescaled so that each mode's physical displacement and velocity are
 * continuous across the change (no click from a parameter move). */
static void update_coefficients(membrane *m, int rescale)
{
    const double T = 1.0 / m->sample_rate, h = 0.5 * T;
    const double c = sqrt(m->tension / m->density);
    const double old_scale = m->mass_scale, old_h = m->coef_h;
    m->mass_scale = 1.0 / sqrt(m->density * m->radius * m->radius);
    m->coef_h = h;
    const double scale = m->mass_scale;
    for (int k = 0; k < m->capacity; k++) {
        double old_omega = m->omega_model[k];
        int fading = k >= m->modes;
        double freq = (k < m->fading_modes) ? m->table.j[k] * c / (2.0 * M_PI * m->radius) : 0.0;
        if (k >= m->fading_modes || freq >= 0.95 * 0.5 * m->sample_rate || freq <= 0.0) {
            /* Silent: frozen at zero, no input, no output. */
            m->c1[k] = m->cd[k] = m->c3[k] = m->ep[k] = 0.0f;
            m->sc[k] = m->ep_k[k] = 0.0f;
            m->q[k] = m->p[k] = 0.0f;
            m->omega_model[k] = 0.0;
            continue;
        }
        double omega = 2.0 * M_PI * freq;
        double sigma = fading ? log(1000.0) / FADE_S : mode_decay_rate(m, omega);
        /* Inverse bilinear map of the wanted discrete poles z = exp((-sigma +- i w) T):
         * s = (2/T) tanh((-sigma +- i w) T / 2) = a +- i b, so the midpoint rule's poles
         * land exactly on the target pitch and decay. */
        double u2 = sigma * T, v2 = omega * T;
        double den = cosh(u2) + cos(v2);
        double a = -(2.0 / T) * sinh(u2) / den;
        double b = (2.0 / T) * sin(v2) / den;
        double wm = sqrt(a * a + b * b); /* model stiffness w' */
        double sm = -a;                  /* model damping s' */
        double D = 1.0 + 2.0 * h * sm + h * h * wm * wm;
        /* In q, p: q+ = q - c1 q + c2 p + eq u, p+ = p - c2 q - c3 p + ep u with
         * c2 = 2 h w' / D and eq = h w' ep. With r = q / (h w') (c2 h w' = c1,
         * c2 / (h w') = 2 / D): r+ = r - c1 r + cd p + ep u, p+ = p - c1 r - c3 p + ep u,
         * one input gain for both, and the displacement weights dm psi q =
         * scale h psi r need no per-mode array (docs/membrane.md). */
        m->c1[k] = (float)(2.0 * h * h * wm * wm / D);
        m->cd[k] = (float)(2.0 / D);
        m->c3[k] = (float)((2.0 * h * h * wm * wm + 4.0 * h * sm) / D);
        m->ep[k] = (float)(scale * T / D);
        if (fading) /* ringing out: no input (and zero input shapes, input_shapes) */
            m->ep[k] = 0.0f;
        const double old_sc = m->sc[k];
        m->sc[k] = (float)sqrt((double)m->cd[k]);
        m->ep_k[k] = (float)(m->ep[k] / (double)m->sc[k]);
        if (rescale && old_omega > 0.0 && old_sc > 0.0) {
            /* y = q / (sqrt(M) w'), y' = p / sqrt(M), sqrt(M) proportional to 1/scale;
             * q = h w' r, so r scales by old_h / h (w' cancels); the stored r / sc and
             * p / sc by old_sc / sc besides. */
            double r = old_scale / scale * (old_sc / m->sc[k]);
            m->q[k] = (float)(m->q[k] * r * old_h / h);
            m->p[k] = (float)(m->p[k] * r);
        } else if (rescale) {
            m->q[k] = m->p[k] = 0.0f;
        }
        m->omega_model[k] = wm;
    }
}

static void refresh_point_couplings(membrane *m);
static void flush_points(membrane *m);
static impulse_shape *make_impulse_shape(membrane *m, double r, double theta);

/* Builds the mode table for `modes` modes; keeps the state of modes that exist
 * in both the old and new table (the order is a prefix property of the sort). */
static ictus_status build_modes(membrane *m, int modes)
{
    int need = padded(modes);
    if (need > m->capacity || !m->table.j) {
        int cap = need;
        mode_table table = {0};
        double *om = calloc((size_t)cap, sizeof(double));
        float *arrays[15];
        int ok = om != NULL;
        for (int i = 0; i < 15; i++) {
            arrays[i] = alloc_floats(cap);
            ok = ok && arrays[i];
        }
        float *impulse[IMPULSE_CACHE];
        for (int i = 0; i < IMPULSE_CACHE; i++) {
            impulse[i] = alloc_floats(cap);
            ok = ok && impulse[i];
        }
        float *ppsi[MEMBRANE_MAX_POINTS][3];
        for (int i = 0; i < MEMBRANE_MAX_POINTS; i++) {
            for (int j = 0; j < 3; j++) {
                ppsi[i][j] = NULL;
                if (i < m->point_count) {
                    ppsi[i][j] = alloc_floats(cap);
                    ok = ok && ppsi[i][j];
                }
            }
        }
        /* The table last: it computes the Bessel zeros in scratch memory that it
         * frees, and state arrays allocated after that landed at heap offsets
         * that cost ~5 % in bench_membrane_core (contact, 1024 modes). */
        ok = ok && mode_table_build(&table, cap) == ICTUS_OK;
        if (!ok) {
            mode_table_free(&table);
            free(om);
            for (int i = 0; i < 15; i++)
                free(arrays[i]);
            for (int i = 0; i < IMPULSE_CACHE; i++)
                free(impulse[i]);
            for (int i = 0; i < MEMBRANE_MAX_POINTS; i++)
                for (int j = 0; j < 3; j++)
                    free(ppsi[i][j]);
            return ICTUS_ENOMEM;
        }
        /* Keep the state of the modes we had (same index = same mode). */
        flush_points(m);
        int keep = m->capacity < cap ? m->capacity : cap;
        if (m->q) {
            memcpy(arrays[0], m->q, sizeof(float) * (size_t)keep);
            memcpy(arrays[1], m->p, sizeof(float) * (size_t)keep);
            memcpy(arrays[11], m->sc, sizeof(float) * (size_t)keep); /* the state's scale */
            memcpy(om, m->omega_model, sizeof(double) * (size_t)keep);
        }
        mode_table_free(&m->table);
        free(m->omega_model);
        free(m->q), free(m->p), free(m->c1), free(m->cd), free(m->c3);
        free(m->ep), free(m->psi_strike);
        free(m->sc), free(m->ep_k);
        for (int i = 0; i < MEMBRANE_PICKUPS; i++) {
            free(m->psi_pick[i]);
            free(m->psi_pick_old[i]);
            free(m->pick_k[i]);
            m->pick_fade_left[i] = 0;
        }
        m->table = table;
        m->omega_model = om;
        m->q = arrays[0], m->p = arrays[1], m->c1 = arrays[2], m->cd = arrays[3];
        m->c3 = arrays[4], m->ep = arrays[5];
        m->psi_strike = arrays[6];
        m->psi_pick[0] = arrays[7];
        m->psi_pick[1] = arrays[8];
        m->psi_pick_old[0] = arrays[9];
        m->psi_pick_old[1] = arrays[10];
        m->sc = arrays[11], m->ep_k = arrays[12];
        m->pick_k[0] = arrays[13];
        m->pick_k[1] = arrays[14];
        for (int i = 0; i < IMPULSE_CACHE; i++) {
            free(m->impulse_cache[i].psi);
            m->impulse_cache[i].psi = impulse[i];
            m->impulse_cache[i].valid = 0;
        }
        for (int i = 0; i < m->point_count; i++) {
            membrane_point *pt = m->points[i];
            free(pt->psi), free(pt->psi_next), free(pt->psi_k);
            pt->psi = ppsi[i][0];
            pt->psi_next = ppsi[i][1];
            pt->psi_k = ppsi[i][2];
            pt->psi_cap = cap;
        }
        m->capacity = cap;
    } else {
        flush_points(m);
        for (int i = 0; i < IMPULSE_CACHE; i++)
            m->impulse_cache[i].valid = 0;
    }
    int old_limit = m->fading_modes > m->modes ? m->fading_modes : m->modes;
    if (modes < old_limit && membrane_energy(m) > 0.0) {
        /* Shrinking while sounding: the dropped modes ring out instead of
         * vanishing with a click. */
        m->fading_modes = old_limit;
        m->fade_left = (long)(FADE_S * m->sample_rate) + 1;
    } else {
        m->fading_modes = modes;
        m->fade_left = 0;
    }
    m->modes = modes;
    m->count = padded(m->fading_modes);
    /* Modes dropped now start from rest if they come back later. */
    for (int k = m->fading_modes; k < m->capacity; k++)
        m->q[k] = m->p[k] = 0.0f;
    update_coefficients(m, 1);
    input_shapes(m, m->strike_r, m->strike_theta, m->psi_strike);
    for (int i = 0; i < MEMBRANE_PICKUPS; i++)
        mode_shapes(m, m->pick_r[i], m->pick_theta[i], m->psi_pick[i]);
    for (int i = 0; i < m->point_count; i++) {
        membrane_point *pt = m->points[i];
        input_shapes(m, pt->r_over_a, pt->theta_deg, pt->psi);
        if (pt->move_pending)
            input_shapes(m, pt->move_r, pt->move_theta, pt->psi_next);
    }
    refresh_point_couplings(m);
    return ICTUS_OK;
}

/* Adds each point's force of the last sample, not yet in the modal state, to
 * the state (message-time only: before coefficients or shapes change). */
static void flush_points(membrane *m)
{
    if (!m->q)
        return;
    for (int i = 0; i < m->point_count; i++) {
        membrane_point *pt = m->points[i];
        if (pt->force_pending != 0.0 && pt->psi) {
            for (int k = 0; k < m->count; k++) {
                float du = m->ep_k[k] * ((float)pt->force_pending * pt->psi[k]);
                m->q[k] += du;
                m->p[k] += du;
            }
        }
        pt->force_pending = 0.0;
    }
}

static double dot_psi(const membrane *m, const float *a, const float *b, const float *weight)
{
    double s = 0.0;
    for (int k = 0; k < m->count; k++)
        s += (double)a[k] * b[k] * weight[k];
    return s;
}

/* The displacement per unit of sum psi r: w = sum dm psi q = scale h sum psi r. */
static double displacement_scale(const membrane *m)
{
    return m->mass_scale * m->coef_h;
}

static void point_couplings(membrane *m, membrane_point *pt)
{
    /* w changes by K F over a sample: K = sum psi dm psi eq = scale h sum psi^2 ep
     * (docs/membrane.md). */
    double K = 0.0;
    for (int k = 0; k < m->count; k++)
        K += (double)pt->psi[k] * pt->psi[k] * m->ep[k];
    pt->self_compliance = K * displacement_scale(m);
    for (int j = 0; j < MEMBRANE_PICKUPS; j++)
        pt->pick_coupling[j] = dot_psi(m, m->psi_pick[j], pt->psi, m->ep);
    for (int k = 0; k < m->capacity; k++)
        pt->psi_k[k] = pt->psi[k] * m->sc[k];
}

/* The shapes and couplings in the kernel's coordinates, after the coefficients, the
 * pickups or the shapes changed. */
static void refresh_point_couplings(membrane *m)
{
    if (!m->sc)
        return;
    for (int j = 0; j < MEMBRANE_PICKUPS; j++)
        for (int k = 0; k < m->capacity; k++)
            m->pick_k[j][k] = m->psi_pick[j][k] * m->sc[k];
    for (int i = 0; i < m->point_count; i++)
        if (m->points[i]->psi)
            point_couplings(m, m->points[i]);
}

/* ---------------------------------------------------------------- lifetime */

membrane *membrane_new(double sample_rate_hz)
{
    membrane *m = calloc(1, sizeof(*m));
    if (!m)
        return NULL;
    ictus_clamp(&sample_rate_hz, MEMBRANE_SR_MIN, MEMBRANE_SR_MAX, 48000.0);
    m->sample_rate = sample_rate_hz;
    m->radius = MEMBRANE_DEFAULT_RADIUS;
    m->tension = MEMBRANE_DEFAULT_TENSION;
    m->density = MEMBRANE_DEFAULT_DENSITY;
    m->t60 = MEMBRANE_DEFAULT_T60;
    m->hf_damping = MEMBRANE_DEFAULT_HF_DAMPING;
    m->output_gain = MEMBRANE_DEFAULT_GAIN;
    m->gain_smoothed = MEMBRANE_DEFAULT_GAIN;
    m->strike_r = 0.3;
    m->pick_r[0] = 0.5;
    m->pick_r[1] = 0.5;
    m->pick_theta[1] = 90.0;
    m->kernel = membrane_kernel_generic;
    m->kernel_pair = membrane_kernel_pair_generic;
#if defined(MEMBRANE_X86) && defined(__GNUC__) && !defined(ICTUS_NO_AVX2)
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
        m->kernel = membrane_kernel_avx2;
        m->kernel_pair = membrane_kernel_pair_avx2;
    }
#endif
    /* ICTUS_MEMBRANE_KERNEL=generic picks the portable kernel on any machine, e.g.
     * to benchmark it inside Pd (bench/peers); read when the object is made. */
    const char *want = getenv("ICTUS_MEMBRANE_KERNEL");
    if (want && strcmp(want, "generic") == 0) {
        m->kernel = membrane_kernel_generic;
        m->kernel_pair = membrane_kernel_pair_generic;
    }
    if (build_modes(m, MEMBRANE_DEFAULT_MODES) != ICTUS_OK) {
        membrane_free(m);
        return NULL;
    }
    return m;
}

void membrane_free(membrane *m)
{
    if (!m)
        return;
    while (m->point_count > 0)
        membrane_point_detach_(m, m->points[m->point_count - 1]);
    mode_table_free(&m->table);
    free(m->omega_model);
    free(m->q), free(m->p), free(m->c1), free(m->cd), free(m->c3);
    free(m->ep), free(m->psi_strike);
    free(m->sc), free(m->ep_k);
    for (int i = 0; i < MEMBRANE_PICKUPS; i++) {
        free(m->psi_pick[i]);
        free(m->psi_pick_old[i]);
        free(m->pick_k[i]);
    }
    for (int i = 0; i < IMPULSE_CACHE; i++)
        free(m->impulse_cache[i].psi);
    free(m);
}

void membrane_use_generic_kernel_(membrane *m)
{
    m->kernel = membrane_kernel_generic;
    m->kernel_pair = membrane_kernel_pair_generic;
}

const char *membrane_kernel_name(const membrane *m)
{
    return m->kernel == membrane_kernel_avx2 ? "avx2+fma" : "generic";
}

/* ---------------------------------------------------------------- setters */

static ictus_status physics_changed(membrane *m, ictus_status s)
{
    flush_points(m);
    update_coefficients(m, 1);
    refresh_point_couplings(m);
    return s;
}

ictus_status membrane_set_sample_rate(membrane *m, double sr)
{
    ictus_status s = ictus_clamp(&sr, MEMBRANE_SR_MIN, MEMBRANE_SR_MAX, 48000.0);
    m->sample_rate = sr;
    return physics_changed(m, s);
}

ictus_status membrane_set_radius(membrane *m, double r)
{
    ictus_status s =
        ictus_clamp(&r, MEMBRANE_RADIUS_MIN, MEMBRANE_RADIUS_MAX, MEMBRANE_DEFAULT_RADIUS);
    m->radius = r;
    return physics_changed(m, s);
}

ictus_status membrane_set_tension(membrane *m, double t)
{
    ictus_status s =
        ictus_clamp(&t, MEMBRANE_TENSION_MIN, MEMBRANE_TENSION_MAX, MEMBRANE_DEFAULT_TENSION);
    m->tension = t;
    return physics_changed(m, s);
}

ictus_status membrane_set_density(membrane *m, double d)
{
    ictus_status s =
        ictus_clamp(&d, MEMBRANE_DENSITY_MIN, MEMBRANE_DENSITY_MAX, MEMBRANE_DEFAULT_DENSITY);
    m->density = d;
    return physics_changed(m, s);
}

/* The mass range is the density range times the area, pi a^2. */
static ictus_range mass_range(const membrane *m)
{
    const double a = m->radius;
    ictus_range r;
    r.min = MEMBRANE_DENSITY_MIN * M_PI * a * a;
    r.max = MEMBRANE_DENSITY_MAX * M_PI * a * a;
    r.def = MEMBRANE_DEFAULT_DENSITY * M_PI * a * a;
    return r;
}

ictus_status membrane_set_mass(membrane *m, double mass_kg)
{
    if (isnan(mass_kg)) {
        membrane_set_density(m, MEMBRANE_DEFAULT_DENSITY);
        return ICTUS_CLAMPED;
    }
    /* Clamped as a mass first, so that the density the limits give is the one a
     * caller passing the limit itself would get. */
    ictus_range range = mass_range(m);
    ictus_status s = ictus_clamp(&mass_kg, range.min, range.max, range.def);
    double density = mass_kg / (M_PI * m->radius * m->radius);
    /* A mass in range gives a density in range but for the rounding of the division
     * (the limit's mass / area can land an ulp outside the density's limit): pinned
     * back, with no report; the mass said whether it was clamped. */
    ictus_clamp(&density, MEMBRANE_DENSITY_MIN, MEMBRANE_DENSITY_MAX, MEMBRANE_DEFAULT_DENSITY);
    membrane_set_density(m, density);
    return s;
}

ictus_status membrane_set_modes(membrane *m, int count)
{
    ictus_status s = ICTUS_OK;
    if (count < MEMBRANE_MODES_MIN) {
        count = MEMBRANE_MODES_MIN;
        s = ICTUS_CLAMPED;
    } else if (count > MEMBRANE_MODES_MAX) {
        count = MEMBRANE_MODES_MAX;
        s = ICTUS_CLAMPED;
    }
    if (count == m->modes)
        return s;
    ictus_status b = build_modes(m, count);
    return b == ICTUS_ENOMEM ? b : s;
}

ictus_status membrane_set_t60(membrane *m, double t60)
{
    ictus_status s = ictus_clamp(&t60, MEMBRANE_T60_MIN, MEMBRANE_T60_MAX, MEMBRANE_DEFAULT_T60);
    m->t60 = t60;
    return physics_changed(m, s);
}

ictus_status membrane_set_hf_damping(membrane *m, double control)
{
    ictus_status s = ictus_clamp(&control, MEMBRANE_HF_DAMPING_MIN, MEMBRANE_HF_DAMPING_MAX,
                                 MEMBRANE_DEFAULT_HF_DAMPING);
    m->hf_damping = control;
    return physics_changed(m, s);
}

ictus_status membrane_set_pickup(membrane *m, int index, double r_over_a, double theta_deg)
{
    ictus_status s = clamp_point(&r_over_a, &theta_deg);
    if (index < 0 || index >= MEMBRANE_PICKUPS)
        return ICTUS_CLAMPED; /* no such pickup: nothing changed */
    m->pick_r[index] = r_over_a;
    m->pick_theta[index] = theta_deg;
    memcpy(m->psi_pick_old[index], m->psi_pick[index], sizeof(float) * (size_t)m->capacity);
    mode_shapes(m, r_over_a, theta_deg, m->psi_pick[index]);
    /* 5 ms linear crossfade from the old point, when there is something to hear. */
    m->pick_fade_len = (int)(0.005 * m->sample_rate) + 1;
    m->pick_fade_left[index] = membrane_energy(m) > 0.0 ? m->pick_fade_len : 0;
    refresh_point_couplings(m);
    return s;
}

ictus_status membrane_set_strike_point(membrane *m, double r_over_a, double theta_deg)
{
    ictus_status s = clamp_point(&r_over_a, &theta_deg);
    m->strike_r = r_over_a;
    m->strike_theta = theta_deg;
    input_shapes(m, r_over_a, theta_deg, m->psi_strike);
    return s;
}

static impulse_shape *find_impulse_shape(membrane *m, double r, double theta)
{
    for (int i = 0; i < IMPULSE_CACHE; i++)
        if (m->impulse_cache[i].valid && m->impulse_cache[i].r_over_a == r &&
            m->impulse_cache[i].theta_deg == theta)
            return &m->impulse_cache[i];
    return NULL;
}

static impulse_shape *make_impulse_shape(membrane *m, double r, double theta)
{
    impulse_shape *s = find_impulse_shape(m, r, theta);
    if (s)
        return s;
    s = &m->impulse_cache[m->impulse_next];
    m->impulse_next = (m->impulse_next + 1) % IMPULSE_CACHE;
    input_shapes(m, r, theta, s->psi);
    s->r_over_a = r;
    s->theta_deg = theta;
    s->valid = 1;
    return s;
}

ictus_status membrane_strike(membrane *m, double r_over_a, double theta_deg, double impulse_ns,
                             int sample_offset)
{
    ictus_status s = clamp_point(&r_over_a, &theta_deg);
    /* An impulse beyond 1e3 N s is no drum stroke; clamp rather than overflow floats. */
    if (ictus_clamp(&impulse_ns, -MEMBRANE_IMPULSE_MAX, MEMBRANE_IMPULSE_MAX, 0.0) != ICTUS_OK)
        s = ICTUS_CLAMPED;
    if (sample_offset < 0) {
        sample_offset = 0;
        s = ICTUS_CLAMPED;
    }
    if (m->queued >= STRIKE_QUEUE) {
        m->dropped++;
        return ICTUS_CLAMPED;
    }
    /* Shapes are computed here, in the message handler, so that the audio loop
     * only looks them up (it recomputes only if four other points evicted it). */
    make_impulse_shape(m, r_over_a, theta_deg);
    pending_strike *p = &m->queue[m->queued++];
    p->r_over_a = r_over_a;
    p->theta_deg = theta_deg;
    p->impulse_ns = impulse_ns;
    p->offset = sample_offset;
    return s;
}

void membrane_clear(membrane *m)
{
    memset(m->q, 0, sizeof(float) * (size_t)m->capacity);
    memset(m->p, 0, sizeof(float) * (size_t)m->capacity);
    m->queued = 0;
    if (m->fade_left > 0)
        m->fade_left = 1; /* nothing left to ring out: end the fade next block */
    for (int i = 0; i < m->point_count; i++) {
        membrane_point *pt = m->points[i];
        pt->move_pending = 0;
        pt->force_pending = 0.0;
        pt->ops->cleared(pt);
    }
}

ictus_status membrane_set_output_gain(membrane *m, double gain)
{
    ictus_status s =
        ictus_clamp(&gain, MEMBRANE_GAIN_MIN, MEMBRANE_GAIN_MAX, MEMBRANE_DEFAULT_GAIN);
    m->output_gain = gain;
    return s;
}

/* ---------------------------------------------------------------- parameter table */

ictus_status membrane_set_param(membrane *m, membrane_param p, double value)
{
    switch (p) {
    case MEMBRANE_PARAM_RADIUS:
        return membrane_set_radius(m, value);
    case MEMBRANE_PARAM_TENSION:
        return membrane_set_tension(m, value);
    case MEMBRANE_PARAM_DENSITY:
        return membrane_set_density(m, value);
    case MEMBRANE_PARAM_MASS:
        return membrane_set_mass(m, value);
    case MEMBRANE_PARAM_MODES: {
        /* Clamped before the conversion to int, which is undefined out of range. */
        double count = floor(value + 0.5);
        ictus_status s =
            ictus_clamp(&count, MEMBRANE_MODES_MIN, MEMBRANE_MODES_MAX, MEMBRANE_DEFAULT_MODES);
        ictus_status b = membrane_set_modes(m, (int)count);
        return b != ICTUS_OK ? b : s;
    }
    case MEMBRANE_PARAM_T60:
        return membrane_set_t60(m, value);
    case MEMBRANE_PARAM_HF_DAMPING:
        return membrane_set_hf_damping(m, value);
    case MEMBRANE_PARAM_GAIN:
        return membrane_set_output_gain(m, value);
    default:
        return ICTUS_CLAMPED;
    }
}

double membrane_get_param(const membrane *m, membrane_param p)
{
    switch (p) {
    case MEMBRANE_PARAM_RADIUS:
        return membrane_get_radius(m);
    case MEMBRANE_PARAM_TENSION:
        return membrane_get_tension(m);
    case MEMBRANE_PARAM_DENSITY:
        return membrane_get_density(m);
    case MEMBRANE_PARAM_MASS:
        return membrane_get_mass(m);
    case MEMBRANE_PARAM_MODES:
        return membrane_get_modes(m);
    case MEMBRANE_PARAM_T60:
        return membrane_get_t60(m);
    case MEMBRANE_PARAM_HF_DAMPING:
        return membrane_get_hf_damping(m);
    case MEMBRANE_PARAM_GAIN:
        return membrane_get_output_gain(m);
    default:
        return 0.0;
    }
}

ictus_range membrane_param_range(const membrane *m, membrane_param p)
{
    static const ictus_range ranges[MEMBRANE_PARAM_COUNT] = {
        [MEMBRANE_PARAM_RADIUS] = {MEMBRANE_RADIUS_MIN, MEMBRANE_RADIUS_MAX,
                                   MEMBRANE_DEFAULT_RADIUS},
        [MEMBRANE_PARAM_TENSION] = {MEMBRANE_TENSION_MIN, MEMBRANE_TENSION_MAX,
                                    MEMBRANE_DEFAULT_TENSION},
        [MEMBRANE_PARAM_DENSITY] = {MEMBRANE_DENSITY_MIN, MEMBRANE_DENSITY_MAX,
                                    MEMBRANE_DEFAULT_DENSITY},
        [MEMBRANE_PARAM_MODES] = {MEMBRANE_MODES_MIN, MEMBRANE_MODES_MAX, MEMBRANE_DEFAULT_MODES},
        [MEMBRANE_PARAM_T60] = {MEMBRANE_T60_MIN, MEMBRANE_T60_MAX, MEMBRANE_DEFAULT_T60},
        [MEMBRANE_PARAM_HF_DAMPING] = {MEMBRANE_HF_DAMPING_MIN, MEMBRANE_HF_DAMPING_MAX,
                                       MEMBRANE_DEFAULT_HF_DAMPING},
        [MEMBRANE_PARAM_GAIN] = {MEMBRANE_GAIN_MIN, MEMBRANE_GAIN_MAX, MEMBRANE_DEFAULT_GAIN},
    };
    const ictus_range none = {0.0, 0.0, 0.0};
    if (p == MEMBRANE_PARAM_MASS)
        return mass_range(m);
    if ((int)p < 0 || p >= MEMBRANE_PARAM_COUNT)
        return none;
    return ranges[p];
}

/* ---------------------------------------------------------------- coupling points */

ictus_status membrane_point_attach_(membrane *m, membrane_point *pt)
{
    if (!m || !pt)
        return ICTUS_CLAMPED;
    for (int i = 0; i < m->point_count; i++)
        if (m->points[i] == pt)
            return ICTUS_OK;
    if (m->point_count >= MEMBRANE_MAX_POINTS)
        return ICTUS_ENOMEM;
    if (pt->owner)
        membrane_point_detach_(pt->owner, pt);
    float *arr[3];
    int ok = 1;
    for (int j = 0; j < 3; j++) {
        arr[j] = alloc_floats(m->capacity);
        ok = ok && arr[j];
    }
    if (!ok) {
        for (int j = 0; j < 3; j++)
            free(arr[j]);
        return ICTUS_ENOMEM;
    }
    free(pt->psi), free(pt->psi_next), free(pt->psi_k);
    pt->psi = arr[0];
    pt->psi_next = arr[1];
    pt->psi_k = arr[2];
    pt->psi_cap = m->capacity;
    pt->owner = m;
    pt->slot = m->point_count;
    m->points[m->point_count++] = pt;
    pt->force_pending = 0.0;
    input_shapes(m, pt->r_over_a, pt->theta_deg, pt->psi);
    if (pt->move_pending)
        input_shapes(m, pt->move_r, pt->move_theta, pt->psi_next);
    point_couplings(m, pt);
    return ICTUS_OK;
}

void membrane_point_detach_(membrane *m, membrane_point *pt)
{
    if (!m || !pt)
        return;
    for (int i = 0; i < m->point_count; i++) {
        if (m->points[i] != pt)
            continue;
        flush_points(m);
        for (int j = i; j + 1 < m->point_count; j++) {
            m->points[j] = m->points[j + 1];
            m->points[j]->slot = j;
        }
        m->point_count--;
        pt->owner = NULL;
        pt->force_pending = 0.0;
        pt->ops->detached(pt);
        return;
    }
}

void membrane_point_free_(membrane_point *pt)
{
    if (!pt)
        return;
    if (pt->owner)
        membrane_point_detach_(pt->owner, pt);
    free(pt->psi), free(pt->psi_next), free(pt->psi_k);
    pt->psi = pt->psi_next = pt->psi_k = NULL;
    pt->psi_cap = 0;
}

void membrane_point_move_(membrane_point *pt, double r_over_a, double theta_deg, int sample_offset)
{
    pt->move_r = r_over_a;
    pt->move_theta = theta_deg;
    pt->move_offset = sample_offset;
    pt->move_pending = 1;
    /* The weights of the new point are computed here, in the message handler,
     * so that landing in the audio loop costs O(modes) only. They come from the
     * strikes' small cache of shapes (the same values): a stick that plays the
     * same spot again, as a roll or a patch with a fixed position does, costs a
     * copy instead of O(modes) Bessel functions. */
    if (pt->owner) {
        membrane *m = pt->owner;
        const impulse_shape *shape = make_impulse_shape(m, r_over_a, theta_deg);
        memcpy(pt->psi_next, shape->psi, sizeof(float) * (size_t)m->capacity);
    }
}

/* ---------------------------------------------------------------- process */

/* Adds an input impulse (force F over one sample along shape psi) after the
 * step: linear, so it equals passing it through the step's input. Updates the
 * pickup sums and coupling-point displacements of this sample too (a's shapes are
 * the kernel's, times sc, as the state). */
static void add_input(membrane *m, const float *psi, double force, membrane_kernel_args *a)
{
    double dpick[MEMBRANE_PICKUPS] = {0}, dw[MEMBRANE_MAX_POINTS] = {0};
    for (int k = 0; k < m->count; k++) {
        float u = (float)force * psi[k];
        float dq = m->ep_k[k] * u, dp = dq; /* r and p take the same input */
        m->q[k] += dq;
        m->p[k] += dp;
        for (int j = 0; j < MEMBRANE_PICKUPS; j++)
            if (a->psi_pick[j])
                dpick[j] += (double)a->psi_pick[j][k] * dp;
        for (int c = 0; c < a->points; c++)
            dw[c] += (double)a->point_psi[c][k] * dq; /* unscaled, as the kernel's */
    }
    for (int j = 0; j < MEMBRANE_PICKUPS; j++)
        a->pick_sum[j] += dpick[j];
    for (int c = 0; c < a->points; c++)
        a->point_w[c] += dw[c];
}

/* psi_k: a point's shapes times sc (the stored state's coordinates). */
static double point_displacement(const membrane *m, const float *psi_k)
{
    double w = 0.0;
    for (int k = 0; k < m->count; k++)
        w += (double)psi_k[k] * m->q[k];
    return w * displacement_scale(m);
}

/* A pending move lands: the last force at the old place goes into the state, the
 * new shapes take over, and the point's object is told (a stick starts its stroke
 * at the surface there, contact.c). */
static void land_point(membrane *m, membrane_point *pt)
{
    if (pt->force_pending != 0.0) {
        for (int k = 0; k < m->count; k++) {
            float du = m->ep_k[k] * ((float)pt->force_pending * pt->psi[k]);
            m->q[k] += du;
            m->p[k] += du;
        }
    }
    float *t = pt->psi;
    pt->psi = pt->psi_next;
    pt->psi_next = t;
    pt->r_over_a = pt->move_r;
    pt->theta_deg = pt->move_theta;
    pt->move_pending = 0;
    point_couplings(m, pt);
    pt->force_pending = 0.0;
    pt->ops->landed(pt, point_displacement(m, pt->psi_k));
}

/* The first sample after `after` on which a pending move lands in a block of n, or n. */
static int next_move(const membrane *m, int after, int n)
{
    int next = n;
    for (int c = 0; c < m->point_count; c++) {
        const membrane_point *pt = m->points[c];
        if (pt->move_pending && pt->move_offset > after && pt->move_offset < next)
            next = pt->move_offset;
    }
    return next;
}

/* Sample i's output from the kernel's pickup sums and the points' direct terms
 * (extra): the gain's smoothing, a moved pickup's crossfade, the overflow guard.
 * 0 when the state overflowed and was cleared. */
static inline __attribute__((always_inline)) int emit_sample(membrane *m, const double *pick_sum,
                                                             const double *extra, int picks,
                                                             float *const *out, int i,
                                                             double gain_coef)
{
    double y[MEMBRANE_PICKUPS];
    int finite = 1;
    if (m->gain_smoothed != m->output_gain) {
        m->gain_smoothed += (m->output_gain - m->gain_smoothed) * gain_coef;
        if (fabs(m->gain_smoothed - m->output_gain) <= 1e-9 * fabs(m->output_gain))
            m->gain_smoothed = m->output_gain;
    }
    const double out_scale = m->gain_smoothed * m->mass_scale;
    y[1] = 0.0;
    for (int j = 0; j < picks; j++) {
        y[j] = out_scale * (pick_sum[j] + extra[j]);
        if (m->pick_fade_left[j] > 0) {
            /* Crossfade from a moved pickup: one more dot product per sample for
             * 5 ms (the points' direct term uses the new place throughout). */
            double old = 0.0;
            for (int k = 0; k < m->count; k++)
                old += (double)m->psi_pick_old[j][k] * m->sc[k] * m->p[k];
            double w = (double)m->pick_fade_left[j] / m->pick_fade_len;
            y[j] = (1.0 - w) * y[j] + w * out_scale * (old + extra[j]);
            m->pick_fade_left[j]--;
        }
        finite = finite && fabs(y[j]) <= FLT_MAX;
    }
    if (picks < MEMBRANE_PICKUPS && m->pick_fade_left[1] > 0)
        m->pick_fade_left[1]--; /* the skipped pickup's crossfade runs on */
    if (!finite) {
        /* Last line of defence (never reached with legal inputs in the tests):
         * a state that overflowed float is silenced rather than sent out. */
        membrane_clear(m);
        y[0] = y[1] = 0.0;
    }
    for (int j = 0; j < MEMBRANE_PICKUPS; j++) {
        if (out && out[j])
            out[j][i] = (float)y[j];
    }
    return finite;
}

/* Samples i and i + 1 of a block of n can run as one free pass (the pair kernel,
 * membrane_kernel.inc): no point folded in at i (the caller checks), no strike
 * force at either, no landing at i + 1 (a point could join), no strike queued at
 * either (it goes into the state after sample i), no pickup crossfade (it reads
 * the state after each sample). */
static int pair_ok(const membrane *m, const float *force_in, int i, int n, int next_landing)
{
    if (i + 1 >= n || next_landing == i + 1 || m->pick_fade_left[0] > 0 || m->pick_fade_left[1] > 0)
        return 0;
    if (force_in && (force_in[i] != 0.0f || force_in[i + 1] != 0.0f))
        return 0; /* NaN and inf (read as 0) take the one-sample path too */
    for (int s = 0; s < m->queued; s++)
        if (m->queue[s].offset == i || m->queue[s].offset == i + 1)
            return 0;
    return 1;
}

void membrane_process(membrane *m, const float *force_in, float *const *out, int n)
{
#ifdef MEMBRANE_X86
    /* Flush denormals to zero while the modes decay (restored on return): a
     * decaying float mode would otherwise crawl through the denormal range
     * at ~100x the cost. */
    unsigned int csr = _mm_getcsr();
    _mm_setcsr(csr | 0x8040u);
#endif
    const double T = 1.0 / m->sample_rate;
    /* One-pole gain smoothing, 5 ms time constant, per sample (block-size independent). */
    const double gain_coef = 1.0 - exp(-1.0 / (0.005 * m->sample_rate));
    membrane_kernel_args a;
    memset(&a, 0, sizeof(a));
    a.count = m->count;
    a.q = m->q, a.p = m->p, a.c1 = m->c1, a.cd = m->cd, a.c3 = m->c3;
    a.ep = m->ep_k;
    a.input_scale = (float)displacement_scale(m);
    const double wscale = displacement_scale(m);
    a.psi_strike = m->psi_strike;
    /* Pickups computed: both, or only the first when nothing takes the second. */
    const int picks = (out && !out[1]) ? 1 : MEMBRANE_PICKUPS;
    for (int j = 0; j < picks; j++)
        a.psi_pick[j] = m->pick_k[j];
    for (int c = 0; c < m->point_count; c++)
        m->points[c]->ops->block_begin(m->points[c], n);
    int next_landing = next_move(m, -1, n);

    for (int i = 0; i < n; i++) {
        float fin = force_in ? force_in[i] : 0.0f;
        if (!isfinite(fin))
            fin = 0.0f;
        /* Points landing now. */
        if (i == next_landing) {
            for (int c = 0; c < m->point_count; c++) {
                membrane_point *pt = m->points[c];
                if (pt->move_pending && pt->move_offset == i)
                    land_point(m, pt);
            }
            next_landing = next_move(m, i, n);
        }
        /* The kernel folds in the force of every point that is active, or whose
         * stroke just ended with its last force still to go in. */
        membrane_point *act[MEMBRANE_MAX_POINTS];
        int na = 0;
        for (int c = 0; c < m->point_count; c++) {
            membrane_point *pt = m->points[c];
            if (pt->active || pt->force_pending != 0.0) {
                act[na] = pt;
                a.point_psi[na] = pt->psi_k;
                a.point_force_pending[na] = (float)pt->force_pending;
                na++;
            }
        }
        a.points = na;
        a.strike_force = fin;
        if (na == 0 && pair_ok(m, force_in, i, n, next_landing)) {
            /* Ringing freely: samples i and i + 1 in one pass, bit-identical to two. */
            m->kernel_pair(&a);
            const double none[MEMBRANE_PICKUPS] = {0};
            if (emit_sample(m, a.pick_sum, none, picks, out, i, gain_coef)) {
                i++;
                emit_sample(m, a.pick_sum2, none, picks, out, i, gain_coef);
            }
            /* else the state was cleared after sample i: i + 1 runs from it alone */
            continue;
        }
        m->kernel(&a);
        for (int c = 0; c < na; c++)
            act[c]->force_pending = 0.0;
        /* Strikes landing now (queue order). */
        for (int s = 0; s < m->queued; s++) {
            if (m->queue[s].offset != i)
                continue;
            impulse_shape *shape =
                find_impulse_shape(m, m->queue[s].r_over_a, m->queue[s].theta_deg);
            if (!shape)
                shape = make_impulse_shape(m, m->queue[s].r_over_a, m->queue[s].theta_deg);
            add_input(m, shape->psi, m->queue[s].impulse_ns / T, &a);
        }
        double extra[MEMBRANE_PICKUPS] = {0};
        int nact = 0;
        for (int c = 0; c < na; c++) {
            if (act[c]->active) {
                /* Compact to the active points; c >= nact, so in-place is safe. */
                a.point_w[nact] = a.point_w[c] * wscale;
                act[nact++] = act[c];
            }
        }
        if (nact > 0) {
            double K[MEMBRANE_MAX_POINTS][MEMBRANE_MAX_POINTS];
            for (int r = 0; r < nact; r++) {
                K[r][r] = act[r]->self_compliance;
                /* Cross-compliance between two sticks on the same head (rare: only
                 * while two strokes overlap), sum psi_r dm psi_c eq. */
                for (int c = 0; c < nact; c++) {
                    if (c == r)
                        continue;
                    double s = 0.0;
                    for (int k = 0; k < m->count; k++)
                        s += (double)act[r]->psi[k] * act[c]->psi[k] * m->ep[k];
                    K[r][c] = s * wscale;
                }
            }
            act[0]->ops->solve(act, nact, a.point_w, (const double(*)[MEMBRANE_MAX_POINTS])K, T, i,
                               extra);
        }
        emit_sample(m, a.pick_sum, extra, picks, out, i, gain_coef);
    }
    /* Carry pending strikes and moves past this block. */
    int kept = 0;
    for (int s = 0; s < m->queued; s++) {
        if (m->queue[s].offset >= n) {
            m->queue[kept] = m->queue[s];
            m->queue[kept].offset -= n;
            kept++;
        }
    }
    m->queued = kept;
    for (int c = 0; c < m->point_count; c++)
        if (m->points[c]->move_pending)
            m->points[c]->move_offset -= n;
    if (m->fade_left > 0) {
        m->fade_left -= n;
        if (m->fade_left <= 0) {
            /* Rung out: drop them for good (no allocation, O(dropped modes)). */
            for (int k = m->modes; k < m->count; k++) {
                m->q[k] = m->p[k] = 0.0f;
                m->c1[k] = m->cd[k] = m->c3[k] = m->ep[k] = 0.0f;
                m->sc[k] = m->ep_k[k] = 0.0f;
                m->omega_model[k] = 0.0;
            }
            m->fading_modes = m->modes;
            m->count = padded(m->modes);
            m->fade_left = 0;
            for (int i = 0; i < IMPULSE_CACHE; i++)
                m->impulse_cache[i].valid = 0; /* shapes of the sounding modes only */
        }
    }
#ifdef MEMBRANE_X86
    _mm_setcsr(csr);
#endif
}

/* ---------------------------------------------------------------- getters */

double membrane_get_sample_rate(const membrane *m)
{
    return m->sample_rate;
}
double membrane_get_radius(const membrane *m)
{
    return m->radius;
}
double membrane_get_tension(const membrane *m)
{
    return m->tension;
}
double membrane_get_density(const membrane *m)
{
    return m->density;
}
double membrane_get_mass(const membrane *m)
{
    return m->density * M_PI * m->radius * m->radius;
}
int membrane_get_modes(const membrane *m)
{
    return m->modes;
}
int membrane_get_sounding_modes(const membrane *m)
{
    int sounding = 0;
    for (int k = 0; k < m->modes; k++)
        sounding += m->omega_model[k] > 0.0;
    return sounding;
}
double membrane_get_t60(const membrane *m)
{
    return m->t60;
}
double membrane_get_hf_damping(const membrane *m)
{
    return m->hf_damping;
}
double membrane_get_output_gain(const membrane *m)
{
    return m->output_gain;
}

int membrane_get_mode(const membrane *m, int k, double *freq_hz, double *t60_s, int *bessel_m,
                      int *bessel_n, int *sin_partner)
{
    if (k < 0 || k >= m->modes)
        return 0;
    double omega = m->table.j[k] * sqrt(m->tension / m->density) / m->radius;
    if (freq_hz)
        *freq_hz = omega / (2.0 * M_PI);
    if (t60_s)
        *t60_s = log(1000.0) / mode_decay_rate(m, omega);
    if (bessel_m)
        *bessel_m = m->table.m[k];
    if (bessel_n)
        *bessel_n = m->table.n[k];
    if (sin_partner)
        *sin_partner = m->table.sin[k];
    return 1;
}

/* State including the coupling-point forces not yet folded in (see the kernel). */
static void effective_state(const membrane *m, int k, double *q, double *p)
{
    double u = 0.0;
    for (int i = 0; i < m->point_count; i++)
        if (m->points[i]->force_pending != 0.0)
            u += m->points[i]->force_pending * m->points[i]->psi[k];
    /* q = h w' r, r = sc (stored q) (membrane_kernel.inc) */
    *q = ((double)m->sc[k] * m->q[k] + (double)m->ep[k] * u) * m->coef_h * m->omega_model[k];
    *p = (double)m->sc[k] * m->p[k] + (double)m->ep[k] * u;
}

static double point_sum(const membrane *m, double r_over_a, double theta_deg, int velocity)
{
    if (!isfinite(r_over_a) || !isfinite(theta_deg))
        return 0.0;
    clamp_point(&r_over_a, &theta_deg);
    double theta = theta_deg * (M_PI / 180.0), s = 0.0;
    for (int k = 0; k < m->modes; k++) {
        if (m->omega_model[k] <= 0.0)
            continue;
        double psi = mode_table_shape(&m->table, k, r_over_a, theta);
        double q, p;
        effective_state(m, k, &q, &p);
        s += velocity ? psi * p * m->mass_scale : psi * q * m->mass_scale / m->omega_model[k];
    }
    return s;
}

double membrane_displacement_at(const membrane *m, double r_over_a, double theta_deg)
{
    return point_sum(m, r_over_a, theta_deg, 0);
}

double membrane_velocity_at(const membrane *m, double r_over_a, double theta_deg)
{
    return point_sum(m, r_over_a, theta_deg, 1);
}

double membrane_energy(const membrane *m)
{
    double e = 0.0;
    for (int k = 0; k < m->count; k++) {
        double q, p;
        effective_state(m, k, &q, &p);
        e += 0.5 * (q * q + p * p);
    }
    return e;
}

long membrane_dropped_strikes(const membrane *m)
{
    return m->dropped;
}
