/* plate_cascade.c -- the von Karman coefficients of a free-edge plate's modes and the
 * nonlinear potential (plate_cascade.h; docs/plates.md, "The cascade"). */
#include "plate_cascade.h"
#include "bessel_internal.h"
#include "ictus_simd.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Gauss-Legendre points on [0, 1] for the radial integrals (ictus_gauss_legendre). */
#define RADIAL_POINTS 96

static double bessel_j_any(int m, double x)
{
    return m < 0 ? ((-m) & 1 ? -ictus_bessel_j(-m, x) : ictus_bessel_j(-m, x))
                 : ictus_bessel_j(m, x);
}

static double bessel_i_any(int m, double x)
{
    return ictus_bessel_i_scaled(m < 0 ? -m : m, x);
}

/* The radial shape of p and its first two derivatives at r (analytic: the Bessel
 * functions' recurrences for J_m' and J_m'', and I_m' and I_m''). */
static void radial3(const plate_mode *p, double r, double out[3])
{
    const double l = p->lambda, x = l * r, e = p->c_scaled * exp(-l * (1.0 - r));
    double j[5], i[5];
    for (int k = 0; k < 5; k++) {
        j[k] = bessel_j_any(p->m - 2 + k, x);
        i[k] = bessel_i_any(p->m - 2 + k, x);
    }
    out[0] = p->norm * (j[2] + e * i[2]);
    out[1] = p->norm * l * (0.5 * (j[1] - j[3]) + e * 0.5 * (i[1] + i[3]));
    out[2] = p->norm * l * l *
             (0.25 * (j[0] - 2.0 * j[2] + j[4]) + e * 0.25 * (i[0] + 2.0 * i[2] + i[4]));
}

/* The clamped-disc frequency equation, scaled: J_m I_m+1 + J_m+1 I_m (e^-x I). */
static double clamped_det(int m, double x)
{
    return ictus_bessel_j(m, x) * ictus_bessel_i_scaled(m + 1, x) +
           ictus_bessel_j(m + 1, x) * ictus_bessel_i_scaled(m, x);
}

int plate_inplane_mode(int m, int s, plate_mode *out)
{
    if (m < 0 || s < 0)
        return -1;
    int seen = 0;
    double x0 = 0.5, f0 = clamped_det(m, x0);
    for (double x1 = x0 + 0.05; x1 < m + (s + 3) * M_PI + 10.0; x1 += 0.05) {
        double f1 = clamped_det(m, x1);
        if ((f0 < 0.0) != (f1 < 0.0)) {
            if (seen++ == s) {
                double lo = x0, hi = x1, flo = f0;
                for (int it = 0; it < 200 && hi - lo > 1e-14 * hi; it++) {
                    double mid = 0.5 * (lo + hi), fm = clamped_det(m, mid);
                    if ((fm < 0.0) == (flo < 0.0))
                        lo = mid, flo = fm;
                    else
                        hi = mid;
                }
                out->lambda = 0.5 * (lo + hi);
                out->m = m, out->s = s;
                out->c_scaled =
                    -ictus_bessel_j(m, out->lambda) / ictus_bessel_i_scaled(m, out->lambda);
                out->norm = 1.0;
                double x[RADIAL_POINTS], w[RADIAL_POINTS], sum = 0.0;
                ictus_gauss_legendre(RADIAL_POINTS, x, w);
                for (int k = 0; k < RADIAL_POINTS; k++) {
                    double v = plate_mode_radial(out, x[k]);
                    sum += w[k] * x[k] * v * v;
                }
                out->norm = 1.0 / sqrt((m ? M_PI : 2.0 * M_PI) * sum);
                return 0;
            }
        }
        x0 = x1, f0 = f1;
    }
    return -1;
}

/* The angular integrals int T_a T_i T_j and int T_a T_i' T_j' over [0, 2 pi), T = cos or
 * sin of m theta: the trapezoid rule, exact for these trigonometric polynomials. */
