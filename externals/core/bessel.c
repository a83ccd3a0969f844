/* bessel.c -- Bessel functions of the first kind and their zeros (plain C99).
 *
 * J_m(x) by Miller's backward recurrence normalised with
 * J_0 + 2 (J_2 + J_4 + ...) = 1 (Abramowitz & Stegun 9.1.46), which is stable for
 * every order and argument we need (m up to a few hundred, x up to ~1000): the
 * recurrence runs downwards from well above max(m, x), where J is the minimal
 * solution, so rounding errors die out instead of growing.
 *
 * Zeros by interlacing (A&S 9.5.2: j_{m-1,n} < j_{m,n} < j_{m-1,n+1}): the zeros of
 * J_0 are bracketed next to McMahon's asymptotic value, and every zero of J_m
 * lies alone between two consecutive zeros of J_{m-1}. A safeguarded Newton
 * iteration inside each bracket then converges to ~1 ulp without any risk of
 * jumping to a neighbouring zero, for any (m, n).
 */
#include "bessel_internal.h"
#include "membrane.h"

#include <math.h>
#include <stdlib.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

void ictus_gauss_legendre(int n, double *x, double *w)
{
    for (int i = 0; i < n; i++) {
        double z = cos(M_PI * (i + 0.75) / (n + 0.5)), dp = 1.0;
        for (int it = 0; it < 100; it++) {
            double p0 = 1.0, p1 = z;
            for (int k = 2; k <= n; k++) {
                double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
                p0 = p1, p1 = p2;
            }
            dp = n * (z * p1 - p0) / (z * z - 1.0);
            double dz = p1 / dp;
            z -= dz;
            if (fabs(dz) < 1e-15)
                break;
        }
        x[i] = 0.5 * (1.0 - z);
        w[i] = 1.0 / ((1.0 - z * z) * dp * dp); /* 2 / (...) on [-1, 1], halved */
    }
}

/* out = {J_{m-1}(x), J_m(x), J_{m+1}(x)}; J_{-1} = -J_1. x >= 0. With integral, also
 * *integral = int_0^x J_m(t) dt = 2 sum_{k >= 0} J_{m+2k+1}(x) (Abramowitz & Stegun
 * 11.1.2; its derivative telescopes to J_m), summed in the same recurrence. */
static void bessel_j3_int(int m, double x, double out[3], double *integral)
{
    if (m < 0)
        m = 0;
    if (integral)
        *integral = 0.0;
    if (!(x > 0.0)) {
        out[0] = (m == 1) ? 1.0 : 0.0;
        out[1] = (m == 0) ? 1.0 : 0.0;
        out[2] = 0.0;
        return;
    }
    if (x < 1.0e-6) {
        /* Series: J_k(x) = (x/2)^k / k! (1 - (x/2)^2 / (k+1) + ...), relative error
         * < 1e-13 here; the recurrence below would divide by a vanishing x. */
        double t = 1.0, half = 0.5 * x;
        for (int k = 0; k <= m + 1; k++) {
            double jk = t * (1.0 - half * half / (k + 1.0));
            if (k == m - 1)
                out[0] = jk;
            else if (k == m)
                out[1] = jk;
            else if (k == m + 1)
                out[2] = jk;
            t *= half / (k + 1.0);
        }
        if (m == 0)
            out[0] = -0.5 * x; /* J_{-1} = -J_1 */
        if (integral)          /* x J_m(x) / (m + 1), to the same order */
            *integral = x * out[1] / (m + 1.0);
        return;
    }
    double top = (double)(m + 1) > x ? (double)(m + 1) : x;
    /* Start far enough above the turning point that J_start/J_top is below 1e-17. */
    int start = (int)(top + 30.0 + sqrt(160.0 * top));
    start += start & 1;
    double bjp = 0.0, bj = 1.0e-30, sum = 0.0, tail = 0.0;
    double jm_m1 = 0.0, jm_0 = 0.0, jm_p1 = 0.0;
    for (int k = start; k > 0; k--) {
        double bjm = (2.0 * k / x) * bj - bjp; /* J_{k-1} */
        bjp = bj;
        bj = bjm;
        int order = k - 1;
        if (fabs(bj) > 1.0e250) { /* rescale everything kept so far */
            bj *= 1.0e-250;
            bjp *= 1.0e-250;
            sum *= 1.0e-250;
            tail *= 1.0e-250;
            jm_m1 *= 1.0e-250;
            jm_0 *= 1.0e-250;
            jm_p1 *= 1.0e-250;
        }
        if (order == m + 1)
            jm_p1 = bj;
        else if (order == m)
            jm_0 = bj;
        else if (order == m - 1)
            jm_m1 = bj;
        if (order > 0 && (order & 1) == 0)
            sum += 2.0 * bj;
        if (order > m && ((order - m) & 1))
            tail += 2.0 * bj;
    }
    sum += bj; /* J_0 */
    if (m == 0)
        jm_m1 = -bjp; /* J_{-1} = -J_1 */
    out[0] = jm_m1 / sum;
    out[1] = jm_0 / sum;
    out[2] = jm_p1 / sum;
    if (integral)
        *integral = tail / sum;
}

