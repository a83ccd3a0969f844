/* membrane_modes.c -- the membrane's modes: the arrays of the modal state and its
 * coefficients, built for a mode count (the table of modes itself is mode_table.c),
 * and the coefficients computed from the physics (docs/membrane.md). */
#include "bessel_internal.h"
#include "membrane_internal.h"

#include <stdlib.h>
#include <string.h>

/* Gauss-Legendre nodes and weights on [0, pi/2], n = GL_STEP, 2 GL_STEP, ... GL_MAX:
 * computed once, the first time a head's radiation is computed (message time). */
#define GL_STEP 8
#define GL_MAX  128
static double gl_t[GL_MAX / GL_STEP][GL_MAX], gl_w[GL_MAX / GL_STEP][GL_MAX];
static int gl_ready[GL_MAX / GL_STEP];

static int gauss_legendre(int n, const double **t, const double **w)
{
    int row = (n + GL_STEP - 1) / GL_STEP;
    row = row < 1 ? 1 : row > GL_MAX / GL_STEP ? GL_MAX / GL_STEP : row;
    n = row * GL_STEP;
    double *tt = gl_t[row - 1], *ww = gl_w[row - 1];
    if (!gl_ready[row - 1]) {
        ictus_gauss_legendre(n, tt, ww); /* on [0, 1]: scaled to [0, pi/2] */
        for (int i = 0; i < n; i++)
            tt[i] *= 0.5 * M_PI, ww[i] *= 0.5 * M_PI;
        gl_ready[row - 1] = 1;
    }
    *t = tt;
    *w = ww;
    return n;
}

/* Air radiation of mode k of a head in an infinite baffle (1/s): the Rayleigh integral
 * of the mode shape J_m(j r/a) cos(m phi) gives the far field, whose power over the
 * half space, divided by twice the mode's energy, is
 *     sigma_rad = rho w^2 a^2 j^2 / (c sigma) int_0^{pi/2} J_m(x)^2 / (j^2 - x^2)^2 sin(t) dt,
 * x = k a sin(t), k = w / c (docs/membrane.md, "Losses"). At low ka the (0, n) modes
 * radiate as monopoles, rho T / (c sigma^2), and the m >= 1 modes (ka)^(2m) less.
 * Gauss-Legendre with 10 + 0.75 ka nodes (rounded up to GL_STEP): within 2e-3 of a
 * 2048-point rule on every mode of the 1024-mode presets for ka / j from 0.02 to 0.95
 * (1e-6 from 0.2 on), at a quarter of the 64-point midpoint rule's cost. */
static double radiation_integral(const membrane *m, int k, double omega)
{
    const int order = m->table.m[k];
    const double j = m->table.j[k], ka = omega / MEMBRANE_AIR_C * m->radius;
    const double dj = ictus_bessel_j(order + 1, j); /* |J_m'(j)| at a zero of J_m */
    const double *t, *w;
    const int steps = gauss_legendre(10 + (int)(0.75 * ka), &t, &w);
    double sum = 0.0;
    for (int i = 0; i < steps; i++) {
        double x = ka * sin(t[i]);
        double den = j * j - x * x;
        /* Near x = j the ratio tends to J_m'(j)^2 / (2 j)^2. */
        double v;
        if (fabs(den) < 1e-6 * j * j) {
            v = dj * dj / (4.0 * j * j);
        } else {
            double ratio = ictus_bessel_j(order, x) / den;
            v = ratio * ratio;
        }
        sum += w[i] * v * sin(t[i]);
    }
    return sum;
}

static double radiation_rate(const membrane *m, int k, double omega)
{
    membrane *mm = (membrane *)m; /* the cache only */
    if (m->plate)
        return 0.0; /* the baffled membrane's integral: not a plate's */
    const double c = membrane_wave_speed_(m), j = m->table.j[k];
    if (c != m->rad_c) {
        mm->rad_c = c;
        mm->rad_valid = 0;
    }
    double in;
    if (m->rad_int && k < m->capacity) {
        for (; m->rad_valid <= k; mm->rad_valid++)
            mm->rad_int[m->rad_valid] =
                radiation_integral(m, m->rad_valid, m->table.j[m->rad_valid] * c / m->radius);
        in = m->rad_int[k];
    } else {
        in = radiation_integral(m, k, omega);
    }
    return MEMBRANE_AIR_RHO * omega * omega * m->radius * m->radius * j * j /
           (MEMBRANE_AIR_C * m->density) * in;
}

