/* membrane.c -- modal circular membrane (see membrane.h, docs/membrane.md): life
 * cycle, pickups and strike point, the processing loop and the read-back of the
 * state. The mode arrays and coefficients are in membrane_modes.c, the strikes and
 * coupling points in membrane_points.c, the one-number parameters in
 * membrane_params.c, the table of modes in mode_table.c, the modal update in
 * membrane_kernel.inc, and the stick's stroke in contact.c, which the membrane only
 * calls through membrane_point_ops (membrane_internal.h). */
#define _POSIX_C_SOURCE 200112L
#include "membrane_internal.h"
#include "ictus_simd.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#if defined(__x86_64__) || defined(__i386__)
#include <xmmintrin.h>
#define MEMBRANE_X86 1
#endif

float *membrane_alloc_floats_(int n)
{
    void *ptr = NULL;
    if (posix_memalign(&ptr, 64, sizeof(float) * (size_t)n) != 0)
        return NULL;
    memset(ptr, 0, sizeof(float) * (size_t)n);
    return ptr;
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
    m->tension_mod = MEMBRANE_DEFAULT_TENSION_MOD;
    m->radiation = MEMBRANE_DEFAULT_RADIATION;
    m->loss_factor = MEMBRANE_DEFAULT_LOSS_FACTOR;
    m->patch = MEMBRANE_DEFAULT_PATCH;
    m->bending = MEMBRANE_DEFAULT_BENDING;
    m->openness = MEMBRANE_DEFAULT_OPENNESS;
    m->edge_damp = MEMBRANE_DEFAULT_EDGE_DAMP;
    m->tm_g = 1.0;
    m->output_gain = MEMBRANE_DEFAULT_GAIN;
    m->gain_smoothed = MEMBRANE_DEFAULT_GAIN;
    m->strike_r = 0.3;
    m->pick_r[0] = 0.5;
    m->pick_r[1] = 0.5;
    m->pick_theta[1] = 90.0;
    /* The widest kernels the CPU runs; ICTUS_MEMBRANE_KERNEL=generic or avx2 caps them,
     * e.g. to benchmark one inside Pd (bench/peers); read when the object is made. */
    membrane_use_kernel_(m, ictus_simd_level());
    if (membrane_reserve_strikes(m, STRIKE_QUEUE) != ICTUS_OK ||
        membrane_build_modes_(m, MEMBRANE_DEFAULT_MODES) != ICTUS_OK) {
        membrane_free(m);
        return NULL;
    }
    return m;
}

ictus_status membrane_reserve_strikes(membrane *m, int count)
{
    if (count <= m->queue_cap)
        return ICTUS_OK;
    pending_strike *q = malloc(sizeof(*q) * (size_t)count);
    if (!q)
        return ICTUS_ENOMEM;
    if (m->queued > 0)
        memcpy(q, m->queue, sizeof(*q) * (size_t)m->queued);
    free(m->queue);
    m->queue = q;
    m->queue_cap = count;
    return ICTUS_OK;
}

void membrane_free(membrane *m)
{
    if (!m)
        return;
    while (m->point_count > 0)
        membrane_point_detach_(m, m->points[m->point_count - 1]);
    membrane_free_mode_arrays_(m);
    membrane_cascade_free_(m);
    free(m->queue);
    free(m);
}

/* Each instruction set's kernels, by ictus_simd level. */
static const struct kernel_set {
    void (*kernel)(membrane_kernel_args *);
    void (*pair)(membrane_kernel_args *);
    void (*tension)(membrane_tension_args *);
    void (*couplings)(membrane_tension_args *);
    double (*energy)(const float *, const float *, const float *, const float *, float, int);
} kernel_sets[] = {
    {membrane_kernel_generic, membrane_kernel_pair_generic, membrane_tension_kernel_generic,
     membrane_couplings_kernel_generic, membrane_energy_kernel_generic},
    {membrane_kernel_avx2, membrane_kernel_pair_avx2, membrane_tension_kernel_avx2,
     membrane_couplings_kernel_avx2, membrane_energy_kernel_avx2},
    {membrane_kernel_avx512, membrane_kernel_pair_avx512, membrane_tension_kernel_avx512,
     membrane_couplings_kernel_avx512, membrane_energy_kernel_avx512},
};

