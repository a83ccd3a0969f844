/* snare_wires.c -- lumped snare wires colliding with a membrane (snare_wires.h).
 *
 * Sign: the membrane's displacement w grows along the force a stick pushes it with;
 * the wires lie on the far side, at y >= w while apart. Compression d = w - y; when
 * d > 0 the head pushes the wire with F = V'(d), V(d) = k/(alpha+1) d+^(alpha+1), and
 * the wire pushes the head back with -F.
 *
 * One sample (T): the head's displacement at the mass is w1 = w_free - K F (K: the
 * membrane's compliance there over the sample); the wire, mass M on a spring k_s with
 * damping c, by the midpoint rule:
 *     M (v1 - v0) / T = F - k_s (y0 + y1) / 2 - c (v0 + v1) / 2,  y1 = y0 + T (v0 + v1) / 2
 * so y1 = y_free + G F, G = 1 / (2M/T^2 + k_s/2 + c/T). The collision force is the
 * discrete gradient F = (V(d1) - V(d0)) / (d1 - d0), which makes the scheme pass the
 * energy exactly (losses: c only), and d1 = (w_free - y_free) - (K + G) F: one scalar
 * equation, increasing in d1, solved by Newton inside a bracket. */
#include "snare_wires.h"
#include "membrane_internal.h"

#include <stdlib.h>

/* Values: docs/sound.md, "Snare wires". */
#define WIRE_MASS_KG   0.001 /* per lumped mass: the moving part of a few strands */
#define WIRE_SPRING_HZ 150.0 /* the mass on the strainer's pull */
#define WIRE_T60_S     0.1   /* of that motion, away from the head */
#define WIRE_STIFFNESS 1.0e9 /* N / m^alpha: steel wire on Mylar (a choice) */
#define WIRE_ALPHA     1.5
#define WIRE_THETA_DEG 90.0 /* the wires lie along this diameter */

static const double wire_r_over_a[SNARE_WIRES_MASSES] = {0.25, 0.6};

typedef struct wire_mass {
    membrane_point point; /* first member: the membrane sees only this */
    double y, v;          /* m, m/s */
    double d;             /* compression at the end of the last sample, m */
    struct snare_wires *set;
} wire_mass;

struct snare_wires {
    wire_mass mass[SNARE_WIRES_MASSES];
    double mass_kg, spring, damping, k, alpha;
    long contact_samples;
};

static const membrane_point_ops wire_ops;

static double potential(const snare_wires *w, double d)
{
    return d > 0.0 ? w->k / (w->alpha + 1.0) * pow(d, w->alpha + 1.0) : 0.0;
}

/* The discrete-gradient force between d0 and d1, and dF/dd1. */
static double grad_force(const snare_wires *w, double d0, double v0, double d1, double *df)
{
    double dx = d1 - d0, scale = fabs(d0) > fabs(d1) ? fabs(d0) : fabs(d1);
    if (d0 <= 0.0 && d1 <= 0.0) {
        *df = 0.0;
        return 0.0;
    }
    if (fabs(dx) > 1.0e-6 * scale) {
        double f = (potential(w, d1) - v0) / dx;
        double f1 = d1 > 0.0 ? w->k * pow(d1, w->alpha) : 0.0;
        *df = (f1 - f) / dx;
        return f > 0.0 ? f : 0.0;
    }
    double mid = 0.5 * (d0 + d1);
    *df = mid > 0.0 ? 0.5 * w->k * w->alpha * pow(mid, w->alpha - 1.0) : 0.0;
    return mid > 0.0 ? w->k * pow(mid, w->alpha) : 0.0;
}

/* Solves d1 = d_free - C F(d0, d1) for F >= 0. */
static double solve_force(const snare_wires *w, double d0, double d_free, double C)
{
    double df, v0 = potential(w, d0);
    double f_hi = grad_force(w, d0, v0, d_free, &df);
    if (f_hi <= 0.0)
        return 0.0;
    /* g(d) = d - d_free + C F(d) is increasing; g(d_free) >= 0, g(d_free - C F(d_free)) <= 0. */
    double hi = d_free, lo = d_free - C * f_hi, d = 0.5 * (lo + hi);
    for (int it = 0; it < 60; it++) {
        double f = grad_force(w, d0, v0, d, &df);
        double g = d - d_free + C * f;
        if (g > 0.0)
            hi = d;
        else
            lo = d;
        double next = d - g / (1.0 + C * df);
        if (!(next > lo && next < hi))
            next = 0.5 * (lo + hi);
        if (fabs(next - d) <= 1.0e-13 * (fabs(d) + 1.0e-9) || hi - lo <= 1.0e-15)
            return grad_force(w, d0, v0, next, &df);
        d = next;
    }
    return grad_force(w, d0, v0, d, &df);
}

/* The masses' forces for this sample (Gauss-Seidel over the masses, which couple
 * through the head), then their motion. */
