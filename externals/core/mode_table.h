/* mode_table.h -- the modes of an ideal circular membrane fixed at its rim, in
 * order of frequency: the Bessel zero each mode rings at, its (m, n) indices, which
 * partner of a degenerate cos/sin pair it is, and its mass-normalised shape
 * (docs/membrane.md, "The membrane"). Internal to the core (the membrane's rooms). */
#ifndef ICTUS_MODE_TABLE_H
#define ICTUS_MODE_TABLE_H

#include "membrane.h"

/* Entry k is the k-th mode by frequency; f_k = j[k] c / (2 pi a). The cos and sin
 * partners of an m >= 1 pair are adjacent (cos first). Any prefix of the table is
 * the table of that many modes, so a mode keeps its index when the count changes. */
typedef struct mode_table {
    double *j;    /* zero of J_m */
    double *norm; /* sqrt(eps_m / pi) / |J_{m+1}(j)|: makes the shapes mass-normalised */
    int *m, *n;   /* Bessel order, and which zero of J_m */
    int *sin;     /* 0: cos(m theta) partner, 1: sin(m theta) partner */
    int size;
} mode_table;

/* Fills *t with the first `size` modes (size >= 1). Allocates. On ICTUS_ENOMEM *t
 * is left empty (all NULL). */
ictus_status mode_table_build(mode_table *t, int size);
void mode_table_free(mode_table *t);

/* psi[k] = J_m(j r/a) {cos, sin}(m theta) * norm for k < live, 0 for live <= k < size:
 * the mass-normalised shapes of the live modes at one point (O(size) Bessel calls,
 * one per cos/sin pair; not for the audio loop). */
void mode_table_shapes(const mode_table *t, int live, double r_over_a, double theta_deg,
                       float *psi);

/* The same for mode k alone, in double (theta in radians). */
double mode_table_shape(const mode_table *t, int k, double r_over_a, double theta_rad);

#endif