void membrane_use_kernel_(membrane *m, int level)
{
    const struct kernel_set *k =
        &kernel_sets[level >= ICTUS_SIMD_GENERIC && level <= ICTUS_SIMD_AVX512 ? level : 0];
    m->kernel = k->kernel;
    m->kernel_pair = k->pair;
    m->tension_kernel = k->tension;
    m->couplings_kernel = k->couplings;
    m->energy_kernel = k->energy;
}

void membrane_use_generic_kernel_(membrane *m)
{
    membrane_use_kernel_(m, ICTUS_SIMD_GENERIC);
}

const char *membrane_kernel_name(const membrane *m)
{
    for (int level = ICTUS_SIMD_AVX512; level > ICTUS_SIMD_GENERIC; level--)
        if (m->kernel == kernel_sets[level].kernel)
            return ictus_simd_name((ictus_simd)level);
    return ictus_simd_name(ICTUS_SIMD_GENERIC);
}

/* ---------------------------------------------------------------- pickups, strike point */

ictus_status membrane_set_pickup(membrane *m, int index, double r_over_a, double theta_deg)
{
    ictus_status s = membrane_clamp_point_(&r_over_a, &theta_deg);
    if (index < 0 || index >= MEMBRANE_PICKUPS)
        return ICTUS_CLAMPED; /* no such pickup: nothing changed */
    m->pick_r[index] = r_over_a;
    m->pick_theta[index] = theta_deg;
    memcpy(m->psi_pick_old[index], m->psi_pick[index], sizeof(float) * (size_t)m->capacity);
    membrane_mode_shapes_(m, r_over_a, theta_deg, m->psi_pick[index]);
    /* 5 ms linear crossfade from the old point, when there is something to hear. */
    m->pick_fade_len = (int)(0.005 * m->sample_rate) + 1;
    m->pick_fade_left[index] = membrane_energy(m) > 0.0 ? m->pick_fade_len : 0;
    membrane_refresh_couplings_(m);
    return s;
}

ictus_status membrane_set_strike_point(membrane *m, double r_over_a, double theta_deg)
{
    ictus_status s = membrane_clamp_point_(&r_over_a, &theta_deg);
    m->strike_r = r_over_a;
    m->strike_theta = theta_deg;
    membrane_input_shapes_(m, r_over_a, theta_deg, m->psi_strike);
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
    membrane_cascade_cleared_(m);
}

/* ---------------------------------------------------------------- process */

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
    if (m->vk_on)
        return 0; /* the von Karman coupling runs after every sample */
    if (m->tm_countdown == 1 && (m->tension_mod > 0.0 || m->tm_g != 1.0))
        return 0; /* a tension update comes before sample i + 1 */
    if (m->bc_on && m->bc_countdown == 1)
        return 0; /* an energy cascade update comes before sample i + 1 */
    if (force_in && (force_in[i] != 0.0f || force_in[i + 1] != 0.0f))
        return 0; /* NaN and inf (read as 0) take the one-sample path too */
    for (int s = 0; s < m->queued; s++)
        if (m->queue[s].offset == i || m->queue[s].offset == i + 1)
            return 0;
    return 1;
}

/* The kernel's arguments for a block: the state, the coefficients and the shapes
 * of the strike point and of the pickups computed (picks of them). */
static void kernel_args_init(membrane *m, membrane_kernel_args *a, int picks)
{
    memset(a, 0, sizeof(*a));
    a->count = m->count;
    a->q = m->q, a->p = m->p, a->c1 = m->c1, a->cd = m->cd, a->c3 = m->c3;
    a->ep = m->ep_k;
    a->input_scale = (float)membrane_displacement_scale_(m);
    a->psi_strike = m->psi_strike;
    for (int j = 0; j < picks; j++)
        a->psi_pick[j] = m->pick_k[j];
}