static void angular(int ma, int sa, int mi, int si, int mj, int sj, double *c1, double *c2)
{
    const int n = 2 * (ma + mi + mj) + 8;
    double s1 = 0.0, s2 = 0.0;
    for (int k = 0; k < n; k++) {
        const double t = 2.0 * M_PI * k / n;
        const double ta = sa ? sin(ma * t) : cos(ma * t);
        const double ti = si ? sin(mi * t) : cos(mi * t), tj = sj ? sin(mj * t) : cos(mj * t);
        const double di = si ? mi * cos(mi * t) : -mi * sin(mi * t);
        const double dj = sj ? mj * cos(mj * t) : -mj * sin(mj * t);
        s1 += ta * ti * tj;
        s2 += ta * di * dj;
    }
    *c1 = fabs(s1) > 1e-9 * n ? s1 * 2.0 * M_PI / n : 0.0;
    *c2 = fabs(s2) > 1e-9 * n ? s2 * 2.0 * M_PI / n : 0.0;
}

/* H from radial tables at the Gauss points (value, first, second derivative). With
 * w = W T: L(w_i, w_j) = A T_i T_j + B T_i' T_j',
 *   A = W_i'' (W_j' / r - m_j^2 W_j / r^2) + W_j'' (W_i' / r - m_i^2 W_i / r^2),
 *   B = -2 (W_i' / r - W_i / r^2) (W_j' / r - W_j / r^2). */
static double h_from_tables(const double *x, const double *w, const double *ra,
                            const double (*ri)[3], int mi, const double (*rj)[3], int mj, double c1,
                            double c2)
{
    double sum = 0.0;
    for (int k = 0; k < RADIAL_POINTS; k++) {
        const double r = x[k], ir = 1.0 / r, ir2 = ir * ir;
        const double *a = ri[k], *b = rj[k];
        const double A =
            a[2] * (b[1] * ir - mj * mj * b[0] * ir2) + b[2] * (a[1] * ir - mi * mi * a[0] * ir2);
        const double B = -2.0 * (a[1] * ir - a[0] * ir2) * (b[1] * ir - b[0] * ir2);
        sum += w[k] * r * ra[k] * (A * c1 + B * c2);
    }
    return sum;
}

double plate_cascade_h(const plate_mode *a, int a_sin, const plate_mode *i, int i_sin,
                       const plate_mode *j, int j_sin)
{
    double x[RADIAL_POINTS], w[RADIAL_POINTS], ra[RADIAL_POINTS];
    double ri[RADIAL_POINTS][3], rj[RADIAL_POINTS][3], c1, c2;
    ictus_gauss_legendre(RADIAL_POINTS, x, w);
    for (int k = 0; k < RADIAL_POINTS; k++) {
        ra[k] = plate_mode_radial(a, x[k]);
        radial3(i, x[k], ri[k]);
        radial3(j, x[k], rj[k]);
    }
    angular(a->m, a_sin, i->m, i_sin, j->m, j_sin, &c1, &c2);
    if (c1 == 0.0 && c2 == 0.0)
        return 0.0;
    return h_from_tables(x, w, ra, (const double(*)[3])ri, i->m, (const double(*)[3])rj, j->m, c1,
                         c2);
}

void plate_cascade_free(plate_cascade *c)
{
    free(c->ip), free(c->ip_sin), free(c->zeta4), free(c->row), free(c->col), free(c->val);
    free(c->kappa), free(c->y), free(c->g), free(c->dy), free(c->t);
    memset(c, 0, sizeof(*c));
}

/* p resized to cap elements of size bytes, or p itself with *ok cleared when out of memory. */
static void *grow(void *p, size_t size, int cap, int *ok)
{
    void *q = realloc(p, size * (size_t)cap);
    if (!q)
        *ok = 0;
    return q ? q : p;
}

