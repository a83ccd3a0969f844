/* snare_wires.c -- the snare side of a snare drum under a batter membrane
 * (snare_wires.h). Values and sources: docs/sound.md, "The snare".
 *
 * Signs: every displacement grows along the force a stick pushes the batter with (into
 * the drum, down); the snare head lies below the batter and the wires below the snare
 * head, at y >= w while apart.
 *
 * The snare head's modes (mass-normalised shapes psi_k, physical units), each a
 * damped oscillator x'' + 2 s x' + W^2 x = f, advance by the trapezoidal rule (W
 * prewarped so that it rings at its frequency; passive: the energy
 * (v^2 + W^2 x^2) / 2 changes by the forces' work and the damping only). Over one
 * sample x1 = xf + g f, xf = A x0 + B v0, g = T / D, D = 2/T + T W^2 / 2 + 2 s. The
 * modes' loops are snare_kernel.inc (float SIMD, the modes grouped by parity).
 *
 * The forces of one sample, solved together (Newton on the joint system, the air
 * eliminated; Gauss-Seidel sweeps as the fallback, to convergence):
 * - the air, F_a = k_air (D0 + D1) / 2 on the snare head's mean displacement and -F_a
 *   on the batter's, D = u_batter - u_snare (the midpoint of a linear spring: exact
 *   energy);
 * - wire i, F_i >= 0 on the wire and -F_i on the head, the discrete gradient of the
 *   collision potential V(d) = k / (alpha + 1) d+^(alpha + 1), d = w_head - y_wire.
 * The wire, mass M on a spring k_s with damping c, by the midpoint rule:
 * y1 = y_free + G F, G = 1 / (2M/T^2 + k_s/2 + c/T). */
#include "snare_wires.h"
#include "bessel_internal.h"
#include "ictus_simd.h"
#include "membrane_internal.h"
#include "snare_internal.h"

#include <stdlib.h>
#include <string.h>

#define HEAD_DENSITY   0.105  /* kg/m^2: 0.076 mm (3 mil) Mylar, 1380 kg/m^3 */
#define HEAD_F01       330.0  /* Hz: the snare head's (0, 1) alone (a tuning choice) */
#define HEAD_T60       0.5    /* s, the t60 part of the decay (as the batter's) */
#define HEAD_ETA       0.002  /* the film's internal loss factor (as the batter's) */
#define SHELL_DEPTH    0.1397 /* m: a 14 x 5.5 inch snare drum */
#define WIRE_MASS_KG   2.0e-4 /* per segment: the part of the strands that moves alone */
#define WIRE_SPRING_HZ 150.0  /* a segment on the strands' tension */
#define WIRE_T60_S     0.1    /* of that motion, away from the head */
#define WIRE_STIFFNESS 1.0e9  /* N / m^alpha: steel wire on Mylar (a choice) */
#define WIRE_ALPHA     1.5    /* the law's exponent (potential(), grad_force()) */
#define WIRE_LENGTH    0.2    /* of the radius: a segment's length, lying along the head */
#define PICK_R         0.5    /* the snare head's pickups: r/a, and degrees off the wires */
#define MAX_SWEEPS     50

/* Along the diameter the wires lie on (theta 0 and 180 degrees), x / a: segment i lies
 * at -radius[3 - i] (i < 4) or +radius[i - 4]. */
static const double wire_r[SNARE_RADII] = {0.1, 0.3, 0.5, 0.7};
#define WIRE_RADIUS(i) ((i) < SNARE_RADII ? SNARE_RADII - 1 - (i) : (i)-SNARE_RADII)
#define WIRE_MINUS(i)  ((i) < SNARE_RADII)
/* The pickups: 45 degrees off the wires, and 135 (the same shape times (-1)^m). */
#define PICK_DEG 45.0

typedef struct air_point {
    membrane_point point; /* first member: the membrane sees only this */
    struct snare_wires *set;
} air_point;

