/* mode_table.c -- the membrane's modes in order of frequency (see mode_table.h). */
#include "mode_table.h"
#include "bessel_internal.h"

#include <math.h>
#include <stdlib.h>

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

void mode_table_free(mode_table *t)
{
    free(t->j), free(t->norm), free(t->m), free(t->n), free(t->sin), free(t->plate);
    free(t->edge), free(t->air), free(t->scale);
    t->j = t->norm = t->edge = t->air = t->scale = NULL;
    t->m = t->n = t->sin = NULL;
    t->plate = NULL;
    t->size = t->air_valid = 0;
}

static int alloc_entries(mode_table *t, int size)
{
    t->j = malloc(sizeof(double) * (size_t)size);
    t->norm = malloc(sizeof(double) * (size_t)size);
    t->m = malloc(sizeof(int) * (size_t)size);
    t->n = malloc(sizeof(int) * (size_t)size);
    t->sin = malloc(sizeof(int) * (size_t)size);
    t->edge = calloc((size_t)size, sizeof(double));
    t->air = calloc((size_t)size, sizeof(double));
    t->scale = malloc(sizeof(double) * (size_t)size);
    if (t->scale)
        for (int k = 0; k < size; k++)
            t->scale[k] = 1.0;
    return t->j && t->norm && t->m && t->n && t->sin && t->edge && t->air && t->scale;
}

/* A plate's table: the free-edge modes below a lambda that Weyl's law for the plate
 * (about lambda^2 / 4 modes, cos and sin counted, below lambda) says holds `size`,
 * grown until it does. Entry k keeps its plate_mode (the radial shape); norm is 1,
 * the radial shape carries the normalisation. */
static ictus_status build_plate(mode_table *t, int size)
{
    double lambda_max = 2.0 * sqrt((double)size) + 4.0;
    plate_mode *pm = NULL;
    int count;
    for (;;) {
        count = plate_free_modes_below(lambda_max, MODE_TABLE_PLATE_NU, &pm);
        if (count < 0)
            return ICTUS_ENOMEM;
        int modes = 0;
        for (int i = 0; i < count; i++)
            modes += pm[i].m ? 2 : 1;
        if (modes >= size)
            break;
        free(pm);
        lambda_max *= 1.15;
    }
    t->plate = malloc(sizeof(plate_mode) * (size_t)size);
    if (!t->plate || !alloc_entries(t, size)) {
        free(pm);
        mode_table_free(t);
        return ICTUS_ENOMEM;
    }
    int k = 0;
    for (int i = 0; i < count && k < size; i++)
        for (int s = 0; s < (pm[i].m ? 2 : 1) && k < size; s++, k++) {
            t->plate[k] = pm[i];
            t->j[k] = pm[i].lambda * pm[i].lambda;
            t->m[k] = pm[i].m;
            t->n[k] = pm[i].s;
            t->sin[k] = s;
            t->norm[k] = 1.0;
            /* cos^2 or sin^2 (m theta) averages 1/2 around the edge, 1 for m = 0 */
            const double w = plate_mode_radial(&pm[i], 1.0);
            t->edge[k] = w * w * (pm[i].m ? M_PI : 2.0 * M_PI);
        }
    free(pm);
    t->size = size;
    return ICTUS_OK;
}