/* Decay rate of mode k (1/s): the law sigma_k = s0 + s1 w_k^2 with s0 + s1 w_1^2 =
 * ln(1000)/t60 and s1 w_ref^2 = hf * s0 at w_ref = 2 pi 1 kHz, plus the air radiation
 * and the internal loss eta w / 2. */
static double mode_decay_rate(const membrane *m, int k, double omega)
{
    double omega1 = m->table.j[0] * membrane_wave_speed_(m) / m->radius;
    double w_ref = 2.0 * M_PI * 1000.0;
    double rate1 = log(1000.0) / m->t60;
    double s0 = rate1 / (1.0 + m->hf_damping * (omega1 / w_ref) * (omega1 / w_ref));
    double s1 = m->hf_damping * s0 / (w_ref * w_ref);
    double rate = s0 + s1 * omega * omega + 0.5 * m->loss_factor * omega;
    /* A dashpot of c N s/m^2 along the edge takes c times the edge integral of the
     * mass-normalised shape squared, psi^2 / (rho h a^2) over a dtheta, from twice the
     * rate: c edge_k / (2 rho h a) (docs/plates.md, "The hi-hat"). */
    const double closed = 1.0 - m->openness;
    if (m->edge_damp > 0.0 && m->table.edge)
        rate += closed * closed * m->edge_damp * m->table.edge[k] / (2.0 * m->density * m->radius);
    /* The power over the mode's energy, its air's mass included (scale^2 = 1 / (1 + beta)) */
    if (m->radiation > 0.0)
        rate += m->radiation * radiation_rate(m, k, omega) * m->table.scale[k] * m->table.scale[k];
    return rate;
}

/* Recomputes every coefficient from the physics. When rescale is set, the modal
 * state is rescaled so that each mode's physical displacement and velocity are
 * continuous across the change (no click from a parameter move). */
void membrane_update_coefficients_(membrane *m, int rescale)
{
    const double T = 1.0 / m->sample_rate, h = 0.5 * T;
    const double c = membrane_wave_speed_(m);
    const double old_scale = m->mass_scale, old_h = m->coef_h;
    m->mass_scale = 1.0 / sqrt(m->density * m->radius * m->radius);
    m->coef_h = h;
    const double scale = m->mass_scale;
    /* The air's mass on each mode (none on a plate): scale[k] = 1 / sqrt(1 + beta g_k), the
     * state rescaled by the old over the new (air_ratio) so the motion stays continuous */
    const double beta = m->plate ? 0.0 : m->air_mass * MEMBRANE_AIR_RHO * m->radius / m->density;
    if (beta > 0.0)
        mode_table_prepare_air(&m->table);
    for (int k = 0; k < m->capacity; k++) {
        const double air_was = m->table.scale[k];
        m->table.scale[k] = beta > 0.0 ? 1.0 / sqrt(1.0 + beta * m->table.air[k]) : 1.0;
        const double air_ratio = air_was / m->table.scale[k];
        double old_omega = m->omega_model[k];
        int fading = k >= m->modes;
        double freq = (k < m->fading_modes) ? mode_table_tuned_j(&m->table, k, &m->tuning) * c /
                                                  (2.0 * M_PI * m->radius)
                                            : 0.0;
        if (k >= m->fading_modes || freq >= 0.95 * 0.5 * m->sample_rate || freq <= 0.0) {
            /* Silent: frozen at zero, no input, no output. */
            m->c1[k] = m->cd[k] = m->c3[k] = m->ep[k] = 0.0f;
            m->sc[k] = m->ep_k[k] = 0.0f;
            m->q[k] = m->p[k] = 0.0f;
            m->omega_model[k] = 0.0;
            m->wm[k] = 0.0f;
            continue;
        }
        double omega = 2.0 * M_PI * freq;
        double sigma = fading ? log(1000.0) / FADE_S : mode_decay_rate(m, k, omega);
        if (!fading)
            sigma *= mode_table_decay_factor(&m->table, k, &m->tuning);
        /* Inverse bilinear map of the wanted discrete poles z = exp((-sigma +- i w) T):
         * s = (2/T) tanh((-sigma +- i w) T / 2) = a +- i b, so the midpoint rule's poles
         * land exactly on the target pitch and decay. */
        double u2 = sigma * T, v2 = omega * T;
        double den = cosh(u2) + cos(v2);
        double a = -(2.0 / T) * sinh(u2) / den;
        double b = (2.0 / T) * sin(v2) / den;
        double wm = sqrt(a * a + b * b); /* model stiffness w' */
        double sm = -a;                  /* model damping s' */
        m->wm0[k] = (float)wm;
        m->sm0[k] = (float)sm;
        if (!fading)
            wm *= m->tm_g; /* tension modulation (membrane_tension_update_) */
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
        if (fading) /* ringing out: no input (and zero input shapes, membrane_input_shapes_) */
            m->ep[k] = 0.0f;
        const double old_sc = m->sc[k];
        m->sc[k] = (float)sqrt((double)m->cd[k]);
        m->ep_k[k] = (float)(m->ep[k] / (double)m->sc[k]);
        if (rescale && old_omega > 0.0 && old_sc > 0.0) {
            /* y = q / (sqrt(M) w'), y' = p / sqrt(M), sqrt(M) proportional to 1/scale;
             * q = h w' r, so r scales by old_h / h (w' cancels); the stored r / sc and
             * p / sc by old_sc / sc besides. */
            double r = old_scale / scale * (old_sc / m->sc[k]) * air_ratio;
            m->q[k] = (float)(m->q[k] * r * old_h / h);
            m->p[k] = (float)(m->p[k] * r);
        } else if (rescale) {
            m->q[k] = m->p[k] = 0.0f;
        }
        m->omega_model[k] = wm;
        m->wm[k] = (float)wm;
    }
    membrane_cascade_refresh_(m);      /* a plate's von Karman coupling follows the physics */
    membrane_band_cascade_refresh_(m); /* and its energy cascade */
}