/* The points whose moves land at sample i; returns the next landing after i. */
static int land_points(membrane *m, int i, int n)
{
    for (int c = 0; c < m->point_count; c++) {
        membrane_point *pt = m->points[c];
        if (pt->move_pending && pt->move_offset == i)
            membrane_land_point_(m, pt);
    }
    return next_move(m, i, n);
}

/* The points whose force the kernel folds in: every point that is active, or whose
 * stroke just ended with its last force still to go in. Into act and a; their count. */
static inline __attribute__((always_inline)) int gather_points(membrane *m, membrane_kernel_args *a,
                                                               membrane_point **act)
{
    int na = 0;
    for (int c = 0; c < m->point_count; c++) {
        membrane_point *pt = m->points[c];
        if (pt->active || pt->force_pending != 0.0) {
            if (m->couplings_stale)
                membrane_refresh_point_couplings_(m);
            act[na] = pt;
            a->point_psi[na] = pt->psi_k;
            a->point_force_pending[na] = (float)pt->force_pending;
            na++;
        }
    }
    return na;
}

/* The queued strikes landing at sample i, in queue order; 1 when one did. */
static inline int land_strikes(membrane *m, int i, double T, membrane_kernel_args *a)
{
    int landed = 0;
    for (int s = 0; s < m->queued; s++) {
        if (m->queue[s].offset != i)
            continue;
        const impulse_shape *shape =
            membrane_impulse_shape_(m, m->queue[s].r_over_a, m->queue[s].theta_deg);
        membrane_add_input_(m, shape->psi, m->queue[s].impulse_ns / T, a);
        landed = 1;
    }
    return landed;
}

/* Solves the forces of the active points among act[0..na) for sample i (their
 * displacements in a->point_w, scaled by wscale here); their direct path to the
 * pickups goes into extra. */