ictus_status mode_table_build(mode_table *t, int size, int plate)
{
    /* Enough Bessel zeros: Weyl's law gives about x^2/4 modes below j = x. */
    double x_max = 2.0 * sqrt((double)size) + 4.0;
    ictus_bessel_zero_entry *zeros = NULL;
    int count = 0, modes = 0;
    t->j = t->norm = t->edge = t->air = t->scale = NULL;
    t->m = t->n = t->sin = NULL;
    t->plate = NULL;
    t->size = t->air_valid = 0;
    if (plate)
        return build_plate(t, size);
    for (;;) {
        free(zeros);
        count = ictus_bessel_zeros_below(x_max, &zeros);
        if (count < 0)
            return ICTUS_ENOMEM;
        modes = 0;
        for (int i = 0; i < count; i++)
            modes += zeros[i].m ? 2 : 1;
        if (modes >= size)
            break;
        x_max *= 1.15;
    }
    if (!alloc_entries(t, size)) {
        free(zeros);
        mode_table_free(t);
        return ICTUS_ENOMEM;
    }
    /* Zeros come sorted by (j, m, n); an m >= 1 zero gives a cos and a sin mode. */
    int k = 0;
    for (int i = 0; i < count && k < size; i++) {
        double v[3];
        ictus_bessel_j3(zeros[i].m, zeros[i].j, v);
        double eps = zeros[i].m ? 2.0 : 1.0;
        for (int s = 0; s < (zeros[i].m ? 2 : 1) && k < size; s++, k++) {
            t->j[k] = zeros[i].j;
            t->m[k] = zeros[i].m;
            t->n[k] = zeros[i].n;
            t->sin[k] = s;
            t->norm[k] = sqrt(eps / M_PI) / fabs(v[2]);
        }
    }
    free(zeros);
    t->size = size;
    return ICTUS_OK;
}

/* Gauss-Legendre nodes on [0, 1], for the panels of mode_table_air_g. */
#define AIR_NODES 8
static double air_x[AIR_NODES], air_w[AIR_NODES];
static int air_ready;

/* Panels of pi/2 (J_m^2 oscillates with period pi) to U = 2 j + 20; past U, J_m(u)^2
 * averages 1 / (pi u) and (j^2 - u^2)^2 >= (3/4)^2 u^4: the tail, 1 / (4 pi U^4) over
 * (3/4)^2 at most, is below 1e-4 of the whole. */
static int air_panels(double j)
{
    return (int)ceil((2.0 * j + 20.0) / (0.5 * M_PI));
}

/* g from J_m at the panels' nodes (jm[p * AIR_NODES + i]: node i of panel p), as many
 * panels as air_panels(j). */
static double air_g_from(const double *jm, int m, double j)
{
    const double dj = ictus_bessel_j(m + 1, j); /* |J_m'(j)| at a zero of J_m */
    const double panel = 0.5 * M_PI;
    const int panels = air_panels(j);
    double sum = 0.0;
    for (int p = 0; p < panels; p++)
        for (int i = 0; i < AIR_NODES; i++) {
            const double u = p * panel + panel * air_x[i], den = j * j - u * u;
            double v;
            if (fabs(den) < 1e-6 * j * j) {
                v = dj * dj / (4.0 * j * j); /* the limit at u = j */
            } else {
                const double r = jm[p * AIR_NODES + i] / den;
                v = r * r;
            }
            sum += panel * air_w[i] * v;
        }
    const double end = panels * panel, u4 = end * end * end * end;
    sum += 1.0 / (4.0 * M_PI * u4); /* the tail as if (j^2 - u^2)^2 were u^4: within 1e-4 */
    return 2.0 * j * j * sum;
}

/* J_m at the nodes of the first `panels` panels. */
static void air_nodes(int m, int panels, double *jm)
{
    if (!air_ready) {
        ictus_gauss_legendre(AIR_NODES, air_x, air_w);
        air_ready = 1;
    }
    const double panel = 0.5 * M_PI;
    for (int p = 0; p < panels; p++)
        for (int i = 0; i < AIR_NODES; i++)
            jm[p * AIR_NODES + i] = ictus_bessel_j(m, p * panel + panel * air_x[i]);
}

double mode_table_air_g(int m, double j)
{
    const int panels = air_panels(j);
    double *jm = malloc(sizeof(double) * (size_t)panels * AIR_NODES);
    if (!jm)
        return 0.0;
    air_nodes(m, panels, jm);
    double g = air_g_from(jm, m, j);
    free(jm);
    return g;
}

/* The modes of one m share the nodes (the panels start at 0), so J_m is evaluated once
 * per m, to the largest j of that m among the modes to compute, not once per mode. */