/* The float arrays of the modal state and coefficients, in their order in memory. */
enum {
    ARR_Q,
    ARR_P,
    ARR_C1,
    ARR_CD,
    ARR_C3,
    ARR_EP,
    ARR_PSI_STRIKE,
    ARR_PICK0,
    ARR_PICK1,
    ARR_PICK_OLD0,
    ARR_PICK_OLD1,
    ARR_SC,
    ARR_EP_K,
    ARR_PICK_K0,
    ARR_PICK_K1,
    ARR_WM0,
    ARR_SM0,
    ARR_WM,
    ARR_COUNT
};

/* A new set of the arrays that depend on the capacity, before it replaces the old. */
typedef struct mode_arrays {
    mode_table table;
    double *omega_model, *rad_int;
    float *f[ARR_COUNT];
    float *impulse[IMPULSE_CACHE];
    float *point_psi[MEMBRANE_MAX_POINTS][3]; /* psi, psi_next, psi_k of each point */
} mode_arrays;

static void mode_arrays_free(mode_arrays *a)
{
    mode_table_free(&a->table);
    free(a->omega_model);
    free(a->rad_int);
    for (int i = 0; i < ARR_COUNT; i++)
        free(a->f[i]);
    for (int i = 0; i < IMPULSE_CACHE; i++)
        free(a->impulse[i]);
    for (int i = 0; i < MEMBRANE_MAX_POINTS; i++)
        for (int j = 0; j < 3; j++)
            free(a->point_psi[i][j]);
}

/* Allocates every array at capacity cap (the points' for `points` points); 0, with
 * nothing left allocated, when memory cannot be had. */
static int mode_arrays_alloc(mode_arrays *a, int cap, int points, int plate)
{
    memset(a, 0, sizeof(*a));
    a->omega_model = calloc((size_t)cap, sizeof(double));
    a->rad_int = calloc((size_t)cap, sizeof(double));
    int ok = a->omega_model != NULL && a->rad_int != NULL;
    for (int i = 0; i < ARR_COUNT; i++) {
        a->f[i] = membrane_alloc_floats_(cap);
        ok = ok && a->f[i];
    }
    for (int i = 0; i < IMPULSE_CACHE; i++) {
        a->impulse[i] = membrane_alloc_floats_(cap);
        ok = ok && a->impulse[i];
    }
    for (int i = 0; i < points; i++) {
        for (int j = 0; j < 3; j++) {
            a->point_psi[i][j] = membrane_alloc_floats_(cap);
            ok = ok && a->point_psi[i][j];
        }
    }
    /* The table last: it computes the Bessel zeros in scratch memory that it
     * frees, and state arrays allocated after that landed at heap offsets
     * that cost ~5 % in bench_membrane_core (contact, 1024 modes). */
    ok = ok && mode_table_build(&a->table, cap, plate) == ICTUS_OK;
    if (!ok)
        mode_arrays_free(a);
    return ok;
}

