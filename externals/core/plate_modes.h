/* plate_modes.h -- the modes of a thin circular plate with a free edge (plain C99).
 *
 * A Kirchhoff plate of radius a, bending stiffness D = E h^3 / (12 (1 - nu^2)) and
 * areal density rho h, free at its edge (a cymbal, a hi-hat's plate: held at the
 * centre by a felt, free at the rim). Its modes (m, s), m nodal diameters and s
 * nodal circles, ring at
 *     omega = lambda^2 / a^2 * sqrt(D / (rho h)),
 * with shapes W(r) {cos, sin}(m theta), W(r) = J_m(lambda r / a) + C I_m(lambda r / a),
 * where lambda and C make the edge free of bending moment and of effective shear
 * (Kirchhoff's free-edge conditions: A. W. Leissa, *Vibration of Plates*, NASA SP-160,
 * 1969, ch. 2). Rigid-body motions (m = 0 and m = 1 without a nodal circle) are
 * not modes here. Everything here allocates or takes O(m + lambda) Bessel work:
 * message time, never the audio thread.
 */
#ifndef ICTUS_PLATE_MODES_H
#define ICTUS_PLATE_MODES_H

#ifdef __cplusplus
extern "C" {
#endif

/* One free-edge mode: its frequency parameter lambda, its indices, and the
 * constant C of its radial shape (I_m's weight, against e^-lambda-scaled I_m:
 * W(r) = J_m(lambda r) + c_scaled e^-lambda I_m(lambda r), r = r/a). */
typedef struct plate_mode {
    double lambda;
    double c_scaled;
    double norm; /* 1 / sqrt(integral of W^2 over the unit disc, with cos^2 or 1) */
    int m, s;
} plate_mode;

/* lambda of mode (m, s) for Poisson's ratio nu (0 <= nu < 0.5): s nodal circles,
 * s >= 1 for m = 0 and 1, s >= 0 for m >= 2. 0 for a rigid-body pair (m <= 1, s = 0)
 * or arguments out of range. To ~1e-12 relative. */
double plate_free_lambda(int m, int s, double nu);

/* The modes with lambda < lambda_max, one entry per (m, s) (an m >= 1 mode is a
 * cos/sin pair: the caller lays both), sorted by lambda, in a malloc'd array the
 * caller frees. Returns the count, or -1 when memory cannot be had. Allocates. */
int plate_free_modes_below(double lambda_max, double nu, plate_mode **out);

/* The normalised radial shape W(r) norm of mode p at r = r/a in [0, 1]: with
 * {cos, sin}(m theta) and 1 / sqrt(rho h a^2) it is the mass-normalised mode shape
 * (the integral of rho h psi^2 over the plate is 1). */
double plate_mode_radial(const plate_mode *p, double r_over_a);

/* e^-x I_m(x) for x >= 0 and integer m >= 0 (the modified Bessel function of the
 * first kind, scaled). Exposed for tests. */
double ictus_bessel_i_scaled(int m, double x);

#ifdef __cplusplus
}
#endif
#endif
