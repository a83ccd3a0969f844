/* plate_cascade.h -- the von Karman coupling of a free-edge plate's lowest modes
 * (the cymbal's cascade; docs/plates.md, "The cascade").
 *
 * The transverse modes Y_k (energy-normalised: kinetic energy sum Y_k'^2 / 2) of the
 * first `modes` entries of a plate's mode table couple through in-plane (Airy stress
 * function) modes chi_a, the eigenfunctions of the biharmonic operator with chi =
 * chi' = 0 at the edge (the free edge's in-plane conditions; C. Touze, O. Thomas,
 * A. Chaigne, JSV 258(4), 2002):
 *     V = sum_a kappa_a phi_a^2,   phi_a = sum_ij H^a_ij Y_i Y_j,
 *     H^a_ij = integral over the unit disc of chi_a L(W_i, W_j),
 * L the von Karman bracket, kappa_a = E h / (8 a^6 (rho h)^2 zeta_a^4). H is sparse:
 * the angular orders satisfy m_a = |m_i +- m_j|. Built at message time (allocates);
 * plate_cascade_step runs on the audio thread and does not. */
#ifndef ICTUS_PLATE_CASCADE_H
#define ICTUS_PLATE_CASCADE_H

#include "mode_table.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The most transverse modes a cascade couples (a multiple of 32). */
#define PLATE_CASCADE_MAX_MODES 256

typedef struct plate_cascade {
    int modes;   /* coupled transverse modes: table entries 0 .. modes-1 */
    int inplane; /* in-plane modes */
    int entries; /* nonzero H^a_ij (i, j in either order) */
    plate_mode *ip;
    int *ip_sin;
    double *zeta4;
    /* H by columns: in-plane mode a has the columns col[row[a] .. row[a + 1] - 1] with an
     * entry, column e (H^a_ij over i) at val + e modes */
    int *row, *col;
    float *val;
    float *kappa;
    /* the scheme's state (membrane_cascade.c) and scratch; t = H^a Y, inplane x modes */
    float *y, *g, *dy, *t;
    double psi; /* the auxiliary variable, psi^2 / 2 = V + floor */
    /* plate_cascade_potential's body for this CPU (plate_cascade_kernel.inc) */
    double (*potential)(const struct plate_cascade *c, const float *y, float *grad);
    double floor; /* J: keeps psi away from 0 */
} plate_cascade;

/* The in-plane mode (m, s) (s = 0, 1, ...: the s-th root) of the clamped biharmonic
 * problem on the unit disc: lambda = zeta (root of J_m I_m+1 + J_m+1 I_m), c_scaled and
 * norm as plate_mode (plate_mode_radial gives chi(r), normalised over the disc with
 * cos^2 (m >= 1) or 1). 0 on success. */
int plate_inplane_mode(int m, int s, plate_mode *out);

/* H = integral over the unit disc of chi_a L(W_i, W_j) for an in-plane mode and two
 * transverse modes, each with its angular part cos (sin 0) or sin (sin 1). */
double plate_cascade_h(const plate_mode *a, int a_sin, const plate_mode *i, int i_sin,
                       const plate_mode *j, int j_sin);

/* Couples the first `modes` modes (a multiple of 32, at most PLATE_CASCADE_MAX_MODES) of
 * table t (a plate's) through every in-plane mode with
 * zeta < zeta_max; entries with |H| below rel_tol times the largest are dropped.
 * Allocates; ICTUS_ENOMEM leaves *c empty. */
ictus_status plate_cascade_build(plate_cascade *c, const mode_table *t, int modes, double zeta_max,
                                 double rel_tol);
void plate_cascade_free(plate_cascade *c);

/* kappa_a from the stretching stiffness E h (N/m, times the user's factor), the
 * radius (m) and the areal density (kg/m^2). */
void plate_cascade_set_scale(plate_cascade *c, double eh, double radius, double density);

/* V (J) at y (c->modes values); grad (may be NULL) receives dV/dY. No allocation. */
double plate_cascade_potential(const plate_cascade *c, const float *y, float *grad);
/* Its two builds (the AVX2 one only where the CPU has AVX2 and FMA). */
double plate_cascade_potential_generic(const plate_cascade *c, const float *y, float *grad);
double plate_cascade_potential_avx2(const plate_cascade *c, const float *y, float *grad);

/* The auxiliary variable set from the potential at y (with floor): after the state
 * was changed from outside the scheme. */
void plate_cascade_anchor(plate_cascade *c, const float *y);

#ifdef __cplusplus
}
#endif
#endif
