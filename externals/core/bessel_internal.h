/* bessel_internal.h -- helpers shared by bessel.c, mode_table.c and the modes' integrals
 * (not public API). */
#ifndef ICTUS_BESSEL_INTERNAL_H
#define ICTUS_BESSEL_INTERNAL_H

typedef struct ictus_bessel_zero_entry {
    double j; /* zero of J_m */
    int m, n;
} ictus_bessel_zero_entry;

/* {J_{m-1}(x), J_m(x), J_{m+1}(x)} for x >= 0 in one Miller recurrence. */
void ictus_bessel_j3(int m, double x, double out[3]);

/* int_0^x J_m(t) dt, in the same recurrence as J_m (any sign of x). */
double ictus_bessel_j_integral(int m, double x);

/* All zeros j_{m,n} < x_max, sorted by (j, m, n), in a malloc'd array the caller
 * frees. Returns the count, or -1 when memory cannot be had. Allocates. */
int ictus_bessel_zeros_below(double x_max, ictus_bessel_zero_entry **out);

/* The n Gauss-Legendre points x and weights w on [0, 1] (the weights sum to 1), by
 * Newton on P_n (Numerical Recipes' gauleg). */
void ictus_gauss_legendre(int n, double *x, double *w);

#endif