struct snare_wires {
    air_point air;
    /* The snare head: live modes in n slots, float, in the kernel's three groups
     * (snare_internal.h: (0, n), other even m, odd m; padding all zero). */
    int n, live;
    double sr, radius, tension, k_air;
    float *x, *v, *xf, *ca, *cb, *g; /* state, free move, coefficients */
    float *mean;                     /* mean of each shape over the head */
    float *psi[SNARE_RADII];         /* shapes at the wire radii, theta 0 */
    float *pick;                     /* shape at the pickup (PICK_R, PICK_DEG) */
    double *w2, *om;                 /* W^2 (prewarped), w; 0 in the padding */
    snare_kernel_args ka;
    snare_kernel_free_fn kfree;
    snare_kernel_force_fn kforce;
    double Kww[SNARE_WIRE_SEGMENTS][SNARE_WIRE_SEGMENTS], Kmw[SNARE_WIRE_SEGMENTS], Kmm;
    /* Newton's compliance C (newton_forces), kept while its beta and G hold; c_beta NaN
     * when the couplings changed. */
    double C[SNARE_WIRE_SEGMENTS][SNARE_WIRE_SEGMENTS], c_beta, c_G;
    /* Wires. */
    int engaged;
    double y[SNARE_WIRE_SEGMENTS], yv[SNARE_WIRE_SEGMENTS], d[SNARE_WIRE_SEGMENTS];
    double mass_kg, spring, damping, k;
    double gap0; /* D at the end of the last sample */
    long contact_samples;
};

static const membrane_point_ops air_ops;
static void head_coefficients(snare_wires *w, double sr);

/* n elements of size `size`, zeroed, 64-byte aligned (NULL when memory cannot be had).
 * Allocates. */
static void *alloc_aligned(int n, size_t size)
{
    void *p = NULL;
    size_t bytes = size * (size_t)(n > 0 ? n : 1);
    bytes = (bytes + 63) / 64 * 64;
    if (posix_memalign(&p, 64, bytes) != 0)
        return NULL;
    memset(p, 0, bytes);
    return p;
}

/* The snare head's displacement at wire segment i (state x, or the free move). */
static double wire_displacement(const snare_wires *w, const float *x, int i)
{
    const int j = WIRE_RADIUS(i);
    double e = 0.0, o = 0.0;
    for (int k = 0; k < w->ka.ne; k++)
        e += (double)w->psi[j][k] * x[k];
    for (int k = w->ka.ne; k < w->n; k++)
        o += (double)w->psi[j][k] * x[k];
    return WIRE_MINUS(i) ? e - o : e + o;
}

/* ---------------------------------------------------------------- collisions */

/* The collision law with alpha = 1.5 (WIRE_ALPHA), by square roots: pow() took a third
 * of the snare's time. V(d) = k / 2.5 d^2.5, V' = k d^1.5, V'' = 1.5 k d^0.5. */
static double potential(const snare_wires *w, double d)
{
    return d > 0.0 ? w->k / 2.5 * d * d * sqrt(d) : 0.0;
}

/* The discrete-gradient force between d0 and d1, and dF/dd1. */
static double grad_force(const snare_wires *w, double d0, double v0, double d1, double *df)
{
    double dx = d1 - d0, scale = fabs(d0) > fabs(d1) ? fabs(d0) : fabs(d1);
    if (d0 <= 0.0 && d1 <= 0.0) {
        *df = 0.0;
        return 0.0;
    }
    if (fabs(dx) > 1.0e-6 * scale) { /* one square root, one division */
        const double r1 = d1 > 0.0 ? sqrt(d1) : 0.0, f1 = w->k * d1 * r1, inv = 1.0 / dx;
        const double f = (f1 * d1 / 2.5 - v0) * inv; /* V(d1) = d1 V'(d1) / 2.5 */
        *df = (f1 - f) * inv;
        return f > 0.0 ? f : 0.0;
    }
    double mid = 0.5 * (d0 + d1);
    *df = mid > 0.0 ? 0.75 * w->k * sqrt(mid) : 0.0;
    return mid > 0.0 ? w->k * mid * sqrt(mid) : 0.0;
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
        double gd = d - d_free + C * f;
        if (gd > 0.0)
            hi = d;
        else
            lo = d;
        double next = d - gd / (1.0 + C * df);
        if (!(next > lo && next < hi))
            next = 0.5 * (lo + hi);
        if (fabs(next - d) <= 1.0e-13 * (fabs(d) + 1.0e-9) || hi - lo <= 1.0e-15)
            return grad_force(w, d0, v0, next, &df);
        d = next;
    }
    return grad_force(w, d0, v0, d, &df);
}

/* ---------------------------------------------------------------- one sample */