/* Frees the arrays that depend on the capacity (not the points'). */
void membrane_free_mode_arrays_(membrane *m)
{
    mode_table_free(&m->table);
    free(m->omega_model);
    free(m->rad_int);
    m->rad_int = NULL;
    m->rad_valid = 0;
    free(m->q), free(m->p), free(m->c1), free(m->cd), free(m->c3);
    free(m->ep), free(m->psi_strike);
    free(m->sc), free(m->ep_k);
    free(m->wm0), free(m->sm0), free(m->wm);
    for (int i = 0; i < MEMBRANE_PICKUPS; i++) {
        free(m->psi_pick[i]);
        free(m->psi_pick_old[i]);
        free(m->pick_k[i]);
    }
    for (int i = 0; i < IMPULSE_CACHE; i++)
        free(m->impulse_cache[i].psi);
}

/* The new arrays replace the old; the state of the modes we had is kept (same
 * index = same mode). */
static void mode_arrays_install(membrane *m, mode_arrays *a, int cap)
{
    float **f = a->f;
    membrane_flush_points_(m);
    int keep = m->capacity < cap ? m->capacity : cap;
    if (m->q) {
        memcpy(f[ARR_Q], m->q, sizeof(float) * (size_t)keep);
        memcpy(f[ARR_P], m->p, sizeof(float) * (size_t)keep);
        memcpy(f[ARR_SC], m->sc, sizeof(float) * (size_t)keep); /* the state's scale */
        memcpy(f[ARR_WM], m->wm, sizeof(float) * (size_t)keep);
        memcpy(a->omega_model, m->omega_model, sizeof(double) * (size_t)keep);
        if (m->table.scale && m->table.size >= keep) /* the air's scale the state is in */
            memcpy(a->table.scale, m->table.scale, sizeof(double) * (size_t)keep);
    }
    membrane_free_mode_arrays_(m);
    m->table = a->table;
    m->omega_model = a->omega_model;
    m->rad_int = a->rad_int;
    m->rad_valid = 0;
    m->q = f[ARR_Q], m->p = f[ARR_P], m->c1 = f[ARR_C1], m->cd = f[ARR_CD];
    m->c3 = f[ARR_C3], m->ep = f[ARR_EP];
    m->psi_strike = f[ARR_PSI_STRIKE];
    m->psi_pick[0] = f[ARR_PICK0];
    m->psi_pick[1] = f[ARR_PICK1];
    m->psi_pick_old[0] = f[ARR_PICK_OLD0];
    m->psi_pick_old[1] = f[ARR_PICK_OLD1];
    m->sc = f[ARR_SC], m->ep_k = f[ARR_EP_K];
    m->pick_k[0] = f[ARR_PICK_K0];
    m->pick_k[1] = f[ARR_PICK_K1];
    m->wm0 = f[ARR_WM0], m->sm0 = f[ARR_SM0], m->wm = f[ARR_WM];
    for (int i = 0; i < MEMBRANE_PICKUPS; i++)
        m->pick_fade_left[i] = 0;
    for (int i = 0; i < IMPULSE_CACHE; i++) {
        m->impulse_cache[i].psi = a->impulse[i];
        m->impulse_cache[i].valid = 0;
    }
    for (int i = 0; i < m->point_count; i++) {
        membrane_point *pt = m->points[i];
        free(pt->psi), free(pt->psi_next), free(pt->psi_k);
        pt->psi = a->point_psi[i][0];
        pt->psi_next = a->point_psi[i][1];
        pt->psi_k = a->point_psi[i][2];
        pt->psi_cap = cap;
    }
    m->capacity = cap;
    /* A smaller set (the other kind of modes, laid after membrane_set_plate cleared the
     * state): no mode beyond it rings or fades. */
    if (m->fading_modes > cap || m->modes > cap) {
        m->modes = m->modes < cap ? m->modes : cap;
        m->fading_modes = m->modes;
        m->fade_left = 0;
        m->count = membrane_padded_(m->modes);
    }
}

