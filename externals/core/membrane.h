/* membrane.h -- modal circular membrane (plain C99, no Pd).
 *
 * An ideal circular membrane of radius a (m), tension T (N/m) and areal density
 * sigma (kg/m^2), fixed at its rim. Its modes (m, n) ring at
 *     f_mn = j_mn * c / (2 pi a),  c = sqrt(T / sigma),
 * where j_mn is the n-th positive zero of the Bessel function J_m. Modes with
 * m >= 1 come in degenerate cos/sin pairs; each is a separate mode here, so the
 * angles of the strike and of the pickups matter. Mode shapes:
 *     phi(r, theta) = J_m(j_mn r / a) * {cos, sin}(m theta).
 * Each mode is a damped oscillator driven by the force at the strike point and
 * by the objects attached to the membrane at coupling points (the sticks of
 * contact.h); the state of all of them advances together sample by sample in
 * membrane_process().
 *
 * Damping law (documented in docs/membrane.md):
 *     sigma_k = sigma0 + sigma1 * omega_k^2 + radiation sigma_rad,k + eta omega_k / 2
 * (decay rate, 1/s; T60 = ln(1000)/sigma_k): sigma0 and sigma1 set by the t60 and
 * hfdamp controls, sigma_rad,k the mode's air radiation, eta the internal loss.
 *
 * Threading: one instance is used by one thread at a time. Setters may be
 * called between membrane_process() calls while sounding; they never click,
 * blow up or produce NaN. Only functions documented as "allocates" allocate;
 * membrane_process() never allocates, locks or prints.
 */
#ifndef ICTUS_MEMBRANE_H
#define ICTUS_MEMBRANE_H

#include "ictus_param.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Legal ranges (SI units). Setters clamp into them and say so (ICTUS_CLAMPED);
 * ictus_param_range() gives the same numbers at run time. */
#define MEMBRANE_RADIUS_MIN     0.01  /* m */
#define MEMBRANE_RADIUS_MAX     2.0   /* m */
#define MEMBRANE_TENSION_MIN    1.0   /* N/m */
#define MEMBRANE_TENSION_MAX    1.0e5 /* N/m */
#define MEMBRANE_DENSITY_MIN    0.01  /* kg/m^2 */
#define MEMBRANE_DENSITY_MAX    20.0  /* kg/m^2 */
#define MEMBRANE_MODES_MIN      1
#define MEMBRANE_MODES_MAX      4096
#define MEMBRANE_T60_MIN        0.005 /* s */
#define MEMBRANE_T60_MAX        60.0  /* s */
#define MEMBRANE_HF_DAMPING_MIN 0.0   /* docs/membrane.md */
#define MEMBRANE_HF_DAMPING_MAX 1000.0
#define MEMBRANE_TENSION_MOD_MIN 0.0 /* 0: linear head (constant tension) */
#define MEMBRANE_TENSION_MOD_MAX 100.0
#define MEMBRANE_RADIATION_MIN   0.0 /* 0: no air radiation loss */
#define MEMBRANE_RADIATION_MAX   100.0
#define MEMBRANE_AIR_MASS_MIN    0.0 /* 0: no air's mass on the head */
#define MEMBRANE_AIR_MASS_MAX    4.0
#define MEMBRANE_LOSS_FACTOR_MIN 0.0 /* 0: no internal loss */
#define MEMBRANE_LOSS_FACTOR_MAX 0.5
#define MEMBRANE_PATCH_MIN       0.0 /* m; 0: a point */
#define MEMBRANE_PATCH_MAX       0.05
#define MEMBRANE_BENDING_MIN     1.0e-3 /* N m: a plate's bending stiffness (membrane_set_plate) */
#define MEMBRANE_BENDING_MAX     1.0e4
#define MEMBRANE_CASCADE_MIN     0.0 /* 0: a linear plate */
#define MEMBRANE_CASCADE_MAX     100.0
#define MEMBRANE_VON_KARMAN_MIN  0.0 /* 0: off */
#define MEMBRANE_VON_KARMAN_MAX  10.0
#define MEMBRANE_OPENNESS_MIN    0.0 /* a hi-hat's pedal: 0 closed, 1 open */
#define MEMBRANE_OPENNESS_MAX    1.0
#define MEMBRANE_EDGE_DAMP_MIN   0.0 /* N s/m^2: 0, no second plate */
#define MEMBRANE_EDGE_DAMP_MAX   1.0e4
#define MEMBRANE_GAIN_MIN       -1.0e6 /* s/m; negative inverts */
#define MEMBRANE_GAIN_MAX       1.0e6
#define MEMBRANE_R_OVER_A_MIN   0.0 /* points: pickups, strikes, contacts */
#define MEMBRANE_R_OVER_A_MAX   1.0
#define MEMBRANE_IMPULSE_MAX    1.0e3  /* N s, |strike impulse| */
#define MEMBRANE_PICKUPS        2      /* pickups (outputs) per membrane */
#define MEMBRANE_MAX_POINTS     4      /* coupling points (contacts) attached at once */
#define MEMBRANE_SR_MIN         1000.0 /* Hz */
#define MEMBRANE_SR_MAX         768000.0

