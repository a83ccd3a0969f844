/* membrane_points.c -- what comes into the membrane at a point: the strike queue
 * with its cache of shapes, and the mode-space side of the coupling points
 * (membrane_internal.h): their shapes, couplings, and forces folded into the modes. */
#include "membrane_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------- coupling points */

/* Adds pt's last force, not yet in the modal state, to the state. */
static void fold_pending_force(membrane *m, const membrane_point *pt)
{
    for (int k = 0; k < m->count; k++) {
        float du = m->ep_k[k] * ((float)pt->force_pending * pt->psi[k]);
        m->q[k] += du;
        m->p[k] += du;
    }
}

void membrane_flush_points_(membrane *m)
{
    if (!m->q)
        return;
    for (int i = 0; i < m->point_count; i++) {
        membrane_point *pt = m->points[i];
        if (pt->force_pending != 0.0 && pt->psi)
            fold_pending_force(m, pt);
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

/* The static compliance a stick feels from the modes left out: the whole head's, for a
 * force spread over the patch and the displacement averaged over it (the membrane's
 * Green's function, (ln((1 - u^2) / eps) + 1/4) / (2 pi T) at u = r/a, eps = patch/a;
 * exact at the centre, the disc's own mean log distance giving the 1/4), less the
 * modes' own, sum psi_k^2 / (T j_k^2) (psi mass-normalised over the unit disc, the
 * patch's means included). Quasi-static: it acts at once, in series with the modes
 * (docs/membrane.md, "The contact patch"). */
static double residual_compliance(const membrane *m, const membrane_point *pt)
{
    const double eps = m->patch / m->radius, u = pt->r_over_a;
    if (m->plate || !pt->static_correction || !(eps > 0.0) || u * u >= 1.0 - eps)
        return 0.0;
    double modal = 0.0;
    for (int k = 0; k < m->modes && k < m->table.size; k++) {
        /* psi carries the air's scale, and the mode rings at j scale: its static
         * compliance is the bare mode's */
        const double js = m->table.j[k] * m->table.scale[k];
        modal += (double)pt->psi[k] * pt->psi[k] / (js * js);
    }
    const double whole = (log((1.0 - u * u) / eps) + 0.25) / (2.0 * M_PI);
    return whole > modal ? (whole - modal) / m->tension : 0.0;
}

static void point_couplings(membrane *m, membrane_point *pt)
{
    /* w changes by K F over a sample: K = sum psi dm psi eq = scale h sum psi^2 ep
     * (docs/membrane.md). */
    double K = 0.0;
    for (int k = 0; k < m->count; k++)
        K += (double)pt->psi[k] * pt->psi[k] * m->ep[k];
    pt->self_compliance = K * membrane_displacement_scale_(m);
    pt->residual_compliance = residual_compliance(m, pt);
    for (int j = 0; j < MEMBRANE_PICKUPS; j++)
        pt->pick_coupling[j] = dot_psi(m, m->psi_pick[j], pt->psi, m->ep);
    for (int k = 0; k < m->capacity; k++)
        pt->psi_k[k] = pt->psi[k] * m->sc[k];
}

void membrane_refresh_point_couplings_(membrane *m)
{
    membrane_tension_args a;
    memset(&a, 0, sizeof(a));
    a.count = m->count;
    a.sc = m->sc, a.ep = m->ep;
    for (int j = 0; j < MEMBRANE_PICKUPS; j++)
        a.psi_pick[j] = m->psi_pick[j];
    membrane_point *pts[MEMBRANE_MAX_POINTS];
    for (int i = 0; i < m->point_count; i++) {
        if (!m->points[i]->psi)
            continue;
        pts[a.points] = m->points[i];
        a.psi[a.points] = m->points[i]->psi;
        a.psi_k[a.points++] = m->points[i]->psi_k;
    }
    if (a.points > 0)
        m->couplings_kernel(&a);
    const double scale = membrane_displacement_scale_(m);
    for (int c = 0; c < a.points; c++) {
        pts[c]->self_compliance = a.self_sum[c] * scale;
        for (int j = 0; j < MEMBRANE_PICKUPS; j++)
            pts[c]->pick_coupling[j] = a.pick_coupling[c][j];
    }
    m->couplings_stale = 0;
}

void membrane_refresh_couplings_(membrane *m)
{
    if (!m->sc)
        return;
    m->couplings_stale = 0;
    for (int j = 0; j < MEMBRANE_PICKUPS; j++)
        for (int k = 0; k < m->capacity; k++)
            m->pick_k[j][k] = m->psi_pick[j][k] * m->sc[k];
    for (int i = 0; i < m->point_count; i++)
        if (m->points[i]->psi)
            point_couplings(m, m->points[i]);
}

void membrane_point_shapes_(const membrane *m, const membrane_point *pt, float *psi)
{
    if (pt->ops->shapes)
        pt->ops->shapes(m, pt, m->modes, psi);
    else
        membrane_input_shapes_(m, pt->r_over_a, pt->theta_deg, psi);
}

/* ---------------------------------------------------------------- attach, detach, move */

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
        arr[j] = membrane_alloc_floats_(m->capacity);
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
    membrane_point_shapes_(m, pt, pt->psi);
    if (pt->move_pending)
        membrane_input_shapes_(m, pt->move_r, pt->move_theta, pt->psi_next);
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
        membrane_flush_points_(m);
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
        const impulse_shape *shape = membrane_impulse_shape_(m, r_over_a, theta_deg);
        memcpy(pt->psi_next, shape->psi, sizeof(float) * (size_t)m->capacity);
    }
}