/* Solves the n x n system A x = b in place (partial pivoting); 0 when singular. */
static int solve_linear(double A[SNARE_WIRE_SEGMENTS][SNARE_WIRE_SEGMENTS], double *b, int n)
{
    for (int c = 0; c < n; c++) {
        int piv = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(A[r][c]) > fabs(A[piv][c]))
                piv = r;
        if (!(fabs(A[piv][c]) > 0.0))
            return 0;
        if (piv != c) {
            for (int k = c; k < n; k++) {
                double t = A[c][k];
                A[c][k] = A[piv][k], A[piv][k] = t;
            }
            double t = b[c];
            b[c] = b[piv], b[piv] = t;
        }
        for (int r = c + 1; r < n; r++) {
            const double f = A[r][c] / A[c][c];
            for (int k = c; k < n; k++)
                A[r][k] -= f * A[c][k];
            b[r] -= f * b[c];
        }
    }
    for (int r = n - 1; r >= 0; r--) {
        double s = b[r];
        for (int k = r + 1; k < n; k++)
            s -= A[r][k] * b[k];
        b[r] = s / A[r][r];
    }
    return 1;
}

/* The wires' forces by Newton's method on the joint system, the air eliminated (it is
 * linear): fa = alpha + beta sum_j Kmw_j F_j, and the gaps after the sample
 *     d = a - C F(d),   a_i = wf_i - yfree_i + Kmw_i alpha,
 *     C_ij = Kww_ij + G delta_ij - beta Kmw_i Kmw_j
 * (the head's, the wire's and the air's compliances), F_i(d_i) the discrete gradient
 * (grad_force), increasing and C^1 in d_i. Newton on R(d) = d - a + C F(d), J = I + C
 * diag(F'), from d = a, to |R| <= 1e-15 m. The same solution as the Gauss-Seidel sweeps
 * (solve_forces), in a few 8 x 8 solves instead of many scalar ones. 1 when converged
 * (F set), 0 to fall back to the sweeps. */
static int newton_forces(snare_wires *w, double alpha, double beta, const double *wf,
                         const double *yfree, double G, double *F)
{
    enum { N = SNARE_WIRE_SEGMENTS };
    double a[N], d[N], v0[N], df[N];
    int any = 0;
    for (int i = 0; i < N; i++) {
        a[i] = wf[i] - yfree[i] + w->Kmw[i] * alpha;
        any |= a[i] > 0.0 || w->d[i] > 0.0;
    }
    if (!any) { /* every gap stays open: no force */
        for (int i = 0; i < N; i++)
            F[i] = 0.0;
        return 1;
    }
    if (!(beta == w->c_beta && G == w->c_G)) { /* beta follows the batter's tension */
        for (int i = 0; i < N; i++)
            for (int j = 0; j < N; j++)
                w->C[i][j] = w->Kww[i][j] + (i == j ? G : 0.0) - beta * w->Kmw[i] * w->Kmw[j];
        w->c_beta = beta, w->c_G = G;
    }
    const double(*C)[N] = (const double(*)[N])w->C;
    for (int i = 0; i < N; i++)
        v0[i] = potential(w, w->d[i]);
    for (int i = 0; i < N; i++)
        d[i] = a[i];
    for (int it = 0; it < 40; it++) {
        /* J's column j is the unit vector where F_j' = 0 (the gap open at both ends of
         * the sample): the step solves on the other, active, gaps alone. */
        double R[N], J[N][N], worst = 0.0, Ra[N];
        int act[N], na = 0, push[N], np = 0;
        for (int i = 0; i < N; i++) {
            if (w->d[i] <= 0.0 && d[i] <= 0.0) { /* open at both ends of the sample */
                F[i] = df[i] = 0.0;
                continue;
            }
            F[i] = grad_force(w, w->d[i], v0[i], d[i], &df[i]);
            if (df[i] != 0.0)
                act[na++] = i;
            if (F[i] != 0.0)
                push[np++] = i;
        }
        for (int i = 0; i < N; i++) { /* C F over the forces that are not zero */
            double cf = 0.0;
            for (int q = 0; q < np; q++)
                cf += C[i][push[q]] * F[push[q]];
            R[i] = d[i] - a[i] + cf;
            worst = fabs(R[i]) > worst ? fabs(R[i]) : worst;
        }
        if (worst <= 1.0e-15)
            return 1;
        for (int r = 0; r < na; r++) {
            for (int c = 0; c < na; c++)
                J[r][c] = C[act[r]][act[c]] * df[act[c]] + (r == c ? 1.0 : 0.0);
            Ra[r] = R[act[r]];
        }
        if (!solve_linear(J, Ra, na))
            return 0;
        for (int i = 0; i < N; i++) { /* the open gaps: R_i less the active steps' share */
            if (df[i] != 0.0)
                continue;
            double s = R[i];
            for (int r = 0; r < na; r++)
                s -= C[i][act[r]] * df[act[r]] * Ra[r];
            d[i] -= s;
        }
        for (int r = 0; r < na; r++)
            d[act[r]] -= Ra[r];
    }
    return 0;
}

