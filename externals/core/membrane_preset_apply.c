/* membrane_preset_apply.c -- sets a membrane to a preset (membrane_presets.h) through
 * the parameter table and the mode table's tuning. */
#include "membrane_internal.h"
#include "membrane_presets.h"

/* The (m, 1) frequency factors of an air-loaded head from the measured ratios: the
 * highest given mode M keeps its ideal frequency, so (1, 1) rings at
 * f_M1 / R_M and (m, 1) at R_m times that:
 *     factor_m = R_m (j_M1 / R_M) / j_m1;   (0, 1) keeps factor 1. */
static void tuning_of(const membrane_preset *p, mode_tuning *u)
{
    u->count = p->ratio_count;
    u->decay_01 = p->decay_01 >= 1.0 ? p->decay_01 : 1.0;
    if (u->count <= 1) {
        u->count = 0;
        if (u->decay_01 > 1.0) { /* only the (0, 1) damping */
            u->count = 1;
            u->factor_m1[0] = 1.0;
        }
        return;
    }
    const int top = u->count - 1;
    const double f11 = ictus_bessel_zero(top, 1) / p->ratio_m1[top];
    u->factor_m1[0] = 1.0;
    for (int mm = 1; mm < u->count; mm++)
        u->factor_m1[mm] = p->ratio_m1[mm] * f11 / ictus_bessel_zero(mm, 1);
}

ictus_status membrane_apply_preset(membrane *m, const membrane_preset *p)
{
    ictus_status s = ICTUS_OK, e;
    const ictus_param_table *t = &membrane_params;
    mode_tuning u = {0};
    tuning_of(p, &u);
    membrane_flush_points_(m);
    if ((e = membrane_set_plate(m, p->plate)) > s)
        s = e;
    m->tuning = u; /* the coefficients follow with the first parameter set below */
    const int bare = p->linear || p->plate; /* a plate: the four are a membrane's */
    const struct {
        int id;
        double value;
    } sets[] = {
        {MEMBRANE_PARAM_RADIUS, p->radius_m},
        {p->plate ? MEMBRANE_PARAM_BENDING : MEMBRANE_PARAM_TENSION,
         p->plate ? p->bending_n_m : p->tension_n_per_m},
        {MEMBRANE_PARAM_DENSITY, p->density_kg_per_m2},
        {MEMBRANE_PARAM_T60, p->t60_s},
        {MEMBRANE_PARAM_HF_DAMPING, p->hf_damping},
        {MEMBRANE_PARAM_MODES, p->modes > 0 ? p->modes : MEMBRANE_DEFAULT_MODES},
        {MEMBRANE_PARAM_TENSION_MOD, bare ? 0.0 : MEMBRANE_DEFAULT_TENSION_MOD},
        {MEMBRANE_PARAM_RADIATION, bare ? 0.0 : MEMBRANE_DEFAULT_RADIATION},
        {MEMBRANE_PARAM_AIR_MASS, bare ? 0.0 : p->air_mass},
        {MEMBRANE_PARAM_LOSS_FACTOR, p->plate ? MEMBRANE_PRESET_BRONZE_LOSS
                                     : bare   ? 0.0
                                              : MEMBRANE_DEFAULT_LOSS_FACTOR},
        {MEMBRANE_PARAM_PATCH, bare ? 0.0 : MEMBRANE_PATCH_BEAD},
        {MEMBRANE_PARAM_CASCADE, p->cascade},
        {MEMBRANE_PARAM_VON_KARMAN, 0.0}, /* off: it darkens the crash (docs/plates.md) */
        {MEMBRANE_PARAM_EDGE_DAMP, p->edge_damp_n_s_per_m2},
    };
    for (int i = 0; i < (int)(sizeof(sets) / sizeof(sets[0])); i++)
        if ((e = ictus_param_set(t, m, sets[i].id, sets[i].value)) > s)
            s = e;
    if ((e = membrane_set_strike_point(m, p->strike_r_over_a, 0.0)) > s)
        s = e;
    for (int i = 0; i < MEMBRANE_PICKUPS && i < 2; i++)
        if ((e = membrane_set_pickup(m, i, p->pickup_r_over_a[i], p->pickup_theta_deg[i])) > s)
            s = e;
    return s;
}