/* The count becomes `modes`. Shrinking while sounding, the dropped modes ring out
 * over FADE_S instead of vanishing with a click. */
static void set_mode_count(membrane *m, int modes)
{
    int old_limit = m->fading_modes > m->modes ? m->fading_modes : m->modes;
    if (modes < old_limit && membrane_energy(m) > 0.0) {
        m->fading_modes = old_limit;
        m->fade_left = (long)(FADE_S * m->sample_rate) + 1;
    } else {
        m->fading_modes = modes;
        m->fade_left = 0;
    }
    m->modes = modes;
    m->count = membrane_padded_(m->fading_modes);
    /* Modes dropped now start from rest if they come back later. */
    for (int k = m->fading_modes; k < m->capacity; k++)
        m->q[k] = m->p[k] = 0.0f;
}

void membrane_refresh_shapes_(membrane *m)
{
    for (int i = 0; i < IMPULSE_CACHE; i++)
        m->impulse_cache[i].valid = 0;
    membrane_input_shapes_(m, m->strike_r, m->strike_theta, m->psi_strike);
    for (int i = 0; i < MEMBRANE_PICKUPS; i++)
        membrane_mode_shapes_(m, m->pick_r[i], m->pick_theta[i], m->psi_pick[i]);
    for (int i = 0; i < m->point_count; i++) {
        membrane_point *pt = m->points[i];
        membrane_point_shapes_(m, pt, pt->psi);
        if (pt->move_pending)
            membrane_input_shapes_(m, pt->move_r, pt->move_theta, pt->psi_next);
    }
}

ictus_status membrane_set_plate(membrane *m, int plate)
{
    plate = plate != 0;
    if (m->plate == plate)
        return ICTUS_OK;
    membrane_clear(m);
    /* Nothing rings: the modes a preset dropped while sounding stop fading now. */
    m->fading_modes = m->modes;
    m->fade_left = 0;
    m->count = membrane_padded_(m->modes);
    m->plate = plate;
    mode_table_free(&m->table); /* the next build lays the other kind's modes */
    return membrane_build_modes_(m, m->modes);
}

int membrane_is_plate(const membrane *m)
{
    return m->plate;
}

/* Keeps the state of the modes in both the old and the new table: a mode keeps its
 * index (the order is a prefix property of the sort, mode_table.h). */
ictus_status membrane_build_modes_(membrane *m, int modes)
{
    int need = membrane_padded_(modes);
    if (need > m->capacity || !m->table.j) {
        mode_arrays a;
        if (!mode_arrays_alloc(&a, need, m->point_count, m->plate))
            return ICTUS_ENOMEM;
        mode_arrays_install(m, &a, need);
    } else {
        membrane_flush_points_(m);
        for (int i = 0; i < IMPULSE_CACHE; i++)
            m->impulse_cache[i].valid = 0;
    }
    set_mode_count(m, modes);
    membrane_update_coefficients_(m, 1);
    membrane_refresh_shapes_(m);
    membrane_refresh_couplings_(m);
    return ICTUS_OK;
}

int membrane_get_sounding_modes(const membrane *m)
{
    int sounding = 0;
    for (int k = 0; k < m->modes; k++)
        sounding += m->omega_model[k] > 0.0;
    return sounding;
}

int membrane_get_mode(const membrane *m, int k, double *freq_hz, double *t60_s, int *bessel_m,
                      int *bessel_n, int *sin_partner)
{
    if (k < 0 || k >= m->modes)
        return 0;
    double omega =
        mode_table_tuned_j(&m->table, k, &m->tuning) * membrane_wave_speed_(m) / m->radius;
    if (freq_hz)
        *freq_hz = omega / (2.0 * M_PI);
    if (t60_s)
        *t60_s = log(1000.0) /
                 (mode_decay_rate(m, k, omega) * mode_table_decay_factor(&m->table, k, &m->tuning));
    if (bessel_m)
        *bessel_m = m->table.m[k];
    if (bessel_n)
        *bessel_n = m->table.n[k];
    if (sin_partner)
        *sin_partner = m->table.sin[k];
    return 1;
}