void mode_table_prepare_air(mode_table *t)
{
    if (t->plate || t->air_valid >= t->size)
        return;
    int top_m = 0;
    double top_j = 0.0;
    for (int k = t->air_valid; k < t->size; k++) {
        top_m = t->m[k] > top_m ? t->m[k] : top_m;
        top_j = t->j[k] > top_j ? t->j[k] : top_j;
    }
    double *jm = malloc(sizeof(double) * (size_t)air_panels(top_j) * AIR_NODES);
    for (int m = 0; m <= top_m; m++) {
        double jmax = 0.0;
        for (int k = t->air_valid; k < t->size; k++)
            if (t->m[k] == m && t->j[k] > jmax)
                jmax = t->j[k];
        if (!(jmax > 0.0))
            continue;
        if (jm)
            air_nodes(m, air_panels(jmax), jm);
        for (int k = t->air_valid; k < t->size; k++) {
            if (t->m[k] != m)
                continue;
            if (k > t->air_valid && t->j[k] == t->j[k - 1] && t->m[k] == t->m[k - 1])
                t->air[k] = t->air[k - 1]; /* the sin partner */
            else
                t->air[k] = jm ? air_g_from(jm, m, t->j[k]) : mode_table_air_g(m, t->j[k]);
        }
    }
    free(jm);
    t->air_valid = t->size;
}

/* Mass-normalised shape of every mode at a point:
 *     psi_k = J_m(j r/a) {cos, sin}(m theta) / sqrt(pi J_{m+1}(j)^2 / eps_m),
 * eps_0 = 1, eps_m = 2, so that b_k = psi_k / sqrt(sigma a^2) = phi_k / sqrt(M_k). */
void mode_table_shapes(const mode_table *t, int live, double r_over_a, double theta_deg, float *psi)
{
    double theta = theta_deg * (M_PI / 180.0);
    double radial = 0.0;
    for (int k = 0; k < t->size; k++) {
        if (k >= live) {
            psi[k] = 0.0f;
            continue;
        }
        /* cos and sin partners are adjacent and share J_m(j r/a). */
        if (!(k > 0 && t->j[k] == t->j[k - 1] && t->m[k] == t->m[k - 1]))
            radial = t->plate ? plate_mode_radial(&t->plate[k], r_over_a)
                              : ictus_bessel_j(t->m[k], t->j[k] * r_over_a);
        double angular = t->sin[k] ? sin(t->m[k] * theta) : cos(t->m[k] * theta);
        psi[k] = (float)(radial * angular * t->norm[k] * t->scale[k]);
    }
}

void mode_table_patch_filter(const mode_table *t, int live, double eps, float *psi)
{
    if (!(eps > 0.0) || t->plate)
        return;
    double mean = 1.0;
    for (int k = 0; k < live && k < t->size; k++) {
        if (!(k > 0 && t->j[k] == t->j[k - 1])) {
            double x = t->j[k] * eps;
            mean = 2.0 * ictus_bessel_j(1, x) / x;
        }
        psi[k] = (float)(psi[k] * mean);
    }
}

double mode_table_shape(const mode_table *t, int k, double r_over_a, double theta_rad)
{
    const double radial = t->plate ? plate_mode_radial(&t->plate[k], r_over_a)
                                   : ictus_bessel_j(t->m[k], t->j[k] * r_over_a);
    return radial * t->norm[k] * t->scale[k] *
           (t->sin[k] ? sin(t->m[k] * theta_rad) : cos(t->m[k] * theta_rad));
}

double mode_table_tuned_j(const mode_table *t, int k, const mode_tuning *u)
{
    if (!u || t->plate || t->n[k] != 1 || t->m[k] >= u->count)
        return t->j[k] * t->scale[k];
    return t->j[k] * u->factor_m1[t->m[k]] * t->scale[k];
}

double mode_table_decay_factor(const mode_table *t, int k, const mode_tuning *u)
{
    if (!u || t->plate || u->count == 0 || t->n[k] != 1 || t->m[k] != 0)
        return 1.0;
    return u->decay_01;
}