/* The forces of this sample: F[0 .. SEGMENTS) on the wires, *fa the air's. uf, wf: the
 * free mean displacement and the free displacements at the wires; ub, kb: the
 * batter's free mean displacement and its compliance. */
static void solve_forces(snare_wires *w, double ub, double kb, double uf, const double *wf,
                         const double *yfree, double G, double *F, double *fa)
{
    const double ka = w->k_air;
    /* The air alone is linear: fa = alpha + beta sum_i Kmw_i F_i. */
    const double beta = ka / (2.0 + ka * (kb + w->Kmm)), alpha = beta * (w->gap0 + ub - uf);
    if (!w->engaged || newton_forces(w, alpha, beta, wf, yfree, G, F)) {
        double air = alpha;
        for (int i = 0; w->engaged && i < SNARE_WIRE_SEGMENTS; i++)
            air += beta * w->Kmw[i] * F[i];
        *fa = air;
        return;
    }
    for (int i = 0; i < SNARE_WIRE_SEGMENTS; i++)
        F[i] = 0.0;
    double air = 0.0;
    for (int sweep = 0; sweep < MAX_SWEEPS; sweep++) {
        double e = ub - uf, change = 0.0, scale = 1e-30;
        for (int i = 0; i < SNARE_WIRE_SEGMENTS; i++)
            e += w->Kmw[i] * F[i];
        double a1 = ka * (w->gap0 + e) / (2.0 + ka * (kb + w->Kmm));
        change += fabs(a1 - air), scale += fabs(a1);
        air = a1;
        if (!w->engaged)
            break;
        for (int i = 0; i < SNARE_WIRE_SEGMENTS; i++) {
            double wi = wf[i] + w->Kmw[i] * air;
            for (int j = 0; j < SNARE_WIRE_SEGMENTS; j++)
                if (j != i)
                    wi -= w->Kww[i][j] * F[j];
            double f1 = solve_force(w, w->d[i], wi - yfree[i], w->Kww[i][i] + G);
            change += fabs(f1 - F[i]), scale += fabs(f1);
            F[i] = f1;
        }
        if (change <= 1e-12 * scale)
            break;
    }
    *fa = air;
}

/* Advances the snare side one sample against the batter's free mean displacement ub
 * (compliance kb): the air force on the batter goes to its point, both heads' sound
 * into extra. */
