/* membrane_params.c -- the membrane's one-number parameters (membrane_param) as one
 * table, and the sample rate and mode count, which have setters of their own. */
#include "ictus_param.h"
#include "membrane_internal.h"

#include <math.h>
#include <stddef.h>

/* After a physical parameter changed: the points' pending forces go in, then the
 * coefficients and the couplings follow (the state is rescaled: no click); returns s. */
static ictus_status physics_changed(void *m, ictus_status s)
{
    membrane_flush_points_(m);
    membrane_update_coefficients_(m, 1);
    membrane_refresh_couplings_(m);
    return s;
}

/* After the radius, the density, the air's mass or the contact patch changed: as
 * physics_changed, the shapes following the coefficients (the air's load on each mode
 * scales its shape; a patch is relative to the radius). */
static ictus_status geometry_changed(void *mv, ictus_status s)
{
    membrane *m = mv;
    membrane_flush_points_(m);
    membrane_update_coefficients_(m, 1);
    if (m->table.j)
        membrane_refresh_shapes_(m);
    membrane_refresh_couplings_(m);
    return s;
}

/* After the tension modulation's amount changed: it is read live, but a head's energy
 * cascade rides on it (on only while it is). */
static ictus_status stretch_changed(void *m, ictus_status s)
{
    membrane_band_cascade_refresh_(m);
    return s;
}

ictus_status membrane_set_sample_rate(membrane *m, double sr)
{
    ictus_status s = ictus_clamp(&sr, MEMBRANE_SR_MIN, MEMBRANE_SR_MAX, 48000.0);
    m->sample_rate = sr;
    return physics_changed(m, s);
}

ictus_status membrane_set_modes(membrane *m, int count)
{
    ictus_status s = ICTUS_OK;
    if (count < MEMBRANE_MODES_MIN) {
        count = MEMBRANE_MODES_MIN;
        s = ICTUS_CLAMPED;
    } else if (count > MEMBRANE_MODES_MAX) {
        count = MEMBRANE_MODES_MAX;
        s = ICTUS_CLAMPED;
    }
    if (count == m->modes)
        return s;
    ictus_status b = membrane_build_modes_(m, count);
    return b == ICTUS_ENOMEM ? b : s;
}

/* A number of modes: a fraction within the range rounds to the nearest count; one below
 * it (0.5) is out of range, as 0 is. */
static ictus_status set_modes(void *m, double value)
{
    /* Clamped before the conversion to int, which is undefined out of range. */
    ictus_status s =
        ictus_clamp(&value, MEMBRANE_MODES_MIN, MEMBRANE_MODES_MAX, MEMBRANE_DEFAULT_MODES);
    double count = floor(value + 0.5);
    ictus_status b = membrane_set_modes(m, (int)count);
    return b != ICTUS_OK ? b : s;
}

static double get_modes(const void *m)
{
    return membrane_get_modes(m);
}

/* The mass range is the density range times the area, pi a^2. */
static ictus_range mass_range(const void *obj)
{
    const membrane *m = obj;
    const double a = m->radius;
    ictus_range r;
    r.min = MEMBRANE_DENSITY_MIN * M_PI * a * a;
    r.max = MEMBRANE_DENSITY_MAX * M_PI * a * a;
    r.def = MEMBRANE_DEFAULT_DENSITY * M_PI * a * a;
    return r;
}

static ictus_status set_mass(void *obj, double mass_kg)
{
    membrane *m = obj;
    if (isnan(mass_kg)) {
        ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_DENSITY, MEMBRANE_DEFAULT_DENSITY);
        return ICTUS_CLAMPED;
    }
    /* Clamped as a mass first, so that the density the limits give is the one a
     * caller passing the limit itself would get. */
    ictus_range range = mass_range(m);
    ictus_status s = ictus_clamp(&mass_kg, range.min, range.max, range.def);
    double density = mass_kg / (M_PI * m->radius * m->radius);
    /* A mass in range gives a density in range but for the rounding of the division
     * (the limit's mass / area can land an ulp outside the density's limit): pinned
     * back, with no report; the mass said whether it was clamped. */
    ictus_clamp(&density, MEMBRANE_DENSITY_MIN, MEMBRANE_DENSITY_MAX, MEMBRANE_DEFAULT_DENSITY);
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_DENSITY, density);
    return s;
}