/* The in-plane modes with zeta < zeta_max (cos and sin partners), into c. */
static int build_inplane(plate_cascade *c, double zeta_max)
{
    int cap = 16, n = 0;
    c->ip = malloc(sizeof(plate_mode) * (size_t)cap);
    c->ip_sin = malloc(sizeof(int) * (size_t)cap);
    for (int m = 0; c->ip && c->ip_sin; m++) {
        plate_mode p;
        if (plate_inplane_mode(m, 0, &p) != 0 || p.lambda >= zeta_max)
            break;
        for (int s = 0; plate_inplane_mode(m, s, &p) == 0 && p.lambda < zeta_max; s++) {
            for (int part = 0; part <= (m > 0); part++) {
                if (n == cap) {
                    cap *= 2;
                    int ok = 1;
                    c->ip = grow(c->ip, sizeof(plate_mode), cap, &ok);
                    c->ip_sin = grow(c->ip_sin, sizeof(int), cap, &ok);
                    if (!ok)
                        return -1;
                }
                c->ip[n] = p, c->ip_sin[n] = part, n++;
            }
        }
    }
    if (!c->ip || !c->ip_sin)
        return -1;
    c->inplane = n;
    return 0;
}

typedef struct entry_list {
    int *a, *i, *j;
    double *h;
    int n, cap;
} entry_list;

static int push_entry(entry_list *l, int a, int i, int j, double h)
{
    if (l->n == l->cap) {
        int cap = l->cap ? 2 * l->cap : 256;
        int ok = 1;
        l->a = grow(l->a, sizeof(int), cap, &ok);
        l->i = grow(l->i, sizeof(int), cap, &ok);
        l->j = grow(l->j, sizeof(int), cap, &ok);
        l->h = grow(l->h, sizeof(double), cap, &ok);
        if (!ok)
            return -1;
        l->cap = cap;
    }
    l->a[l->n] = a, l->i[l->n] = i, l->j[l->n] = j, l->h[l->n] = h, l->n++;
    return 0;
}

/* Every H^a_ij (i <= j) the angular selection rule allows, into l; its largest |H|. */
static double all_entries(const plate_cascade *c, const mode_table *t, int modes, entry_list *l)
{
    double x[RADIAL_POINTS], w[RADIAL_POINTS], big = 0.0;
    ictus_gauss_legendre(RADIAL_POINTS, x, w);
    double(*rt)[RADIAL_POINTS][3] = malloc(sizeof(*rt) * (size_t)modes);
    double(*ra)[RADIAL_POINTS] = malloc(sizeof(*ra) * (size_t)c->inplane);
    if (!rt || !ra) {
        free(rt), free(ra);
        return -1.0;
    }
    for (int k = 0; k < modes; k++)
        for (int r = 0; r < RADIAL_POINTS; r++)
            radial3(&t->plate[k], x[r], rt[k][r]);
    for (int a = 0; a < c->inplane; a++)
        for (int r = 0; r < RADIAL_POINTS; r++)
            ra[a][r] = plate_mode_radial(&c->ip[a], x[r]);
    for (int a = 0; a < c->inplane && big >= 0.0; a++) {
        const int ma = c->ip[a].m;
        for (int i = 0; i < modes && big >= 0.0; i++) {
            for (int j = i; j < modes; j++) {
                const int mi = t->m[i], mj = t->m[j];
                if (ma != mi + mj && ma != abs(mi - mj))
                    continue;
                double c1, c2;
                angular(ma, c->ip_sin[a], mi, t->sin[i], mj, t->sin[j], &c1, &c2);
                if (c1 == 0.0 && c2 == 0.0)
                    continue;
                double h = h_from_tables(x, w, ra[a], (const double(*)[3])rt[i], mi,
                                         (const double(*)[3])rt[j], mj, c1, c2);
                if (push_entry(l, a, i, j, h) != 0) {
                    big = -1.0;
                    break;
                }
                big = fmax(big, fabs(h));
            }
        }
    }
    free(rt), free(ra);
    return big;
}