static inline void solve_points(membrane *m, membrane_point **act, int na, membrane_kernel_args *a,
                                double wscale, double T, int i, double extra[MEMBRANE_PICKUPS])
{
    int nact = 0;
    for (int c = 0; c < na; c++) {
        if (act[c]->active) {
            /* Compact to the active points; c >= nact, so in-place is safe. */
            a->point_w[nact] = a->point_w[c] * wscale;
            act[nact++] = act[c];
        }
    }
    if (nact == 0)
        return;
    double K[MEMBRANE_MAX_POINTS][MEMBRANE_MAX_POINTS];
    for (int r = 0; r < nact; r++) {
        K[r][r] = act[r]->self_compliance + act[r]->residual_compliance;
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
    /* Points of one kind (the same ops: sticks, snare wires) are solved together; the
     * kinds see each other's forces through the modes a sample later. */
    int done = 0;
    for (int g = 0; g < nact; g++) {
        if (done & (1 << g))
            continue;
        membrane_point *sub[MEMBRANE_MAX_POINTS];
        double subw[MEMBRANE_MAX_POINTS], subK[MEMBRANE_MAX_POINTS][MEMBRANE_MAX_POINTS];
        int idx[MEMBRANE_MAX_POINTS], ns = 0;
        for (int c = g; c < nact; c++)
            if (act[c]->ops == act[g]->ops) {
                idx[ns] = c;
                sub[ns] = act[c];
                subw[ns++] = a->point_w[c];
                done |= 1 << c;
            }
        if (ns == nact) {
            act[0]->ops->solve(act, nact, a->point_w, (const double(*)[MEMBRANE_MAX_POINTS])K, T, i,
                               extra);
            return;
        }
        for (int r = 0; r < ns; r++)
            for (int c = 0; c < ns; c++)
                subK[r][c] = K[idx[r]][idx[c]];
        sub[0]->ops->solve(sub, ns, subw, (const double(*)[MEMBRANE_MAX_POINTS])subK, T, i, extra);
    }
}

/* After a block of n: pending strikes and moves carry past it, and modes that have
 * rung out are dropped for good (no allocation, O(dropped modes)). */
static void block_end(membrane *m, int n)
{
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
    if (m->fade_left <= 0)
        return;
    m->fade_left -= n;
    if (m->fade_left > 0)
        return;
    for (int k = m->modes; k < m->count; k++) {
        m->q[k] = m->p[k] = 0.0f;
        m->c1[k] = m->cd[k] = m->c3[k] = m->ep[k] = 0.0f;
        m->sc[k] = m->ep_k[k] = 0.0f;
        m->omega_model[k] = 0.0;
        m->wm[k] = 0.0f;
    }
    m->fading_modes = m->modes;
    m->count = membrane_padded_(m->modes);
    m->fade_left = 0;
    for (int i = 0; i < IMPULSE_CACHE; i++)
        m->impulse_cache[i].valid = 0; /* shapes of the sounding modes only */
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
    /* Pickups computed: both, or only the first when nothing takes the second. */
    const int picks = (out && !out[1]) ? 1 : MEMBRANE_PICKUPS;
    membrane_kernel_args a;
    kernel_args_init(m, &a, picks);
    const double wscale = membrane_displacement_scale_(m);
    for (int c = 0; c < m->point_count; c++)
        m->points[c]->ops->block_begin(m->points[c], n);
    int next_landing = next_move(m, -1, n);
    const float force_cap = (float)MEMBRANE_FORCE_MAX;

    for (int i = 0; i < n; i++) {
        /* NaN/inf: 0; beyond +-MEMBRANE_FORCE_MAX N (a contact's cap): the cap. */
        float fin = force_in ? ictus_clamp_force(force_in[i], force_cap) : 0.0f;
        if (i == next_landing)
            next_landing = land_points(m, i, n);
        if (m->tension_mod > 0.0 || m->tm_g != 1.0) {
            /* Every TM_INTERVAL samples of absolute time: block-size independent. */
            if (m->tm_countdown <= 0 && membrane_tension_update_(m))
                m->tm_countdown = TM_INTERVAL;
        }
        if (m->bc_on && m->bc_countdown <= 0 && membrane_band_cascade_update_(m))
            m->bc_countdown = m->bc_interval; /* absolute time, as the tension update */
        membrane_point *act[MEMBRANE_MAX_POINTS];
        int na = gather_points(m, &a, act);
        a.points = na;
        a.strike_force = fin;
        if (na == 0 && pair_ok(m, force_in, i, n, next_landing)) {
            /* Ringing freely: samples i and i + 1 in one pass, bit-identical to two. */
            m->kernel_pair(&a);
            if (m->tm_countdown > 0)
                m->tm_countdown -= 2;
            if (m->bc_countdown > 0)
                m->bc_countdown -= 2;
            const double none[MEMBRANE_PICKUPS] = {0};
            if (emit_sample(m, a.pick_sum, none, picks, out, i, gain_coef)) {
                i++;
                emit_sample(m, a.pick_sum2, none, picks, out, i, gain_coef);
            }
            /* else the state was cleared after sample i: i + 1 runs from it alone */
            continue;
        }
        m->kernel(&a);
        if (m->tm_countdown > 0)
            m->tm_countdown--;
        if (m->bc_countdown > 0)
            m->bc_countdown--;
        for (int c = 0; c < na; c++)
            act[c]->force_pending = 0.0;
        int struck = land_strikes(m, i, T, &a);
        double extra[MEMBRANE_PICKUPS] = {0};
        if (m->vk_on)
            membrane_cascade_step_(m, &a, struck || na > 0 || fin != 0.0f, extra, picks);
        solve_points(m, act, na, &a, wscale, T, i, extra);
        emit_sample(m, a.pick_sum, extra, picks, out, i, gain_coef);
    }
    block_end(m, n);
#ifdef MEMBRANE_X86
    _mm_setcsr(csr);
#endif
}

/* ---------------------------------------------------------------- read-back */

double membrane_get_sample_rate(const membrane *m)
{
    return m->sample_rate;
}

int membrane_get_modes(const membrane *m)
{
    return m->modes;
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
    membrane_clamp_point_(&r_over_a, &theta_deg);
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