static double get_mass(const void *obj)
{
    const membrane *m = obj;
    return m->density * M_PI * m->radius * m->radius;
}

/* Indexed by membrane_param: name (as the Pd message), unit, range, then the double
 * it is kept in and what follows a change, or the set, get and range of one that is
 * not a field of its own. gain is dimensionless to the user: output = membrane
 * velocity x gain (docs/membrane.md). */
/* clang-format off */
#define RANGE(P) {MEMBRANE_##P##_MIN, MEMBRANE_##P##_MAX, MEMBRANE_DEFAULT_##P}
#define FIELD(f) offsetof(membrane, f)
/* clang-format on */
static const ictus_param_def membrane_param_def[MEMBRANE_PARAM_COUNT] = {
    [MEMBRANE_PARAM_RADIUS] = {"radius", "m", RANGE(RADIUS), FIELD(radius), geometry_changed},
    [MEMBRANE_PARAM_TENSION] = {"tension", "N/m", RANGE(TENSION), FIELD(tension), physics_changed},
    [MEMBRANE_PARAM_DENSITY] = {"density", "kg/m^2", RANGE(DENSITY), FIELD(density),
                                geometry_changed},
    [MEMBRANE_PARAM_MASS] = {"mass", "kg", {0, 0, 0}, 0, NULL, set_mass, get_mass, mass_range},
    [MEMBRANE_PARAM_MODES] = {"modes", "", RANGE(MODES), 0, NULL, set_modes, get_modes, NULL},
    [MEMBRANE_PARAM_T60] = {"t60", "s", RANGE(T60), FIELD(t60), physics_changed},
    [MEMBRANE_PARAM_HF_DAMPING] = {"hfdamp", "", RANGE(HF_DAMPING), FIELD(hf_damping),
                                   physics_changed},
    [MEMBRANE_PARAM_GAIN] = {"gain", "", RANGE(GAIN), FIELD(output_gain), NULL},
    /* Takes effect at the next tension update (TM_INTERVAL samples at most). */
    [MEMBRANE_PARAM_TENSION_MOD] = {"tensionmod", "", RANGE(TENSION_MOD), FIELD(tension_mod),
                                    stretch_changed},
    [MEMBRANE_PARAM_RADIATION] = {"radiation", "", RANGE(RADIATION), FIELD(radiation),
                                  physics_changed},
    [MEMBRANE_PARAM_LOSS_FACTOR] = {"lossfactor", "", RANGE(LOSS_FACTOR), FIELD(loss_factor),
                                    physics_changed},
    [MEMBRANE_PARAM_PATCH] = {"patch", "m", RANGE(PATCH), FIELD(patch), geometry_changed},
    [MEMBRANE_PARAM_BENDING] = {"bending", "N m", RANGE(BENDING), FIELD(bending), physics_changed},
    [MEMBRANE_PARAM_CASCADE] = {"cascade", "", RANGE(CASCADE), FIELD(cascade), physics_changed},
    [MEMBRANE_PARAM_OPENNESS] = {"openness", "", RANGE(OPENNESS), FIELD(openness), physics_changed},
    [MEMBRANE_PARAM_EDGE_DAMP] = {"edgedamp", "N s/m^2", RANGE(EDGE_DAMP), FIELD(edge_damp),
                                  physics_changed},
    [MEMBRANE_PARAM_VON_KARMAN] = {"vonkarman", "", RANGE(VON_KARMAN), FIELD(von_karman),
                                   physics_changed},
    [MEMBRANE_PARAM_AIR_MASS] = {"airmass", "", RANGE(AIR_MASS), FIELD(air_mass), geometry_changed},
};
#undef RANGE
#undef FIELD

const ictus_param_table membrane_params = {membrane_param_def, MEMBRANE_PARAM_COUNT};
