/* membrane_presets.h -- drum heads modelled on measured instruments, by name: one table
 * for membrane~'s "preset NAME", the ictus-drum abstraction and ictusd's --drum-preset
 * (docs/sound.md, "Presets", gives each value's source). Plain C99, no Pd.
 *
 * The table (membrane_presets.c) is data only, so that the daemon can link it without
 * the DSP core; membrane_preset_apply() (membrane_preset_apply.c) sets a membrane to a
 * preset through the parameter table (ictus_param.h) and the mode table's tuning
 * (mode_table.h). */
#ifndef ICTUS_MEMBRANE_PRESETS_H
#define ICTUS_MEMBRANE_PRESETS_H

#include "membrane.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The internal loss factor of the cymbal presets' bronze (decay rate eta w / 2): a
 * choice within the 1e-4 .. 1e-3 that bronze and brass plates show (docs/plates.md). */
#define MEMBRANE_PRESET_BRONZE_LOSS 3.0e-4

/* The largest m whose (m, 1) ratio a preset may give, plus one. */
#define MEMBRANE_PRESET_RATIOS 8

typedef struct membrane_preset {
    const char *name; /* the one name: membrane~ "preset NAME", ictusd --drum-preset NAME */
    const char *what; /* the instrument, in a few words */
    double radius_m, tension_n_per_m, density_kg_per_m2;
    double t60_s;              /* T60 of the lowest mode before any tuning (membrane.h) */
    double hf_damping;         /* membrane.h's high-frequency damping control */
    int modes;                 /* mode count; 0: the membrane's default (MEMBRANE_DEFAULT_MODES) */
    double strike_r_over_a;    /* where the force inlet strikes (theta 0) */
    double pickup_r_over_a[2]; /* pickups 1 and 2 */
    double pickup_theta_deg[2];
    /* Air loading: measured frequency ratios of the (m, 1) modes to (1, 1), for
     * m = 1 .. ratio_count - 1 (ratio_m1[0] unused); ratio_count 0: an ideal membrane.
     * The highest given mode keeps its ideal frequency, the others move to the ratios. */
    int ratio_count;
    double ratio_m1[MEMBRANE_PRESET_RATIOS];
    double decay_01; /* (0, 1) decays this many times faster (1: as the damping law) */
    int wires;       /* snare wires on the head (snare_wires.h; the Pd wrapper lays them) */
    int linear;      /* 1: no tension modulation, radiation or internal loss, forces at a
                      * point (the paper's head); 0: membrane.h's defaults for the four */
    /* 1: a cymbal, a free-edge plate of bending stiffness bending_n_m (N m) and the
     * density above (membrane_set_plate; tension unused, the four above off); not a
     * drum for the daemon's physics. 0: a drum. */
    int plate;
    double bending_n_m;
    /* A hi-hat: the closed pair's loss along the top plate's edge (MEMBRANE_PARAM_EDGE_DAMP,
     * N s/m^2); 0 for every other preset. The pedal (openness) is the player's: a preset
     * leaves it as it is. */
    double edge_damp_n_s_per_m2;
    /* The energy cascade (MEMBRANE_PARAM_CASCADE, docs/plates.md "The cascade",
     * docs/membrane.md "The energy cascade"); 0 for paper, snare, floor-tom and kick. */
    double cascade;
    /* The air's mass on the head's modes (MEMBRANE_PARAM_AIR_MASS, docs/membrane.md "The
     * air's mass"); 0 where a row leaves it out. The tension is the one that puts (0, 1)
     * at the frequency `what` names with it. */
    double air_mass;
} membrane_preset;

/* The presets, in the order the docs list them; count via membrane_preset_count(). */
int membrane_preset_count(void);
const membrane_preset *membrane_preset_at(int index);
/* The preset named `name`, in any casing ("Snare", "SNARE"), or NULL. */
const membrane_preset *membrane_preset_find(const char *name);
/* "snare, tom, ...": the names, for error messages; the drums' alone (not the
 * plates), for what takes a drum. */
const char *membrane_preset_names(void);
const char *membrane_preset_drum_names(void);

/* Sets m to preset p: a membrane or a plate, radius, tension (or bending), density,
 * T60, hfdamp, mode count, a hi-hat's edge loss, strike point, pickups and the tuning of
 * its modes; gain and openness are left as they are (the mix and the foot, not the
 * instrument). Allocates when the mode count grows: message time only, never from audio.
 * ICTUS_ENOMEM when the modes could not be had (the other values are set). */
ictus_status membrane_apply_preset(membrane *m, const membrane_preset *p);

#ifdef __cplusplus
}
#endif
#endif