/* ---------------------------------------------------------------- tension modulation
 *
 * The averaged-tension model (docs/membrane.md, "Tension modulation"): the head's
 * mean stretch raises its tension, T = T0 (1 + kappa E), and every mode's w' follows
 * g = sqrt(T / T0). */

double membrane_tension_kappa(const membrane *m)
{
    /* Biaxial strain eps = (1/4A) int |grad w|^2 dA, dT = Y H eps / (1 - nu); the
     * strain integral is 2 V / T0 (V the potential energy), and V averages E / 2:
     * kappa = Y H / (4 (1 - nu) pi a^2 T0^2), H = density / rho. */
    if (m->plate)
        return 0.0; /* a membrane's stretch */
    const double H = m->density / MEMBRANE_MYLAR_RHO;
    const double area = M_PI * m->radius * m->radius;
    return m->tension_mod * MEMBRANE_MYLAR_YOUNG * H /
           (4.0 * (1.0 - MEMBRANE_MYLAR_POISSON) * area * m->tension * m->tension);
}

double membrane_frequency_factor(const membrane *m)
{
    return m->tm_g;
}

/* The coefficients of the sounding modes at factor g (float, as
 * membrane_update_coefficients_ makes them with w' = g wm0), the stored state converted
 * so that each mode's energy (q, p) is kept, and the pickups' shapes in the new sc: one
 * vector pass (membrane_kernel.inc). The points' couplings follow when a point next
 * takes part in a sample: no point does while the tension changes, and a head glides
 * through ~100 updates between two strokes. */
static void rebuild_coefficients(membrane *m, float g, int live)
{
    membrane_tension_args a;
    memset(&a, 0, sizeof(a));
    a.count = m->count;
    a.live = live;
    a.g = g;
    a.h = (float)m->coef_h;
    a.ept = (float)(m->mass_scale / m->sample_rate); /* ep = scale T / D */
    a.wm0 = m->wm0, a.sm0 = m->sm0, a.wm = m->wm;
    a.q = m->q, a.p = m->p, a.c1 = m->c1, a.cd = m->cd, a.c3 = m->c3;
    a.ep = m->ep, a.sc = m->sc, a.ep_k = m->ep_k;
    for (int j = 0; j < MEMBRANE_PICKUPS; j++) {
        a.psi_pick[j] = m->psi_pick[j];
        a.pick_k[j] = m->pick_k[j];
    }
    m->tension_kernel(&a);
    for (int k = 0; k < live; k++)
        m->omega_model[k] = m->wm[k]; /* 0 for the silent modes, as wm */
    m->couplings_stale = m->point_count > 0;
}

int membrane_tension_update_(membrane *m)
{
    /* Not during a stroke (a stick touching, or flying close above the head): the
     * update keeps each mode's energy, so the displacement under the stick moves by a
     * fraction of the change of g, which a stiff contact would turn into a force step
     * and the contact's potential into energy from nowhere. The tension follows on
     * the first sample after the stroke (the stick 5 mm clear, docs/membrane.md). */
    for (int i = 0; i < m->point_count; i++)
        if (m->points[i]->active || m->points[i]->force_pending != 0.0)
            return 0;
    const double kappa = membrane_tension_kappa(m);
    if (kappa <= 0.0 && m->tm_g == 1.0)
        return 1;
    /* The sounding modes: the fading ones take no part. */
    const int live = m->modes < m->count ? m->modes : m->count;
    double e = m->energy_kernel(m->q, m->p, m->wm, m->sc, (float)m->coef_h, live);
    double g = sqrt(1.0 + kappa * e);
    if (!(g <= TM_G_MAX))
        g = TM_G_MAX; /* also NaN */
    if (fabs(g - m->tm_g) <= TM_THRESHOLD * m->tm_g && !(g == 1.0 && m->tm_g != 1.0))
        return 1;
    if (fabs(g - 1.0) <= TM_THRESHOLD)
        g = 1.0;
    m->tm_g = g;
    rebuild_coefficients(m, (float)g, live);
    return 1;
}
