/* snare_internal.h -- the snare head's kernel (snare_kernel.inc), shared by
 * snare_wires.c and the two builds of the kernel. Not part of the API. */
#ifndef ICTUS_SNARE_INTERNAL_H
#define ICTUS_SNARE_INTERNAL_H

#define SNARE_RADII      4 /* wire segments in pairs at x / a = +-r_j */
#define SNARE_KERNEL_PAD 16 /* each mode group padded to a multiple of 16 floats (AVX-512) */

/* The snare head's float state and coefficients: groups [0, n0) the (0, n) modes,
 * [n0, ne) the other even-m modes, [ne, n) the odd-m modes, each a multiple of
 * SNARE_KERNEL_PAD (padding all zero), 64-byte aligned. */
typedef struct snare_kernel_args {
    int n0, ne, n;
    float *x, *v, *xf;
    const float *ca, *cb, *g, *mean, *pick;
    const float *psi[SNARE_RADII];
} snare_kernel_args;

/* xf = ca x + cb v for every mode; the sum of mean xf and, when wires is 1, those of
 * psi_j xf over the even and the odd modes apart (0 otherwise). */
typedef void (*snare_kernel_free_fn)(snare_kernel_args *a, int wires, double *mean,
                                     double even[SNARE_RADII], double odd[SNARE_RADII]);
/* The sample's forces (fa on the mean; F_+ + F_- on the even, F_+ - F_- on the odd
 * modes) into x and v; the new velocity's sums at the pickup, even and odd apart. */
typedef void (*snare_kernel_force_fn)(snare_kernel_args *a, double fa, const double Fe[SNARE_RADII],
                                      const double Fo[SNARE_RADII], double two_over_t,
                                      double *pick_even, double *pick_odd);

void snare_kernel_free_generic(snare_kernel_args *a, int wires, double *mean,
                               double even[SNARE_RADII], double odd[SNARE_RADII]);
void snare_kernel_force_generic(snare_kernel_args *a, double fa, const double Fe[SNARE_RADII],
                                const double Fo[SNARE_RADII], double two_over_t, double *pick_even,
                                double *pick_odd);
void snare_kernel_free_avx2(snare_kernel_args *a, int wires, double *mean, double even[SNARE_RADII],
                            double odd[SNARE_RADII]);
void snare_kernel_force_avx2(snare_kernel_args *a, double fa, const double Fe[SNARE_RADII],
                             const double Fo[SNARE_RADII], double two_over_t, double *pick_even,
                             double *pick_odd);
void snare_kernel_free_avx512(snare_kernel_args *a, int wires, double *mean,
                              double even[SNARE_RADII], double odd[SNARE_RADII]);
void snare_kernel_force_avx512(snare_kernel_args *a, double fa, const double Fe[SNARE_RADII],
                               const double Fo[SNARE_RADII], double two_over_t, double *pick_even,
                               double *pick_odd);

#endif