static void snare_step(snare_wires *w, double ub, double kb, double T,
                       double extra[MEMBRANE_PICKUPS])
{
    double uf, E[SNARE_RADII], O[SNARE_RADII], wf[SNARE_WIRE_SEGMENTS] = {0};
    double yfree[SNARE_WIRE_SEGMENTS], F[SNARE_WIRE_SEGMENTS] = {0}, fa;
    /* The free move, its mean and its displacements at the wires (snare_kernel.inc). */
    w->kfree(&w->ka, w->engaged, &uf, E, O);
    for (int i = 0; w->engaged && i < SNARE_WIRE_SEGMENTS; i++) {
        const int j = WIRE_RADIUS(i);
        wf[i] = WIRE_MINUS(i) ? E[j] - O[j] : E[j] + O[j];
    }
    const double A = 2.0 * w->mass_kg / (T * T) + 0.5 * w->spring + w->damping / T;
    const double B = 2.0 * w->mass_kg / (T * T) - 0.5 * w->spring + w->damping / T;
    const double G = 1.0 / A;
    for (int i = 0; i < SNARE_WIRE_SEGMENTS; i++)
        yfree[i] = G * (B * w->y[i] + 2.0 * w->mass_kg * w->yv[i] / T);
    solve_forces(w, ub, kb, uf, wf, yfree, G, F, &fa);
    /* The forces into the snare head's modes (the pair at +-r_j: their sum on the even
     * modes, their difference on the odd), and its velocity at the pickups. */
    double Fe[SNARE_RADII], Fo[SNARE_RADII], pe, po;
    for (int j = 0; j < SNARE_RADII; j++) {
        const double fp = F[SNARE_RADII + j], fm = F[SNARE_RADII - 1 - j];
        Fe[j] = fp + fm, Fo[j] = fp - fm;
    }
    w->kforce(&w->ka, fa, Fe, Fo, 2.0 / T, &pe, &po);
    const double pv[MEMBRANE_PICKUPS] = {pe + po, pe - po};
    /* The displacements after the forces, from the couplings (no more dot products). */
    double u1 = uf + w->Kmm * fa;
    for (int i = 0; w->engaged && i < SNARE_WIRE_SEGMENTS; i++)
        u1 -= w->Kmw[i] * F[i];
    w->gap0 = (ub - kb * fa) - u1;
    int touching = 0;
    for (int i = 0; w->engaged && i < SNARE_WIRE_SEGMENTS; i++) {
        double y1 = yfree[i] + G * F[i], wh = wf[i] + w->Kmw[i] * fa;
        for (int j = 0; j < SNARE_WIRE_SEGMENTS; j++)
            if (F[j] != 0.0)
                wh -= w->Kww[i][j] * F[j];
        w->yv[i] = 2.0 / T * (y1 - w->y[i]) - w->yv[i];
        w->y[i] = y1;
        w->d[i] = wh - y1;
        touching |= F[i] > 0.0;
    }
    w->contact_samples += touching;
    membrane_point *pt = &w->air.point;
    pt->force_pending = -fa;
    /* The batter's pickups are in units of 1 / mass_scale (membrane.c, emit_sample). */
    const double to_batter = 1.0 / pt->owner->mass_scale;
    for (int j = 0; j < MEMBRANE_PICKUPS; j++)
        extra[j] += -fa * pt->pick_coupling[j] + pv[j] * to_batter;
}

static void air_solve(membrane_point *const *pts, int count, const double *w_free,
                      const double (*K)[MEMBRANE_MAX_POINTS], double T, int sample,
                      double extra[MEMBRANE_PICKUPS])
{
    (void)sample;
    for (int i = 0; i < count; i++)
        snare_step(((air_point *)pts[i])->set, w_free[i], K[i][i], T, extra);
}

/* ---------------------------------------------------------------- the point's ops */

/* Each batter mode's mean over the head: for (0, n), norm 2 J1(j) / j; else 0. */
static void air_shapes(const membrane *m, const membrane_point *pt, int live, float *psi)
{
    (void)pt;
    for (int k = 0; k < m->capacity; k++) {
        psi[k] = 0.0f;
        if (k < live && m->table.m[k] == 0) {
            double j = m->table.j[k];
            psi[k] = (float)(m->table.norm[k] * m->table.scale[k] * 2.0 * ictus_bessel_j(1, j) / j);
        }
    }
}

static void air_landed(membrane_point *pt, double displacement_m, double velocity_mps)
{
    (void)pt, (void)displacement_m, (void)velocity_mps;
}

/* The batter's sample rate changed (DSP restarted at another rate): the snare head's
 * coefficients follow, its modes kept. */
static void air_block_begin(membrane_point *pt, int n)
{
    snare_wires *w = ((air_point *)pt)->set;
    (void)n;
    if (pt->owner && pt->owner->sample_rate != w->sr)
        head_coefficients(w, pt->owner->sample_rate);
}

static void snare_rest(snare_wires *w)
{
    if (w->x) {
        memset(w->x, 0, sizeof(float) * (size_t)w->n);
        memset(w->v, 0, sizeof(float) * (size_t)w->n);
    }
    memset(w->y, 0, sizeof(w->y));
    memset(w->yv, 0, sizeof(w->yv));
    memset(w->d, 0, sizeof(w->d));
    w->gap0 = 0.0;
}

/* membrane_clear(): the batter is still; so is the snare side (the air at rest with it). */
static void air_cleared(membrane_point *pt)
{
    snare_wires *w = ((air_point *)pt)->set;
    snare_rest(w);
    pt->active = 1;
}