ictus_status plate_cascade_build(plate_cascade *c, const mode_table *t, int modes, double zeta_max,
                                 double rel_tol)
{
    memset(c, 0, sizeof(*c));
    if (!t->plate || modes < 32 || modes % 32 || modes > PLATE_CASCADE_MAX_MODES || modes > t->size)
        return ICTUS_CLAMPED;
    entry_list l = {0};
    double big = -1.0;
    if (build_inplane(c, zeta_max) == 0)
        big = all_entries(c, t, modes, &l);
    const int na = c->inplane;
    int kept = 0;
    for (int e = 0; e < l.n; e++)
        kept += (fabs(l.h[e]) >= rel_tol * big) * (l.i[e] == l.j[e] ? 1 : 2);
    c->zeta4 = malloc(sizeof(double) * (size_t)(na + 1));
    c->kappa = calloc((size_t)(na + 1), sizeof(float));
    /* per in-plane mode, the columns j of H^a with an entry, each stored whole (modes
     * floats): t_a = sum over them of Y_j H^a(:, j), a vector loop */
    unsigned char *has = calloc((size_t)(na * modes + 1), 1);
    int columns = 0;
    for (int e = 0; has && e < l.n; e++) {
        if (fabs(l.h[e]) < rel_tol * big)
            continue;
        for (int side = 0; side < 2; side++) {
            const int r = l.a[e] * modes + (side ? l.i[e] : l.j[e]);
            columns += !has[r];
            has[r] = 1;
        }
    }
    c->row = calloc((size_t)(na + 1), sizeof(int));
    c->col = malloc(sizeof(int) * (size_t)(columns + 1));
    c->val = calloc((size_t)columns * modes + 1, sizeof(float));
    c->t = calloc((size_t)(na * modes + 1), sizeof(float));
    c->y = calloc((size_t)modes, sizeof(float));
    c->g = calloc((size_t)modes, sizeof(float));
    c->dy = calloc((size_t)modes, sizeof(float));
    if (big < 0.0 || !has || !c->zeta4 || !c->kappa || !c->row || !c->col || !c->val || !c->t ||
        !c->y || !c->g || !c->dy) {
        free(l.a), free(l.i), free(l.j), free(l.h), free(has);
        plate_cascade_free(c);
        return ICTUS_ENOMEM;
    }
    c->modes = modes;
    /* AVX2 where the CPU runs it (ictus_simd_level(), which AVX-512 includes). */
    c->potential = ictus_simd_level() >= ICTUS_SIMD_AVX2 ? plate_cascade_potential_avx2
                                                         : plate_cascade_potential_generic;
    int at = 0;
    for (int a = 0; a < na; a++) {
        c->row[a] = at;
        for (int j = 0; j < modes; j++)
            if (has[a * modes + j])
                c->col[at++] = j;
    }
    c->row[na] = at;
    free(has);
    for (int e = 0; e < l.n; e++) {
        if (fabs(l.h[e]) < rel_tol * big)
            continue;
        for (int side = 0; side < 1 + (l.i[e] != l.j[e]); side++) {
            const int j = side ? l.i[e] : l.j[e], i = side ? l.j[e] : l.i[e];
            int k = c->row[l.a[e]];
            while (c->col[k] != j)
                k++;
            c->val[(size_t)k * modes + i] = (float)l.h[e];
        }
    }
    for (int a = 0; a < na; a++) {
        const double z2 = c->ip[a].lambda * c->ip[a].lambda;
        c->zeta4[a] = z2 * z2;
    }
    c->entries = kept;
    free(l.a), free(l.i), free(l.j), free(l.h);
    return ICTUS_OK;
}

void plate_cascade_set_scale(plate_cascade *c, double eh, double radius, double density)
{
    const double a2 = radius * radius, a6 = a2 * a2 * a2;
    for (int a = 0; a < c->inplane; a++)
        c->kappa[a] = (float)(eh / (8.0 * a6 * density * density * c->zeta4[a]));
    /* psi's floor: far below any audible energy, far above float's smallest */
    c->floor = 1e-12;
}

double plate_cascade_potential(const plate_cascade *c, const float *y, float *grad)
{
    return c->potential(c, y, grad);
}

void plate_cascade_anchor(plate_cascade *c, const float *y)
{
    c->psi = sqrt(2.0 * (plate_cascade_potential(c, y, NULL) + c->floor));
}