static void wires_solve(membrane_point *const *pts, int count, const double *w_free,
                        const double (*K)[MEMBRANE_MAX_POINTS], double T, int sample,
                        double extra[MEMBRANE_PICKUPS])
{
    (void)sample;
    double F[MEMBRANE_MAX_POINTS] = {0}, yfree[MEMBRANE_MAX_POINTS];
    snare_wires *w = ((wire_mass *)pts[0])->set;
    const double A = 2.0 * w->mass_kg / (T * T) + 0.5 * w->spring + w->damping / T;
    const double B = 2.0 * w->mass_kg / (T * T) - 0.5 * w->spring + w->damping / T;
    const double G = 1.0 / A;
    for (int i = 0; i < count; i++) {
        wire_mass *m = (wire_mass *)pts[i];
        yfree[i] = G * (B * m->y + 2.0 * w->mass_kg * m->v / T);
    }
    for (int sweep = 0; sweep < (count > 1 ? 4 : 1); sweep++) {
        for (int i = 0; i < count; i++) {
            wire_mass *m = (wire_mass *)pts[i];
            double wf = w_free[i];
            for (int j = 0; j < count; j++)
                if (j != i)
                    wf -= K[i][j] * F[j];
            F[i] = solve_force(w, m->d, wf - yfree[i], K[i][i] + G);
        }
    }
    for (int i = 0; i < count; i++) {
        wire_mass *m = (wire_mass *)pts[i];
        double wf = w_free[i];
        for (int j = 0; j < count; j++)
            wf -= K[i][j] * F[j];
        double y1 = yfree[i] + G * F[i];
        m->v = 2.0 * (y1 - m->y) / T - m->v;
        m->y = y1;
        m->d = wf - y1;
        m->point.force_pending = -F[i];
        if (F[i] > 0.0)
            w->contact_samples++;
        for (int j = 0; j < MEMBRANE_PICKUPS; j++)
            extra[j] += -F[i] * m->point.pick_coupling[j];
    }
}

static void wires_landed(membrane_point *pt, double displacement_m)
{
    (void)pt, (void)displacement_m;
}

static void wires_block_begin(membrane_point *pt, int n)
{
    (void)pt, (void)n;
}

/* membrane_clear(): the head is still; so are the wires, touching it. */
static void wires_cleared(membrane_point *pt)
{
    wire_mass *m = (wire_mass *)pt;
    m->y = m->v = m->d = 0.0;
    m->point.active = 1;
}

static void wires_detached(membrane_point *pt)
{
    (void)pt;
}

static const membrane_point_ops wire_ops = {wires_landed, wires_solve, wires_block_begin,
                                            wires_cleared, wires_detached};

snare_wires *snare_wires_new(void)
{
    snare_wires *w = calloc(1, sizeof(*w));
    if (!w)
        return NULL;
    w->mass_kg = WIRE_MASS_KG;
    w->spring = WIRE_MASS_KG * pow(2.0 * M_PI * WIRE_SPRING_HZ, 2.0);
    /* c = 2 M sigma, sigma = ln(1000) / T60 */
    w->damping = 2.0 * WIRE_MASS_KG * log(1000.0) / WIRE_T60_S;
    w->k = WIRE_STIFFNESS;
    w->alpha = WIRE_ALPHA;
    for (int i = 0; i < SNARE_WIRES_MASSES; i++) {
        w->mass[i].point.ops = &wire_ops;
        w->mass[i].point.r_over_a = wire_r_over_a[i];
        w->mass[i].point.theta_deg = WIRE_THETA_DEG;
        w->mass[i].set = w;
    }
    return w;
}

void snare_wires_detach(snare_wires *w)
{
    if (!w)
        return;
    for (int i = 0; i < SNARE_WIRES_MASSES; i++)
        if (w->mass[i].point.owner)
            membrane_point_detach_(w->mass[i].point.owner, &w->mass[i].point);
}

void snare_wires_free(snare_wires *w)
{
    if (!w)
        return;
    for (int i = 0; i < SNARE_WIRES_MASSES; i++)
        membrane_point_free_(&w->mass[i].point);
    free(w);
}

ictus_status snare_wires_attach(snare_wires *w, membrane *m)
{
    if (!w || !m)
        return ICTUS_CLAMPED;
    if (w->mass[0].point.owner == m)
        return ICTUS_OK;
    snare_wires_detach(w);
    if (m->point_count + SNARE_WIRES_MASSES > MEMBRANE_MAX_POINTS)
        return ICTUS_ENOMEM;
    for (int i = 0; i < SNARE_WIRES_MASSES; i++) {
        ictus_status s = membrane_point_attach_(m, &w->mass[i].point);
        if (s != ICTUS_OK) {
            snare_wires_detach(w);
            return s;
        }
        wire_mass *wm = &w->mass[i];
        wm->y = membrane_displacement_at(m, wm->point.r_over_a, wm->point.theta_deg);
        wm->v = 0.0;
        wm->d = 0.0;
        wm->point.active = 1;
    }
    return ICTUS_OK;
}

membrane *snare_wires_membrane(const snare_wires *w)
{
    return w ? w->mass[0].point.owner : NULL;
}

double snare_wires_energy(const snare_wires *w)
{
    double e = 0.0;
    for (int i = 0; i < SNARE_WIRES_MASSES; i++) {
        const wire_mass *m = &w->mass[i];
        e += 0.5 * w->mass_kg * m->v * m->v + 0.5 * w->spring * m->y * m->y + potential(w, m->d);
    }
    return e;
}

long snare_wires_contact_samples(const snare_wires *w)
{
    return w->contact_samples;
}