static void air_detached(membrane_point *pt)
{
    (void)pt;
}

static const membrane_point_ops air_ops = {air_landed,  air_solve,    air_block_begin,
                                           air_cleared, air_detached, air_shapes};

/* ---------------------------------------------------------------- the snare head */

/* The float arrays of the head, for freeing and allocating together. */
#define HEAD_FLOATS (8 + SNARE_RADII)
static void head_floats(snare_wires *w, float **arrs[HEAD_FLOATS])
{
    float **f[8] = {&w->x, &w->v, &w->xf, &w->ca, &w->cb, &w->g, &w->mean, &w->pick};
    for (int i = 0; i < 8; i++)
        arrs[i] = f[i];
    for (int j = 0; j < SNARE_RADII; j++)
        arrs[8 + j] = &w->psi[j];
}

static void free_head(snare_wires *w)
{
    float **arrs[HEAD_FLOATS];
    head_floats(w, arrs);
    for (int i = 0; i < HEAD_FLOATS; i++)
        free(*arrs[i]), *arrs[i] = NULL;
    free(w->w2), free(w->om), w->w2 = w->om = NULL;
    w->n = w->live = 0;
}

/* The cos(m theta) modes of a head of this wave speed below f_max, into (m, j) (when
 * mm is not NULL); their count, -1 when memory cannot be had. Allocates. */
static int list_modes(double c, double a, double f_max, int *mm, double *jj, int cap)
{
    ictus_bessel_zero_entry *zeros = NULL;
    int count = ictus_bessel_zeros_below(2.0 * M_PI * a * f_max / c, &zeros);
    for (int i = 0; mm && i < count && i < cap; i++)
        mm[i] = zeros[i].m, jj[i] = zeros[i].j;
    free(zeros);
    return count;
}

static double shape(int m, double j, double norm, double r, double theta)
{
    return norm * ictus_bessel_j(m, j * r) * cos(m * theta);
}

/* The shape's mean along a segment centred at r / a on the wires' diameter (theta 0):
 * the segment lies on the head along its length, WIRE_LENGTH of the radius. The mean of
 * J_m(j s) over [r - l/2, r + l/2] is the difference of its integral from 0. */
static double line_shape(int m, double j, double norm, double r)
{
    const double lo = j * (r - 0.5 * WIRE_LENGTH), hi = j * (r + 0.5 * WIRE_LENGTH);
    return norm * (ictus_bessel_j_integral(m, hi) - ictus_bessel_j_integral(m, lo)) /
           (j * WIRE_LENGTH);
}

/* The shape of slot k at wire segment i ((-1)^m at the minus side: the odd group). */
static double wire_shape(const snare_wires *w, int i, int k)
{
    const double s = w->psi[WIRE_RADIUS(i)][k];
    return WIRE_MINUS(i) && k >= w->ka.ne ? -s : s;
}

static void head_couplings(snare_wires *w)
{
    w->c_beta = NAN; /* newton_forces builds C again */
    w->Kmm = 0.0;
    for (int i = 0; i < SNARE_WIRE_SEGMENTS; i++) {
        w->Kmw[i] = 0.0;
        for (int j = 0; j < SNARE_WIRE_SEGMENTS; j++)
            w->Kww[i][j] = 0.0;
    }
    for (int k = 0; k < w->n; k++) {
        const double g = w->g[k], mk = w->mean[k];
        w->Kmm += mk * mk * g;
        for (int i = 0; i < SNARE_WIRE_SEGMENTS; i++) {
            const double si = wire_shape(w, i, k);
            w->Kmw[i] += mk * si * g;
            for (int j = 0; j < SNARE_WIRE_SEGMENTS; j++)
                w->Kww[i][j] += si * wire_shape(w, j, k) * g;
        }
    }
}

/* The modes' coefficients at sample rate sr, and the couplings; modes above 0.45 sr
 * fall silent. No allocation (also from the audio thread, when the rate changed). */
