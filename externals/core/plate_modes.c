/* plate_modes.c -- the modes of a thin circular plate with a free edge (plate_modes.h).
 *
 * For W(r) = J_m(lambda r) + C I_m(lambda r) (r in units of the radius), the free
 * edge asks, at r = 1 (Leissa 1969, eqs. 2.2-2.4, Kirchhoff's effective shear):
 *     bending moment   W'' + nu (W' - m^2 W) = 0
 *     effective shear  (lap W)' - (1 - nu) m^2 (W' - W) = 0,
 * with lap J_m(lambda r) = -lambda^2 J_m and lap I_m(lambda r) = +lambda^2 I_m. The
 * two conditions are linear in (1, C); lambda is a root of their determinant, found
 * by scanning it in lambda and bisecting each change of sign. I_m is carried scaled
 * by e^-lambda (it grows like e^lambda), which scales the determinant and leaves its
 * roots alone.
 */
#include "plate_modes.h"

#include "bessel_internal.h"
#include "membrane.h"

#include <math.h>
#include <stdlib.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* {e^-x I_{m-1}(x), e^-x I_m(x), e^-x I_{m+1}(x)} (I_{-1} = I_1) by Miller's backward
 * recurrence I_{k-1} = (2k / x) I_k + I_{k+1}, normalised with
 * e^x = I_0 + 2 (I_1 + I_2 + ...) (the generating function at theta = 0): every
 * term positive, so the sum loses nothing to cancellation. */
static void bessel_i3_scaled(int m, double x, double out[3])
{
    if (m < 0)
        m = 0;
    if (!(x > 1.0e-12)) {
        out[0] = (m == 1) ? 1.0 : 0.0; /* I_0(0) = 1 is I_{m-1} only for m = 1 */
        out[1] = (m == 0) ? 1.0 : 0.0;
        out[2] = 0.0;
        return;
    }
    const int top = 2 * (m + (int)x) + 60;
    double next = 0.0, cur = 1.0e-280, sum = 0.0, im_1 = 0.0, im = 0.0, ip = 0.0;
    for (int k = top; k >= 1; k--) {
        /* cur = I_k, next = I_{k+1} (up to a common factor) */
        if (k == m + 1)
            ip = cur;
        if (k == m)
            im = cur;
        if (k == m - 1)
            im_1 = cur;
        sum += 2.0 * cur;
        const double prev = (2.0 * k / x) * cur + next; /* I_{k-1} */
        next = cur;
        cur = prev;
        if (cur > 1.0e250) { /* rescale everything kept so far */
            const double f = 1.0e-250;
            cur *= f, next *= f, sum *= f, im_1 *= f, im *= f, ip *= f;
        }
    }
    /* cur = I_0 */
    sum += cur;
    if (m == 0) {
        im = cur;
        im_1 = ip; /* I_{-1} = I_1 */
    } else if (m == 1) {
        im_1 = cur;
    }
    out[0] = im_1 / sum;
    out[1] = im / sum;
    out[2] = ip / sum;
}

double ictus_bessel_i_scaled(int m, double x)
{
    double v[3];
    bessel_i3_scaled(m, x, v);
    return v[1];
}

/* The free-edge conditions' matrix at lambda: rows (moment, shear), columns
 * (J part, e^-lambda I part). */
static void edge_matrix(int m, double lam, double nu, double a[2][2])
{
    double j[3], i[3];
    ictus_bessel_j3(m, lam, j);
    bessel_i3_scaled(m, lam, i);
    const double m2 = (double)m * m, l2 = lam * lam, l3 = l2 * lam;
    const double J = j[1], Jp = 0.5 * (j[0] - j[2]);
    const double I = i[1], Ip = 0.5 * (i[0] + i[2]);
    /* W'' from Bessel's equations: J'' = -J'/x - (1 - m^2/x^2) J, I'' = -I'/x + (1 + m^2/x^2) I */
    const double Jpp = -Jp / lam - (1.0 - m2 / l2) * J;
    const double Ipp = -Ip / lam + (1.0 + m2 / l2) * I;
    a[0][0] = l2 * Jpp + nu * (lam * Jp - m2 * J);
    a[0][1] = l2 * Ipp + nu * (lam * Ip - m2 * I);
    a[1][0] = -l3 * Jp - (1.0 - nu) * m2 * (lam * Jp - J);
    a[1][1] = l3 * Ip - (1.0 - nu) * m2 * (lam * Ip - I);
}

static double edge_det(int m, double lam, double nu)
{
    double a[2][2];
    edge_matrix(m, lam, nu, a);
    return a[0][0] * a[1][1] - a[0][1] * a[1][0];
}

/* The roots of order m in (lo, hi) by a scan in steps of 0.05 (roots of one order lie
 * about pi apart) and bisection; calls found(root) for each, in order, until it
 * returns 0. Returns the number found. */