/* Defaults: a 14-inch Mylar head (radius 0.178 m, 0.262 kg/m^2) at 3000 N/m. */
#define MEMBRANE_DEFAULT_RADIUS     0.178
#define MEMBRANE_DEFAULT_TENSION    3000.0
#define MEMBRANE_DEFAULT_DENSITY    0.262
#define MEMBRANE_DEFAULT_MODES      128
#define MEMBRANE_DEFAULT_T60        1.0
#define MEMBRANE_DEFAULT_HF_DAMPING 1.0
/* Tension modulation (docs/membrane.md, "Tension modulation"): 1 = a Mylar head. */
#define MEMBRANE_DEFAULT_TENSION_MOD 1.0
/* Losses from physics (docs/membrane.md, "Losses"): air radiation of a baffled head
 * (1 = a head in an infinite baffle, 0.5 = the same head radiating into free space on
 * one side) and the film's internal loss factor eta (decay rate eta w / 2). */
#define MEMBRANE_DEFAULT_RADIATION   0.5
#define MEMBRANE_DEFAULT_LOSS_FACTOR 0.002
/* The air's mass on the modes (docs/membrane.md, "The air's mass"): 0 for the bare head;
 * 1 = the air on one face of a head in an infinite baffle. */
#define MEMBRANE_DEFAULT_AIR_MASS 0.0
/* The contact patch (docs/membrane.md, "The contact patch"): forces come in spread
 * evenly over a disc of this radius and a stick feels the static compliance of the modes
 * left out. 0 (the bare head's default): a point, no correction; the drum presets take
 * the stick bead's radius, the physics' tip radius. */
#define MEMBRANE_DEFAULT_PATCH       0.0
/* A plate's bending stiffness D = E h^3 / (12 (1 - nu^2)): 1 mm of bronze (E 100 GPa,
 * nu 0.33); a membrane does not use it. */
#define MEMBRANE_DEFAULT_BENDING     9.35
/* The energy cascade (docs/plates.md, "The cascade"; docs/membrane.md, "The energy
 * cascade"): 0 off (a bare plate or head; the cymbal and most drum presets turn it on); and the von
 * Karman coupling of its lowest modes: 0 off, 1 bronze. */
#define MEMBRANE_DEFAULT_CASCADE     0.0
#define MEMBRANE_DEFAULT_VON_KARMAN  0.0
/* A hi-hat's pedal (docs/plates.md, "The hi-hat"): the default is the stand at rest, the
 * spring holding the plates apart; no second plate by default. */
#define MEMBRANE_DEFAULT_OPENNESS    1.0
#define MEMBRANE_DEFAULT_EDGE_DAMP   0.0
#define MEMBRANE_PATCH_BEAD          0.007
#define MEMBRANE_AIR_RHO             1.2   /* kg/m^3 */
#define MEMBRANE_AIR_C               343.0 /* m/s */
/* Mylar (PET film), for the tension modulation: Young's modulus (Pa), Poisson's ratio
 * and density (kg/m^3); the head's thickness is its areal density / MEMBRANE_MYLAR_RHO. */
#define MEMBRANE_MYLAR_YOUNG   4.5e9
#define MEMBRANE_MYLAR_POISSON 0.38
#define MEMBRANE_MYLAR_RHO     1390.0
/* A forte hit (0.05 kg stick at 5 m/s, default head, r/a = 0.3) peaks near 0.5 full
 * scale with this gain (measured by tests/core, docs/membrane.md#output-scale). */
#define MEMBRANE_DEFAULT_GAIN 0.16

/* The one-number parameters, set, read and ranged through membrane_params
 * (ictus_param.h): ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_T60, 2.0).
 * Setting one that shapes the modes recomputes the coefficients and rescales the
 * state so that the sound goes on without a click. */