static void head_coefficients(snare_wires *w, double sr)
{
    const double T = 1.0 / sr;
    for (int k = 0; k < w->n; k++) {
        const double om = w->om[k], s = log(1000.0) / HEAD_T60 + 0.5 * HEAD_ETA * om;
        if (!(om > 0.0) || om >= 0.9 * M_PI * sr) {
            w->ca[k] = w->cb[k] = w->g[k] = w->x[k] = w->v[k] = 0.0f;
            w->w2[k] = 0.0;
            continue;
        }
        const double wm = 2.0 / T * tan(0.5 * om * T); /* prewarped */
        const double D = 2.0 / T + 0.5 * T * wm * wm + 2.0 * s;
        w->w2[k] = wm * wm;
        w->ca[k] = (float)((2.0 / T - 0.5 * T * wm * wm + 2.0 * s) / D);
        w->cb[k] = (float)(2.0 / D);
        w->g[k] = (float)(T / D);
    }
    w->sr = sr;
    head_couplings(w);
}

static int pad(int n)
{
    return (n + SNARE_KERNEL_PAD - 1) / SNARE_KERNEL_PAD * SNARE_KERNEL_PAD;
}

/* Allocates the head's arrays for n slots; 0 when memory cannot be had. */
static int alloc_head(snare_wires *w, int n)
{
    float **arrs[HEAD_FLOATS];
    head_floats(w, arrs);
    int ok = 1;
    for (int i = 0; i < HEAD_FLOATS; i++)
        ok = ok && (*arrs[i] = alloc_aligned(n, sizeof(float)));
    ok = ok && (w->w2 = alloc_aligned(n, sizeof(double)));
    ok = ok && (w->om = alloc_aligned(n, sizeof(double)));
    w->n = n;
    return ok;
}

/* Mode (m, j) into slot k: its frequency and shapes (mass-normalised). */
static void lay_mode(snare_wires *w, int k, int m, double j, double c01, double a)
{
    const double mass_norm = 1.0 / sqrt(HEAD_DENSITY * a * a);
    const double norm = sqrt((m ? 2.0 : 1.0) / M_PI) / fabs(ictus_bessel_j(m + 1, j)) * mass_norm;
    w->om[k] = j * c01 / a;
    w->mean[k] = (float)(m == 0 ? norm * 2.0 * ictus_bessel_j(1, j) / j : 0.0);
    for (int r = 0; r < SNARE_RADII; r++)
        w->psi[r][k] = (float)line_shape(m, j, norm, wire_r[r]);
    w->pick[k] = (float)shape(m, j, norm, PICK_R, PICK_DEG * M_PI / 180.0);
}

/* Builds the snare head for a batter of radius a at sample rate sr: the modes sorted
 * into the kernel's groups. Allocates. */
static ictus_status build_head(snare_wires *w, double sr, double a)
{
    const double c01 = 2.0 * M_PI * a * HEAD_F01 / ictus_bessel_zero(0, 1);
    const double f_max = fmin(SNARE_HEAD_F_MAX, 0.4 * sr);
    free_head(w);
    int n = list_modes(c01, a, f_max, NULL, NULL, 0);
    if (n < 0)
        return ICTUS_ENOMEM;
    int *mm = malloc(sizeof(int) * (size_t)(n ? n : 1));
    double *jj = malloc(sizeof(double) * (size_t)(n ? n : 1));
    if (!mm || !jj) {
        free(mm), free(jj);
        return ICTUS_ENOMEM;
    }
    list_modes(c01, a, f_max, mm, jj, n);
    int count[3] = {0, 0, 0}; /* (0, n), other even m, odd m */
    for (int k = 0; k < n; k++)
        count[mm[k] == 0 ? 0 : (mm[k] % 2 == 0 ? 1 : 2)]++;
    const int n0 = pad(count[0]), ne = n0 + pad(count[1]), total = ne + pad(count[2]);
    if (!alloc_head(w, total)) {
        free(mm), free(jj), free_head(w);
        return ICTUS_ENOMEM;
    }
    int next[3] = {0, n0, ne};
    for (int k = 0; k < n; k++) {
        const int grp = mm[k] == 0 ? 0 : (mm[k] % 2 == 0 ? 1 : 2);
        lay_mode(w, next[grp]++, mm[k], jj[k], c01, a);
    }
    free(mm), free(jj);
    w->live = n;
    w->radius = a;
    w->tension = HEAD_DENSITY * c01 * c01;
    w->k_air = MEMBRANE_AIR_RHO * MEMBRANE_AIR_C * MEMBRANE_AIR_C * M_PI * a * a / SHELL_DEPTH;
    w->ka = (snare_kernel_args){
        n0,    ne,    total, w->x,    w->v,    w->xf,
        w->ca, w->cb, w->g,  w->mean, w->pick, {w->psi[0], w->psi[1], w->psi[2], w->psi[3]}};
    head_coefficients(w, sr);
    snare_rest(w);
    return ICTUS_OK;
}