static int roots_between(int m, double nu, double lo, double hi, int (*found)(double, void *),
                         void *ctx)
{
    const double step = 0.05;
    int count = 0;
    double x0 = lo, f0 = edge_det(m, x0, nu);
    while (x0 < hi) {
        const double x1 = x0 + step, f1 = edge_det(m, x1, nu);
        if ((f0 < 0.0) != (f1 < 0.0)) {
            double a = x0, b = x1, fa = f0;
            for (int it = 0; it < 200 && b - a > 1e-14 * b; it++) {
                const double c = 0.5 * (a + b), fc = edge_det(m, c, nu);
                if ((fc < 0.0) == (fa < 0.0))
                    a = c, fa = fc;
                else
                    b = c;
            }
            const double root = 0.5 * (a + b);
            if (root >= hi)
                break;
            count++;
            if (!found(root, ctx))
                break;
        }
        x0 = x1, f0 = f1;
    }
    return count;
}

/* The scan starts above the rigid-body root at 0 and below every mode: the lowest,
 * (2, 0), has lambda = 2.29 (nu = 0.33). */
#define LAMBDA_SCAN_START 0.5

typedef struct nth_ctx {
    int want, seen;
    double root;
} nth_ctx;

static int take_nth(double root, void *p)
{
    nth_ctx *c = p;
    c->root = root;
    return ++c->seen < c->want;
}

double plate_free_lambda(int m, int s, double nu)
{
    if (m < 0 || s < 0 || !(nu >= 0.0 && nu < 0.5) || (m <= 1 && s == 0))
        return 0.0;
    nth_ctx c = {m <= 1 ? s : s + 1, 0, 0.0};
    /* the k-th root of order m lies below m + (k + 1) pi + a margin */
    roots_between(m, nu, LAMBDA_SCAN_START, m + (c.want + 2) * M_PI + 10.0, take_nth, &c);
    return c.seen == c.want ? c.root : 0.0;
}

typedef struct list_ctx {
    plate_mode *modes;
    int count, cap, m, first;
    double nu;
} list_ctx;

static int take_all(double root, void *p)
{
    list_ctx *c = p;
    if (c->count == c->cap) {
        int cap = c->cap ? 2 * c->cap : 64;
        plate_mode *grown = realloc(c->modes, sizeof(plate_mode) * (size_t)cap);
        if (!grown) {
            c->cap = -1;
            return 0;
        }
        c->modes = grown, c->cap = cap;
    }
    plate_mode *q = &c->modes[c->count++];
    q->lambda = root, q->m = c->m, q->s = c->first++;
    return 1;
}

/* C (against the scaled I_m) from the moment condition, and the norm by Simpson's
 * rule over r in [0, 1] (about 25 points per radial wavelength). */
static void complete_mode(plate_mode *p, double nu)
{
    double a[2][2];
    edge_matrix(p->m, p->lambda, nu, a);
    p->c_scaled = fabs(a[0][1]) > 0.0 ? -a[0][0] / a[0][1] : 0.0;
    p->norm = 1.0;
    int n = 200 + 4 * (int)(p->lambda * 2.0);
    n += n % 2;
    double sum = 0.0;
    for (int k = 0; k <= n; k++) {
        const double r = (double)k / n, w = plate_mode_radial(p, r);
        const double weight = (k == 0 || k == n) ? 1.0 : (k % 2 ? 4.0 : 2.0);
        sum += weight * w * w * r;
    }
    const double radial = sum / (3.0 * n);
    p->norm = 1.0 / sqrt((p->m ? M_PI : 2.0 * M_PI) * radial);
}

static int by_lambda(const void *x, const void *y)
{
    const plate_mode *a = x, *b = y;
    if (a->lambda != b->lambda)
        return a->lambda < b->lambda ? -1 : 1;
    return a->m - b->m;
}

int plate_free_modes_below(double lambda_max, double nu, plate_mode **out)
{
    *out = NULL;
    if (!(nu >= 0.0 && nu < 0.5) || !(lambda_max > 0.0))
        return 0;
    list_ctx c = {NULL, 0, 0, 0, 0, nu};
    for (int m = 0;; m++) {
        c.m = m, c.first = (m <= 1) ? 1 : 0;
        const int before = c.count;
        roots_between(m, nu, LAMBDA_SCAN_START, lambda_max, take_all, &c);
        if (c.cap < 0) {
            free(c.modes);
            return -1;
        }
        /* The first root of order m is above m: once an order has none, none above has. */
        if (c.count == before && m >= 2)
            break;
    }
    for (int k = 0; k < c.count; k++)
        complete_mode(&c.modes[k], nu);
    if (c.count > 1)
        qsort(c.modes, (size_t)c.count, sizeof(plate_mode), by_lambda);
    *out = c.modes;
    return c.count;
}

double plate_mode_radial(const plate_mode *p, double r_over_a)
{
    const double r = fmin(fmax(r_over_a, 0.0), 1.0), x = p->lambda * r;
    /* e^-lambda I_m(lambda r) = e^-lambda(1 - r) (e^-x I_m(x)) */
    const double i = ictus_bessel_i_scaled(p->m, x) * exp(-p->lambda * (1.0 - r));
    return p->norm * (ictus_bessel_j(p->m, x) + p->c_scaled * i);
}