typedef enum membrane_param {
    MEMBRANE_PARAM_RADIUS,  /* m */
    MEMBRANE_PARAM_TENSION, /* N/m */
    MEMBRANE_PARAM_DENSITY, /* kg/m^2 */
    /* kg: sets the density as mass / (pi a^2), clamped into the density range times
     * pi a^2 (its range follows the radius); density wins if set later. */
    MEMBRANE_PARAM_MASS,
    MEMBRANE_PARAM_MODES, /* a count, as membrane_set_modes(); a fraction rounds to the nearest */
    /* Damping: T60 of the fundamental (s), and the high-frequency damping control
     * (documented in docs/membrane.md; 0 = every mode decays like the fundamental). */
    MEMBRANE_PARAM_T60,
    MEMBRANE_PARAM_HF_DAMPING,
    MEMBRANE_PARAM_GAIN, /* output gain applied to the pickups (docs/membrane.md) */
    /* Tension modulation, dimensionless: the stretch of a Mylar head raises its tension
     * with the vibration energy E (J), T = T0 (1 + tensionmod kappa E), kappa from
     * Young's modulus, thickness and T0 (docs/membrane.md); every mode's frequency
     * follows sqrt(T / T0). 1 = Mylar, 0 = a linear head (constant tension). */
    MEMBRANE_PARAM_TENSION_MOD,
    /* Losses added to the t60/hfdamp law: the air radiation of each mode (a factor
     * on the baffled-membrane radiation rate, 1 = air) and the film's internal loss
     * factor eta (decay rate eta w / 2). Both 0: the t60/hfdamp law alone. */
    MEMBRANE_PARAM_RADIATION,
    MEMBRANE_PARAM_LOSS_FACTOR,
    /* m: radius of the disc a strike's or a stick's force is spread over (0: a point) */
    MEMBRANE_PARAM_PATCH,
    /* N m: the bending stiffness D of a plate (membrane_set_plate); a membrane ignores it */
    MEMBRANE_PARAM_BENDING,
    /* A plate's energy cascade (docs/plates.md, "The cascade"): energy moves between
     * neighbouring third-octave bands of modes toward equal energy per mode, at a rate
     * cascade x Gamma, Gamma the frequency shift the in-plane stress of the vibration puts
     * on every mode (1 = that rate; 0 = linear). On a membrane with tension modulation,
     * at cascade x w01 x ((g - 1) / 0.1)^2, g its frequency factor (docs/membrane.md). */
    MEMBRANE_PARAM_CASCADE,
    /* A hi-hat (docs/plates.md, "The hi-hat"): the bottom plate pressed against a plate's
     * edge by the pedal acts as a dashpot spread along the edge, edgedamp N s/m^2 (N per
     * m/s per metre of edge) when closed, times (1 - openness)^2; openness 0 closed, 1
     * open (the plates apart). A membrane, fixed at its rim, is not moved by it. */
    MEMBRANE_PARAM_OPENNESS,
    MEMBRANE_PARAM_EDGE_DAMP,
    /* A plate's von Karman coupling of its lowest 32 modes (docs/plates.md): a factor on
     * the stretching stiffness E h (1 = the bronze plate of that D and density; 0 = off);
     * a membrane ignores it */
    MEMBRANE_PARAM_VON_KARMAN,
    /* The air's mass on a membrane's modes (docs/membrane.md, "The air's mass"): a factor
     * on the mass the air on one face of the head in an infinite baffle adds to each mode
     * (the reactive part of the radiation the "radiation" loss is the resistive part of;
     * 1 = that air, 0 = none). Heavier, every mode rings lower, the (0, n) modes most; a
     * plate ignores it. */
    MEMBRANE_PARAM_AIR_MASS,
    MEMBRANE_PARAM_COUNT
} membrane_param;

/* Indexed by membrane_param; names as the Pd messages (hfdamp, gain). */
extern const ictus_param_table membrane_params;

typedef struct membrane membrane;

/* Creates a membrane with the defaults above at the given sample rate (Hz).
 * Allocates. Returns NULL when memory cannot be had. */
membrane *membrane_new(double sample_rate_hz);
void membrane_free(membrane *m);

/* A thin circular plate with a free edge (plate 1: a cymbal, docs/plates.md) or the
 * membrane fixed at its rim (0, the default) of the same radius and density: the
 * modes become the plate's, ringing at lambda^2 / (2 pi a^2) sqrt(D / density) with D
 * the "bending" parameter, and the state is cleared. On a plate the tension, the
 * tension modulation, the air radiation and the contact patch do nothing (the
 * t60/hfdamp law sets the decays). Allocates: message time only. */
ictus_status membrane_set_plate(membrane *m, int plate);
int membrane_is_plate(const membrane *m);

/* Sample rate of this instance (Hz); recomputes the coefficients, keeps the state. */
ictus_status membrane_set_sample_rate(membrane *m, double sample_rate_hz);

/* Number of modes (sorted by frequency). Allocates when growing beyond the
 * capacity reached so far; call from a message handler, never from audio.
 * Modes above Nyquist*0.95 are kept silent (counted, not ringing). */