/* ---------------------------------------------------------------- the API */

snare_wires *snare_wires_new(void)
{
    snare_wires *w = calloc(1, sizeof(*w));
    if (!w)
        return NULL;
    w->mass_kg = WIRE_MASS_KG;
    w->spring = w->mass_kg * pow(2.0 * M_PI * WIRE_SPRING_HZ, 2.0);
    /* c = 2 M sigma, sigma = ln(1000) / T60 */
    w->damping = 2.0 * w->mass_kg * log(1000.0) / WIRE_T60_S;
    w->k = WIRE_STIFFNESS;
    w->engaged = 1;
    /* As the batter's kernel (membrane.c): ictus_simd_level() picks the copy. */
    static const snare_kernel_free_fn frees[] = {snare_kernel_free_generic, snare_kernel_free_avx2,
                                                 snare_kernel_free_avx512};
    static const snare_kernel_force_fn forces[] = {
        snare_kernel_force_generic, snare_kernel_force_avx2, snare_kernel_force_avx512};
    const ictus_simd level = ictus_simd_level();
    w->kfree = frees[level];
    w->kforce = forces[level];
    w->air.point.ops = &air_ops;
    w->air.set = w;
    return w;
}

void snare_wires_detach(snare_wires *w)
{
    if (w && w->air.point.owner)
        membrane_point_detach_(w->air.point.owner, &w->air.point);
}

void snare_wires_free(snare_wires *w)
{
    if (!w)
        return;
    membrane_point_free_(&w->air.point);
    free_head(w);
    free(w);
}

ictus_status snare_wires_attach(snare_wires *w, membrane *m)
{
    if (!w || !m)
        return ICTUS_CLAMPED;
    if (w->air.point.owner == m)
        return ICTUS_OK;
    snare_wires_detach(w);
    if (m->point_count + SNARE_POINTS > MEMBRANE_MAX_POINTS)
        return ICTUS_ENOMEM;
    ictus_status s = build_head(w, m->sample_rate, m->radius);
    if (s != ICTUS_OK)
        return s;
    if ((s = membrane_point_attach_(m, &w->air.point)) != ICTUS_OK)
        return s;
    /* The air at rest with the batter (a preset is set on a still head). */
    snare_rest(w);
    w->air.point.active = 1;
    return ICTUS_OK;
}

membrane *snare_wires_membrane(const snare_wires *w)
{
    return w ? w->air.point.owner : NULL;
}

void snare_wires_engage(snare_wires *w, int on)
{
    if (!w || w->engaged == (on != 0))
        return;
    w->engaged = on != 0;
    for (int i = 0; i < SNARE_WIRE_SEGMENTS; i++) {
        w->y[i] = w->engaged && w->x ? wire_displacement(w, w->x, i) : 0.0;
        w->yv[i] = w->d[i] = 0.0;
    }
}

int snare_wires_engaged(const snare_wires *w)
{
    return w ? w->engaged : 0;
}

double snare_wires_energy(const snare_wires *w)
{
    double e = 0.5 * w->k_air * w->gap0 * w->gap0;
    for (int k = 0; k < w->n; k++)
        e += 0.5 * ((double)w->v[k] * w->v[k] + w->w2[k] * (double)w->x[k] * w->x[k]);
    for (int i = 0; w->engaged && i < SNARE_WIRE_SEGMENTS; i++)
        e += 0.5 * w->mass_kg * w->yv[i] * w->yv[i] + 0.5 * w->spring * w->y[i] * w->y[i] +
             potential(w, w->d[i]);
    return e;
}

long snare_wires_contact_samples(const snare_wires *w)
{
    return w->contact_samples;
}

int snare_wires_head_modes(const snare_wires *w)
{
    return w->live;
}

double snare_wires_head_f01(const snare_wires *w)
{
    (void)w;
    return HEAD_F01;
}

double snare_wires_air_stiffness(const snare_wires *w)
{
    return w->k_air;
}