/* ---------------------------------------------------------------- strikes */

static impulse_shape *find_impulse_shape(membrane *m, double r, double theta)
{
    for (int i = 0; i < IMPULSE_CACHE; i++)
        if (m->impulse_cache[i].valid && m->impulse_cache[i].r_over_a == r &&
            m->impulse_cache[i].theta_deg == theta)
            return &m->impulse_cache[i];
    return NULL;
}

impulse_shape *membrane_impulse_shape_(membrane *m, double r, double theta)
{
    impulse_shape *s = find_impulse_shape(m, r, theta);
    if (s)
        return s;
    s = &m->impulse_cache[m->impulse_next];
    m->impulse_next = (m->impulse_next + 1) % IMPULSE_CACHE;
    membrane_input_shapes_(m, r, theta, s->psi);
    s->r_over_a = r;
    s->theta_deg = theta;
    s->valid = 1;
    return s;
}

ictus_status membrane_strike(membrane *m, double r_over_a, double theta_deg, double impulse_ns,
                             int sample_offset)
{
    ictus_status s = membrane_clamp_point_(&r_over_a, &theta_deg);
    /* An impulse beyond 1e3 N s is no drum stroke; clamp rather than overflow floats. */
    if (ictus_clamp(&impulse_ns, -MEMBRANE_IMPULSE_MAX, MEMBRANE_IMPULSE_MAX, 0.0) != ICTUS_OK)
        s = ICTUS_CLAMPED;
    if (sample_offset < 0) {
        sample_offset = 0;
        s = ICTUS_CLAMPED;
    }
    if (m->queued >= m->queue_cap) {
        m->dropped++;
        return ICTUS_CLAMPED;
    }
    /* Shapes are computed here, in the message handler, so that the audio loop
     * only looks them up (it recomputes only if four other points evicted it). */
    membrane_impulse_shape_(m, r_over_a, theta_deg);
    pending_strike *p = &m->queue[m->queued++];
    p->r_over_a = r_over_a;
    p->theta_deg = theta_deg;
    p->impulse_ns = impulse_ns;
    p->offset = sample_offset;
    return s;
}

/* ---------------------------------------------------------------- in the loop */

/* Adds an input impulse (force F over one sample along shape psi) after the
 * step: linear, so it equals passing it through the step's input. Updates the
 * pickup sums and coupling-point displacements of this sample too (a's shapes are
 * the kernel's, times sc, as the state). */
void membrane_add_input_(membrane *m, const float *psi, double force, membrane_kernel_args *a)
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

/* sum psi_k x over the modes: psi_k is a point's shapes times sc, x a stored state array
 * (held over sc, membrane_kernel.inc). */
static double point_sum_k(const membrane *m, const float *psi_k, const float *x)
{
    double s = 0.0;
    for (int k = 0; k < m->count; k++)
        s += (double)psi_k[k] * x[k];
    return s;
}

static double point_displacement(const membrane *m, const float *psi_k)
{
    return point_sum_k(m, psi_k, m->q) * membrane_displacement_scale_(m);
}

/* The velocity there (m/s, positive into the head): the pickups' own sum. */
static double point_velocity(const membrane *m, const float *psi_k)
{
    return point_sum_k(m, psi_k, m->p) * m->mass_scale;
}

/* A pending move lands: the last force at the old place goes into the state, the
 * new shapes take over, and the point's object is told where the head is there and
 * how fast it moves (a stick starts its stroke at the surface, contact.c). */
void membrane_land_point_(membrane *m, membrane_point *pt)
{
    if (pt->force_pending != 0.0)
        fold_pending_force(m, pt);
    float *t = pt->psi;
    pt->psi = pt->psi_next;
    pt->psi_next = t;
    pt->r_over_a = pt->move_r;
    pt->theta_deg = pt->move_theta;
    pt->move_pending = 0;
    point_couplings(m, pt);
    pt->force_pending = 0.0;
    pt->ops->landed(pt, point_displacement(m, pt->psi_k), point_velocity(m, pt->psi_k));
}
