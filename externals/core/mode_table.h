/* mode_table.h -- the modes of an ideal circular membrane fixed at its rim, or of a
 * thin circular plate with a free edge (plate_modes.h), in order of frequency: the
 * frequency parameter each mode rings at, its (m, n) indices, which partner of a
 * degenerate cos/sin pair it is, and its mass-normalised shape (docs/membrane.md,
 * "The membrane"; docs/plates.md). Internal to the core (the membrane's rooms). */
#ifndef ICTUS_MODE_TABLE_H
#define ICTUS_MODE_TABLE_H

#include "membrane.h"
#include "plate_modes.h"

/* Entry k is the k-th mode by frequency; f_k = j[k] c / (2 pi a), with c the wave
 * speed sqrt(T / sigma) of a membrane, and for a plate c = sqrt(D / sigma) / a and
 * j = lambda^2 (plate_modes.h). The cos and sin partners of an m >= 1 pair are
 * adjacent (cos first). Any prefix of the table is the table of that many modes, so a
 * mode keeps its index when the count changes. */
typedef struct mode_table {
    double *j;    /* membrane: zero of J_m; plate: lambda^2 */
    double *norm; /* sqrt(eps_m / pi) / |J_{m+1}(j)|: makes the shapes mass-normalised */
    int *m, *n;   /* order (nodal diameters), and which zero of J_m (plate: nodal circles) */
    int *sin;     /* 0: cos(m theta) partner, 1: sin(m theta) partner */
    /* The shape squared integrated around the edge, the integral over theta of
     * psi(1, theta)^2: what a loss spread along the edge takes from the mode (a
     * hi-hat's second plate, docs/plates.md). 0 for a membrane (fixed at its rim). */
    double *edge;
    /* The air's load (membrane_modes.c, docs/membrane.md "The air's mass"): air[k] is the
     * mass the air on one face of the head in an infinite baffle adds to mode k, per unit
     * of rho_air a / sigma (the low-frequency limit of its radiation reactance; 0 for a
     * plate), and scale[k] = 1 / sqrt(1 + beta_k), beta_k that added mass over the mode's
     * own as the head now has it (1: no air; membrane_modes.c sets it): the shapes and
     * the frequency of mode k carry it. */
    double *air, *scale;
    int air_valid; /* air[k] is computed for k < air_valid (mode_table_prepare_air) */
    int size;
    plate_mode *plate; /* a plate's modes (their radial shapes, normalised), NULL: a membrane */
} mode_table;

/* Fills *t with the first `size` modes (size >= 1) of a membrane (plate 0) or of a
 * free-edge plate of Poisson's ratio MODE_TABLE_PLATE_NU (plate 1). Allocates. On
 * ICTUS_ENOMEM *t is left empty (all NULL). */
ictus_status mode_table_build(mode_table *t, int size, int plate);
/* Bronze and brass (cymbal alloys): nu = 0.33 (also the value of Leissa's tables). */
#define MODE_TABLE_PLATE_NU 0.33
void mode_table_free(mode_table *t);

/* The air's mass on mode k per unit of rho_air a / sigma, for the mode of zero j of J_m:
 * g = 2 j^2 int_0^inf J_m(u)^2 / (j^2 - u^2)^2 du (a baffled head's radiation reactance
 * at low ka; its wavenumber transform by the Lommel integral). g j tends to 1 (an
 * infinite membrane's rho / k) as j grows. Exported for the tests. */
double mode_table_air_g(int m, double j);
/* Computes air[k] for the modes that lack it (none for a plate): only a head with air
 * on it asks, at message time, once per mode, J_m at the quadrature nodes once per m
 * (setting airmass on a head of 1024 modes: 41 ms, 4096: 0.24 s). */
void mode_table_prepare_air(mode_table *t);

/* psi[k] = J_m(j r/a) {cos, sin}(m theta) * norm for k < live, 0 for live <= k < size:
 * the mass-normalised shapes of the live modes at one point (O(size) Bessel calls,
 * one per cos/sin pair; not for the audio loop). */
void mode_table_shapes(const mode_table *t, int live, double r_over_a, double theta_deg,
                       float *psi);

/* A force spread evenly over a disc of radius eps (relative to the head's) instead
 * of a point: every shape times its mean over the disc, 2 J1(j eps) / (j eps) (the
 * mean value theorem of the Helmholtz equation, which each mode shape solves), for
 * k < live. eps <= 0, or a plate: unchanged (a plate takes forces at a point). O(live)
 * Bessel calls. */
void mode_table_patch_filter(const mode_table *t, int live, double eps, float *psi);

/* The same for mode k alone, in double (theta in radians). */
double mode_table_shape(const mode_table *t, int k, double r_over_a, double theta_rad);

/* A correction of the ideal membrane's frequencies and decays for what loads the
 * head (a timpani's kettle: membrane_presets.c, docs/sound.md). The (m, 1) mode rings
 * at factor_m1[m] times its ideal frequency for m < MODE_TUNING_M (1 for the other
 * modes), and the (0, 1) mode decays decay_01 times faster than the damping law says.
 * count 0: no correction (the ideal membrane). The shapes stay the ideal ones. */
#define MODE_TUNING_M 8
typedef struct mode_tuning {
    int count; /* factor_m1[0 .. count-1] are set, count <= MODE_TUNING_M */
    double factor_m1[MODE_TUNING_M];
    double decay_01; /* >= 1 */
} mode_tuning;

/* The zero that sets mode k's frequency under tuning u (u NULL or count 0: j[k]), times
 * the air's scale[k] (a tuning is of the head in vacuo). */
double mode_table_tuned_j(const mode_table *t, int k, const mode_tuning *u);
/* The factor on mode k's decay rate under tuning u (1 but for a tuned (0, 1) mode). */
double mode_table_decay_factor(const mode_table *t, int k, const mode_tuning *u);

#endif