ictus_status membrane_set_modes(membrane *m, int count);

/* Pickup `index` (0 .. MEMBRANE_PICKUPS-1) at r/a in [0, 1], angle in degrees. */
ictus_status membrane_set_pickup(membrane *m, int index, double r_over_a, double theta_deg);

/* Point where the force input of membrane_process() is applied. */
ictus_status membrane_set_strike_point(membrane *m, double r_over_a, double theta_deg);

/* An ideal impulse (N s) at (r/a, theta), landing `sample_offset` samples into the
 * next membrane_process() call (offsets past that block carry over to later
 * blocks). Up to 64 pending strikes are queued (membrane_reserve_strikes: more); more
 * are dropped and counted (membrane_dropped_strikes). */
ictus_status membrane_strike(membrane *m, double r_over_a, double theta_deg, double impulse_ns,
                             int sample_offset);

/* Room for `count` pending strikes (at least 64): a block of n samples may hold one on
 * every sample. Never shrinks. ICTUS_ENOMEM: the room stays as it was. Allocates. */
ictus_status membrane_reserve_strikes(membrane *m, int count);

/* Silences every mode at once, and ends the stroke of every attached contact. */
void membrane_clear(membrane *m);

/* The largest force (N) the core applies: force_in beyond +-MEMBRANE_FORCE_MAX is
 * clamped to it, and so is a contact's force (no drumstick pushes with a teranewton). */
#define MEMBRANE_FORCE_MAX 1.0e12

/* Advances n samples. force_in (may be NULL) is a force (N) applied at the
 * strike point (NaN and inf count as 0, beyond +-MEMBRANE_FORCE_MAX it is clamped);
 * out[0..MEMBRANE_PICKUPS-1] receive the pickup signals (membrane velocity, see docs/membrane.md).
 * force_in may alias an output. When out is not NULL but out[1] is, the second pickup is not
 * computed at all (one dot product per mode and sample less); pickup 0 is the same either way. */
void membrane_process(membrane *m, const float *force_in, float *const *out, int n);

/* Read-back, for tests, help patches and the wrappers' error messages (the
 * one-number parameters: ictus_param_get(&membrane_params, m, id)). */
double membrane_get_sample_rate(const membrane *m);
int membrane_get_modes(const membrane *m);
/* Of those modes, how many ring: the others lie above 0.95 x Nyquist and are kept
 * silent. 0 means the membrane makes no sound at this sample rate. */
int membrane_get_sounding_modes(const membrane *m);
/* Mode k (0-based, sorted by frequency): frequency (Hz), T60 (s), indices (m, n)
 * and which of the degenerate pair (0 = cos, 1 = sin). Return 0 on a bad k. */
int membrane_get_mode(const membrane *m, int k, double *freq_hz, double *t60_s, int *bessel_m,
                      int *bessel_n, int *sin_partner);
/* Membrane transverse displacement (m) and velocity (m/s) at a point, from the
 * current modal state (O(modes); not for the audio loop). */
double membrane_displacement_at(const membrane *m, double r_over_a, double theta_deg);
double membrane_velocity_at(const membrane *m, double r_over_a, double theta_deg);
/* Total vibrational energy of the modes (J). */
double membrane_energy(const membrane *m);
/* A plate's nonlinear potential (J) in its von Karman coupling (docs/plates.md): the
 * scheme's psi^2 / 2 less its floor; 0 without it (the energy cascade has none). */
double membrane_cascade_energy(const membrane *m);
/* Tension modulation: the coefficient kappa (1/J) of T = T0 (1 + kappa E) at the
 * current parameters (tensionmod included), and the frequency factor sqrt(T / T0)
 * the modes ring with now (1 for a linear head). */
double membrane_tension_kappa(const membrane *m);
double membrane_frequency_factor(const membrane *m);
/* Strikes dropped because the queue was full. */
long membrane_dropped_strikes(const membrane *m);

/* The n-th positive zero (n >= 1) of the Bessel function J_m (m >= 0), computed
 * to about 1e-13 relative (not from a table). Exposed for tests and docs. */
double ictus_bessel_zero(int m, int n);
/* J_m(x) for integer m >= 0. */
double ictus_bessel_j(int m, double x);

/* Which modal kernel this instance runs: "avx512", "avx2+fma" or "generic" (chosen at
 * membrane_new() from the CPU's features and ICTUS_MEMBRANE_KERNEL: ictus_simd.h).
 * For benchmarks and bug reports. */
const char *membrane_kernel_name(const membrane *m);

#ifdef __cplusplus
}
#endif
#endif