void ictus_bessel_j3(int m, double x, double out[3])
{
    bessel_j3_int(m, x, out, NULL);
}

double ictus_bessel_j_integral(int m, double x)
{
    double v[3], integral;
    if (m < 0 || !isfinite(x))
        return 0.0;
    if (x < 0.0) { /* J_m is (-1)^m symmetric, so its integral from 0 is (-1)^(m+1) */
        bessel_j3_int(m, -x, v, &integral);
        return (m & 1) ? integral : -integral;
    }
    bessel_j3_int(m, x, v, &integral);
    return integral;
}

double ictus_bessel_j(int m, double x)
{
    double v[3];
    if (m < 0 || !isfinite(x))
        return 0.0;
    if (x < 0.0) { /* J_m(-x) = (-1)^m J_m(x) */
        ictus_bessel_j3(m, -x, v);
        return (m & 1) ? -v[1] : v[1];
    }
    ictus_bessel_j3(m, x, v);
    return v[1];
}

/* The single zero of J_m in the open interval (lo, hi), where J_m changes sign. */
static double bessel_zero_in(int m, double lo, double hi, double guess)
{
    double v[3];
    ictus_bessel_j3(m, lo, v);
    double flo = v[1];
    double x = (guess > lo && guess < hi) ? guess : 0.5 * (lo + hi);
    for (int it = 0; it < 200; it++) {
        ictus_bessel_j3(m, x, v);
        double f = v[1];
        if (f == 0.0)
            return x;
        if ((f > 0.0) == (flo > 0.0)) {
            lo = x;
            flo = f;
        } else {
            hi = x;
        }
        /* J_m' = J_{m-1} - (m/x) J_m (A&S 9.1.27). */
        double d = v[0] - (m / x) * f;
        double xn = (d != 0.0) ? x - f / d : 0.5 * (lo + hi);
        if (!(xn > lo && xn < hi))
            xn = 0.5 * (lo + hi); /* Newton left the bracket: bisect */
        double step = fabs(xn - x);
        x = xn;
        if (step <= 4.0e-16 * x || hi - lo <= 4.0e-16 * x)
            break;
    }
    /* One last Newton step from the converged point polishes the last ulp. */
    ictus_bessel_j3(m, x, v);
    double d = v[0] - (m / x) * v[1];
    if (d != 0.0) {
        double xn = x - v[1] / d;
        if (fabs(xn - x) < 1.0e-12 * x)
            x = xn;
    }
    return x;
}

/* n-th zero of J_0, bracketed beside McMahon's beta = (n - 1/4) pi: j_{0,n} lies in
 * (beta, beta + 1/(8 beta) + ...) and 1/(8 beta) < 0.06. */
static double bessel_zero0(int n)
{
    double beta = (n - 0.25) * M_PI;
    double mcmahon = beta + 1.0 / (8.0 * beta) - 124.0 / (3.0 * pow(8.0 * beta, 3.0));
    return bessel_zero_in(0, beta, beta + 0.125 * M_PI, mcmahon);
}

double ictus_bessel_zero(int m, int n)
{
    if (m < 0 || n < 1)
        return 0.0;
    /* Zeros j_{l, n .. n+m-l} for l = 0 .. m, each level bracketed by the last. */
    double *z = malloc(sizeof(double) * (size_t)(m + 1));
    if (!z)
        return 0.0;
    for (int i = 0; i <= m; i++)
        z[i] = bessel_zero0(n + i);
    for (int l = 1; l <= m; l++)
        for (int i = 0; i <= m - l; i++)
            z[i] = bessel_zero_in(l, z[i], z[i + 1], 0.5 * (z[i] + z[i + 1]));
    double r = z[0];
    free(z);
    return r;
}

static int zero_cmp(const void *pa, const void *pb)
{
    const ictus_bessel_zero_entry *a = pa, *b = pb;
    if (a->j != b->j)
        return a->j < b->j ? -1 : 1;
    if (a->m != b->m)
        return a->m < b->m ? -1 : 1;
    return a->n < b->n ? -1 : (a->n > b->n);
}

/* The first zero of J_m above `after` (itself a zero of J_m or a point below
 * the first one, where J_m has no zero in between). Zeros of J_m, m >= 1, are
 * more than pi apart (A&S 9.5.2 ff.), so stepping by 3 < pi brackets the next
 * one alone. */
static double bessel_next_zero(int m, double after)
{
    const double h = 3.0;
    double lo = after + 1.0e-9 * (after > 1.0 ? after : 1.0);
    double flo = ictus_bessel_j(m, lo);
    for (int i = 0; i < 10000; i++) {
        double hi = lo + h, fhi = ictus_bessel_j(m, hi);
        if ((flo > 0.0) != (fhi > 0.0) || fhi == 0.0)
            return bessel_zero_in(m, lo, hi, 0.5 * (lo + hi));
        lo = hi;
        flo = fhi;
    }
    return after; /* unreachable for legal m, after */
}

static int push_zero(ictus_bessel_zero_entry **list, int *len, int *cap, double j, int m, int n)
{
    if (*len == *cap) {
        int grown_cap = *cap * 2;
        ictus_bessel_zero_entry *grown = realloc(*list, sizeof(**list) * (size_t)grown_cap);
        if (!grown)
            return 0;
        *list = grown;
        *cap = grown_cap;
    }
    (*list)[*len].j = j;
    (*list)[*len].m = m;
    (*list)[*len].n = n;
    (*len)++;
    return 1;
}

int ictus_bessel_zeros_below(double x_max, ictus_bessel_zero_entry **out)
{
    /* Level m holds the zeros of J_m below x_max plus the first one above: the
     * zeros of J_{m+1} below x_max are then bracketed by consecutive entries, and
     * its first zero above x_max is the next one after its last bracketed zero. */
    int count0 = (int)(x_max / M_PI) + 3;
    double *prev = malloc(sizeof(double) * (size_t)count0);
    double *cur = malloc(sizeof(double) * (size_t)count0);
    int cap = 64, len = 0;
    ictus_bessel_zero_entry *list = malloc(sizeof(*list) * (size_t)cap);
    if (!prev || !cur || !list) {
        free(prev);
        free(cur);
        free(list);
        return -1;
    }
    int kprev = 0;
    for (int n = 1; n <= count0; n++) {
        prev[kprev++] = bessel_zero0(n);
        if (prev[kprev - 1] >= x_max)
            break;
    }
    for (int i = 0; i < kprev && prev[i] < x_max; i++)
        if (!push_zero(&list, &len, &cap, prev[i], 0, i + 1))
            goto fail;
    for (int m = 1;; m++) {
        int k = 0;
        for (int i = 0; i + 1 < kprev && prev[i] < x_max; i++)
            cur[k++] = bessel_zero_in(m, prev[i], prev[i + 1], 0.5 * (prev[i] + prev[i + 1]));
        if (k == 0 || cur[k - 1] < x_max) {
            /* No zero above x_max yet: find the next one (there is room: a level
             * never holds more zeros than the one below it). */
            cur[k] = bessel_next_zero(m, k ? cur[k - 1] : (double)m);
            k++;
        }
        if (cur[0] >= x_max)
            break; /* j_{m,1} increases with m: no higher order has a zero below */
        for (int i = 0; i < k && cur[i] < x_max; i++)
            if (!push_zero(&list, &len, &cap, cur[i], m, i + 1))
                goto fail;
        double *t = prev;
        prev = cur;
        cur = t;
        kprev = k;
    }
    free(prev);
    free(cur);
    qsort(list, (size_t)len, sizeof(*list), zero_cmp);
    *out = list;
    return len;
fail:
    free(prev);
    free(cur);
    free(list);
    return -1;
}
