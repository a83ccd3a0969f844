/* membrane~ -- a circular drum head (modal membrane, externals/core/membrane.h).
 *
 * [membrane~ NAME radius tension density modes]: NAME lets contact~ objects find
 * it (as delread~ finds delwrite~); the numbers are optional.
 * Inlet: force (N) applied at the strike point ("position"); messages below.
 * Outlets: pickup 1 and pickup 2 (membrane velocity scaled by "gain", see
 * docs/membrane.md).
 *
 * Timing: a "strike" (and a contact~ "hit") lands on the sample its logical time
 * names, for any block size, by the sample clock of ictus_pd_common.c.
 * Attached contacts: the contact~ objects that play this membrane~ attach their core
 * contacts to its core through ictus_membrane_tilde_attach(); this file does not know
 * contact~ itself, it calls back whoever attached when it is deleted.
 */
#include <string.h>

#include "ictus_pd.h"
#include "ictus_name.h"
#include "membrane_presets.h"
#include "snare_wires.h"
#include "m_imp.h" /* obj_starttraverseoutlet: is the second outlet connected? */

#if PD_FLOATSIZE != 32
#error "ictus: the DSP core works on 32-bit float signals; build against a 32-bit Pd"
#endif

/* 10 N s is four times a 0.05 kg stick at the core's 50 m/s limit: the object takes
 * less than the core (MEMBRANE_IMPULSE_MAX), and no pulling. */
#define ICTUS_STRIKE_IMPULSE_MAX 10.0 /* N s */

/* A contact attached on behalf of an object that plays this membrane~. */
typedef struct _membrane_tilde_attached {
    contact *a_core;
    void *a_owner; /* NULL: a free slot */
    t_ictus_gonefn a_gone;
} t_membrane_tilde_attached;

struct _membrane_tilde {
    t_object x_obj;
    t_float x_f; /* force (N) when the inlet gets a float */
    membrane *x_core;
    t_symbol *x_name; /* bound name for contact~, or &s_ */
    t_ictus_clock x_clock;
    t_membrane_tilde_attached x_attached[MEMBRANE_MAX_CONTACTS];
    int x_silent;         /* every mode above Nyquist: said once, when it became so */
    snare_wires *x_wires; /* NULL: no wires on the head */
};

t_class *ictus_membrane_tilde_class;

/* ---------------- parameters ---------------- */

/* gain is dimensionless to the user: output = membrane velocity x gain (docs/membrane.md). */
static const t_ictus_params membrane_tilde_params = {"membrane~", &membrane_params};

/* The creation arguments after NAME, in order. */
static const membrane_param membrane_tilde_args[] = {MEMBRANE_PARAM_RADIUS, MEMBRANE_PARAM_TENSION,
                                                     MEMBRANE_PARAM_DENSITY, MEMBRANE_PARAM_MODES};
#define NARGS (int)(sizeof(membrane_tilde_args) / sizeof(membrane_tilde_args[0]))

/* A head whose lowest mode lies above the core's cutoff (0.95 x Nyquist) makes no
 * sound at all: a tiny radius, a huge tension (a plate's bending) or a low sample
 * rate. Said once when a parameter or the sample rate takes it there, not again
 * until it has sounded. A plate's modes do not depend on the tension. */
static void membrane_tilde_check_silent(t_membrane_tilde *x)
{
    int silent = membrane_get_sounding_modes(x->x_core) == 0;
    if (silent && !x->x_silent) {
        double sr = membrane_get_sample_rate(x->x_core), lowest = 0;
        membrane_get_mode(x->x_core, 0, &lowest, 0, 0, 0, 0);
        pd_error(x,
                 "membrane~%s%s: all %d modes lie above Nyquist (lowest %g Hz, modes ring "
                 "below %g Hz at sr %g Hz): silent; lower the %s, raise the density or "
                 "enlarge the radius",
                 x->x_name != &s_ ? " " : "", x->x_name != &s_ ? x->x_name->s_name : "",
                 membrane_get_modes(x->x_core), lowest, 0.95 * 0.5 * sr, sr,
                 membrane_is_plate(x->x_core) ? "bending" : "tension");
    }
    x->x_silent = silent;
}

/* radius, tension, density, mass, modes, t60, hfdamp, gain, tensionmod: one number each. */
static void membrane_tilde_setparam(t_membrane_tilde *x, t_symbol *s, int argc, t_atom *argv)
{
    ictus_params_message(x, &membrane_tilde_params, x->x_core, s, argc, argv);
    membrane_tilde_check_silent(x);
}

/* Puts the snare side (snare head, air, wires: snare_wires.h) under the head, wires on
 * or off (present), or takes it away (!present); 1 when done. */
static int membrane_tilde_set_snare(t_membrane_tilde *x, int present, int on)
{
    const char *sep = x->x_name != &s_ ? " " : "",
               *name = x->x_name != &s_ ? x->x_name->s_name : "";
    if (!present) {
        snare_wires_free(x->x_wires);
        x->x_wires = 0;
        return 1;
    }
    if (!x->x_wires) {
        x->x_wires = snare_wires_new();
        if (!x->x_wires || snare_wires_attach(x->x_wires, x->x_core) != ICTUS_OK) {
            pd_error(x,
                     "membrane~%s%s: wires: no room for the snare's %d coupling point (at most "
                     "%d with the sticks) or out of memory: no snare",
                     sep, name, SNARE_POINTS, MEMBRANE_MAX_POINTS);
            snare_wires_free(x->x_wires);
            x->x_wires = 0;
            return 0;
        }
    }
    snare_wires_engage(x->x_wires, on);
    return 1;
}

/* wires on lays the snare side under the head if it is not there; off lifts the wires
 * (the snare head and the air stay). */
static int membrane_tilde_set_wires(t_membrane_tilde *x, int on)
{
    if (!on && !x->x_wires)
        return 1;
    if (on && membrane_is_plate(x->x_core)) {
        pd_error(x, "membrane~%s%s: wires: a cymbal (a plate) has no snare wires; ignored",
                 x->x_name != &s_ ? " " : "", x->x_name != &s_ ? x->x_name->s_name : "");
        return 0;
    }
    return membrane_tilde_set_snare(x, 1, on);
}

/* wires on|off (or 1|0): the snare wires, colliding with the head (snare_wires.h). */
static void membrane_tilde_wires(t_membrane_tilde *x, t_symbol *s, int argc, t_atom *argv)
{
    (void)s;
    /* on and off in any casing, as the presets' names */
    if (argc == 1 && argv[0].a_type == A_SYMBOL &&
        (ictus_name_equal(argv[0].a_w.w_symbol->s_name, "on") ||
         ictus_name_equal(argv[0].a_w.w_symbol->s_name, "off")))
        membrane_tilde_set_wires(x, ictus_name_equal(argv[0].a_w.w_symbol->s_name, "on"));
    else if (argc == 1 && argv[0].a_type == A_FLOAT &&
             (argv[0].a_w.w_float == 0 || argv[0].a_w.w_float == 1))
        membrane_tilde_set_wires(x, argv[0].a_w.w_float == 1);
    else
        pd_error(x, "membrane~%s%s: wires: expected on or off (1 or 0)",
                 x->x_name != &s_ ? " " : "", x->x_name != &s_ ? x->x_name->s_name : "");
}

/* preset NAME: a drum modelled on a measured instrument (membrane_presets.h). */
static void membrane_tilde_preset(t_membrane_tilde *x, t_symbol *s, int argc, t_atom *argv)
{
    const char *sep = x->x_name != &s_ ? " " : "",
               *name = x->x_name != &s_ ? x->x_name->s_name : "";
    const membrane_preset *p;
    (void)s;
    if (argc < 1 || argv[0].a_type != A_SYMBOL) {
        pd_error(x, "membrane~%s%s: preset: expected a name (%s)", sep, name,
                 membrane_preset_names());
        return;
    }
    p = membrane_preset_find(atom_getsymbol(&argv[0])->s_name);
    if (!p) {
        pd_error(x, "membrane~%s%s: preset: unknown '%s'; the presets are %s", sep, name,
                 atom_getsymbol(&argv[0])->s_name, membrane_preset_names());
        return;
    }
    if (argc > 1)
        pd_error(x, "membrane~%s%s: preset takes one name; extra arguments ignored", sep, name);
    membrane_tilde_set_snare(x, 0, 0); /* the snare follows the new head */
    if (membrane_apply_preset(x->x_core, p) == ICTUS_ENOMEM)
        pd_error(x, "membrane~%s%s: preset %s: out of memory for %d modes; kept %d", sep, name,
                 p->name, p->modes, membrane_get_modes(x->x_core));
    if (p->wires)
        membrane_tilde_set_snare(x, 1, 1);
    membrane_tilde_check_silent(x);
}

/* pickup <1|2> <r/a> <theta deg> */
static void membrane_tilde_pickup(t_membrane_tilde *x, t_symbol *s, int argc, t_atom *argv)
{
    double index, r, theta;
    (void)s;
    if (!ictus_getnumber(x, "membrane~", "pickup", "index (1 or 2)", argc, argv, 0, &index))
        return;
    if (index != 1 && index != 2) {
        pd_error(x, "membrane~: pickup: index must be 1 or 2, got %g", index);
        return;
    }
    if (!ictus_getpoint(x, "membrane~", "pickup", argc, argv, 1, &r, &theta))
        return;
    if (argc > 3)
        pd_error(x, "membrane~: pickup takes three numbers (index, r/a, theta); extra arguments "
                    "ignored");
    membrane_set_pickup(x->x_core, (int)index - 1, r, theta);
}

/* position <r/a> <theta deg>: where the signal inlet's force is applied. */
static void membrane_tilde_position(t_membrane_tilde *x, t_symbol *s, int argc, t_atom *argv)
{
    double r, theta;
    (void)s;
    if (!ictus_getpoint(x, "membrane~", "position", argc, argv, 0, &r, &theta))
        return;
    if (argc > 2)
        pd_error(x, "membrane~: position takes two numbers (r/a, theta); extra arguments ignored");
    membrane_set_strike_point(x->x_core, r, theta);
}

/* strike <r/a> <theta deg> <impulse N s>, at this message's logical time. */
static void membrane_tilde_strike(t_membrane_tilde *x, t_symbol *s, int argc, t_atom *argv)
{
    double r, theta, impulse;
    (void)s;
    if (!ictus_getpoint(x, "membrane~", "strike", argc, argv, 0, &r, &theta) ||
        !ictus_getnumber(x, "membrane~", "strike", "impulse (N s)", argc, argv, 2, &impulse))
        return;
    if (argc > 3)
        pd_error(x, "membrane~: strike takes three numbers (r/a, theta, impulse); extra arguments "
                    "ignored");
    if (impulse < 0 || impulse > ICTUS_STRIKE_IMPULSE_MAX) {
        double used = impulse < 0 ? 0 : ICTUS_STRIKE_IMPULSE_MAX;
        pd_error(x, "membrane~: strike: impulse must be in [0, %g] N s, got %g; using %g",
                 ICTUS_STRIKE_IMPULSE_MAX, impulse, used);
        impulse = used;
    }
    long dropped = membrane_dropped_strikes(x->x_core);
    membrane_strike(x->x_core, r, theta, impulse, ictus_clock_offset_now(&x->x_clock));
    if (membrane_dropped_strikes(x->x_core) != dropped)
        pd_error(x,
                 "membrane~%s%s: strike: more strikes wait for this block than it has samples "
                 "(twice over); dropped",
                 x->x_name != &s_ ? " " : "", x->x_name != &s_ ? x->x_name->s_name : "");
}

static void membrane_tilde_clear(t_membrane_tilde *x)
{
    membrane_clear(x->x_core);
}

/* print: the physics and the first modes, in the Pd window. */
static void membrane_tilde_print(t_membrane_tilde *x)
{
    const membrane *core = x->x_core;
    int k, count = membrane_get_modes(core);
    post("membrane~ %s: radius %g m, tension %g N/m, density %g kg/m^2 (mass %g kg), "
         "%d modes, t60 %g s, hfdamp %g, gain %g, tensionmod %g, sr %g Hz",
         x->x_name != &s_ ? x->x_name->s_name : "(no name)",
         ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_RADIUS),
         ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_TENSION),
         ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_DENSITY),
         ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_MASS), count,
         ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_T60),
         ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_HF_DAMPING),
         ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_GAIN),
         ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_TENSION_MOD),
         membrane_get_sample_rate(core));
    if (membrane_is_plate(core))
        post("membrane~ %s: a free-edge plate, bending %g N m, cascade %g, vonkarman %g, "
             "openness %g, edgedamp %g N s/m^2",
             x->x_name != &s_ ? x->x_name->s_name : "(no name)",
             ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_BENDING),
             ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_CASCADE),
             ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_VON_KARMAN),
             ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_OPENNESS),
             ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_EDGE_DAMP));
    else if (ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_CASCADE) > 0.0 &&
             ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_TENSION_MOD) > 0.0)
        post("membrane~ %s: energy cascade %g (docs/membrane.md)",
             x->x_name != &s_ ? x->x_name->s_name : "(no name)",
             ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_CASCADE));
    if (!membrane_is_plate(core) &&
        ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_AIR_MASS) > 0.0)
        post("membrane~ %s: airmass %g (the air's mass on the modes, docs/membrane.md)",
             x->x_name != &s_ ? x->x_name->s_name : "(no name)",
             ictus_param_get(&membrane_params, core, MEMBRANE_PARAM_AIR_MASS));
    if (x->x_wires)
        post("membrane~ %s: snare head %d modes, wires %s",
             x->x_name != &s_ ? x->x_name->s_name : "(no name)", snare_wires_head_modes(x->x_wires),
             snare_wires_engaged(x->x_wires) ? "on" : "off");
    for (k = 0; k < count && k < 12; k++) {
        double f, t60;
        int bm, bn, sinp;
        if (membrane_get_mode(x->x_core, k, &f, &t60, &bm, &bn, &sinp))
            post("  mode %2d (%d,%d)%s: %9.2f Hz  T60 %.3f s", k, bm, bn,
                 bm ? (sinp ? " sin" : " cos") : "    ", f, t60);
    }
}

/* ---------------- attached contacts ---------------- */

int ictus_membrane_tilde_attach(t_membrane_tilde *m, contact *c, void *owner, t_ictus_gonefn gone)
{
    int i, free_slot = -1;
    for (i = 0; i < MEMBRANE_MAX_CONTACTS; i++) {
        if (m->x_attached[i].a_owner == owner)
            return 1;
        if (!m->x_attached[i].a_owner && free_slot < 0)
            free_slot = i;
    }
    if (free_slot < 0 || membrane_attach_contact(m->x_core, c) != ICTUS_OK)
        return 0;
    m->x_attached[free_slot].a_core = c;
    m->x_attached[free_slot].a_owner = owner;
    m->x_attached[free_slot].a_gone = gone;
    return 1;
}

int ictus_membrane_tilde_contacts(const t_membrane_tilde *m)
{
    int i, count = 0;
    for (i = 0; i < MEMBRANE_MAX_CONTACTS; i++)
        count += m->x_attached[i].a_owner != 0;
    return count;
}

void ictus_membrane_tilde_detach(t_membrane_tilde *m, void *owner)
{
    int i;
    for (i = 0; i < MEMBRANE_MAX_CONTACTS; i++)
        if (owner && m->x_attached[i].a_owner == owner) {
            membrane_detach_contact(m->x_core, m->x_attached[i].a_core);
            m->x_attached[i].a_core = 0;
            m->x_attached[i].a_owner = 0;
            m->x_attached[i].a_gone = 0;
        }
}

const t_ictus_clock *ictus_membrane_tilde_clock(const t_membrane_tilde *m)
{
    return &m->x_clock;
}

/* ---------------- DSP ---------------- */

static t_int *membrane_tilde_perform(t_int *w)
{
    t_membrane_tilde *x = (t_membrane_tilde *)(w[1]);
    t_sample *force_in = (t_sample *)(w[2]);
    t_sample *out[MEMBRANE_PICKUPS];
    int n = (int)(w[5]);
    out[0] = (t_sample *)(w[3]);
    out[1] = (t_sample *)(w[4]); /* NULL: nothing connected, pickup 2 not computed */
    ictus_clock_block_begin(&x->x_clock, n);
    membrane_process(x->x_core, force_in, out, n);
    ictus_clock_block_end(&x->x_clock, n);
    return (w + 6);
}

static void membrane_tilde_dsp(t_membrane_tilde *x, t_signal **sp)
{
    double sr = sp[0]->s_sr;
    if (membrane_set_sample_rate(x->x_core, sr) != ICTUS_OK)
        pd_error(x, "membrane~: sample rate %g Hz is outside [%g, %g]; using %g", sr,
                 MEMBRANE_SR_MIN, MEMBRANE_SR_MAX, membrane_get_sample_rate(x->x_core));
    ictus_clock_dsp(&x->x_clock, membrane_get_sample_rate(x->x_core));
    /* Strikes wait for the block that holds their sample: room for one on every sample
     * of the window a block covers (max(n, one tick)), and as many again. */
    int window = sp[0]->s_n > sys_getblksize() ? sp[0]->s_n : sys_getblksize();
    if (membrane_reserve_strikes(x->x_core, 2 * window) != ICTUS_OK)
        pd_error(x, "membrane~: out of memory for %d pending strikes; a block holds fewer",
                 2 * window);
    membrane_tilde_check_silent(x);
    /* Pd rebuilds the DSP chain whenever a connection changes, so asking here is
     * enough. An unconnected signal outlet's buffer is read by nobody. */
    t_outlet *second;
    int second_used = obj_starttraverseoutlet(&x->x_obj, &second, 1) != NULL;
    dsp_add(membrane_tilde_perform, 5, x, sp[0]->s_vec, sp[1]->s_vec,
            second_used ? sp[2]->s_vec : NULL, (t_int)sp[0]->s_n);
}

/* ---------------- life cycle ---------------- */

static void *membrane_tilde_new(t_symbol *s, int argc, t_atom *argv)
{
    membrane *core = membrane_new(sys_getsr() > 0 ? sys_getsr() : 44100);
    t_membrane_tilde *x = ictus_core_object_new(ictus_membrane_tilde_class, "membrane~", core);
    int first = 0, i;
    (void)s;
    if (!x)
        return 0;
    x->x_core = core;
    x->x_f = 0;
    x->x_name = &s_;
    memset(&x->x_clock, 0, sizeof(x->x_clock));
    memset(x->x_attached, 0, sizeof(x->x_attached));
    x->x_wires = 0;
    if (argc > 0 && argv[0].a_type == A_SYMBOL) {
        x->x_name = atom_getsymbol(&argv[0]);
        pd_bind(&x->x_obj.ob_pd, x->x_name);
        first = 1;
    }
    /* optional: radius tension density modes */
    for (i = first; i < argc && i - first < NARGS; i++) {
        double value;
        int id = membrane_tilde_args[i - first];
        if (ictus_getnumber(x, "membrane~", "creation argument", membrane_params.def[id].name, argc,
                            argv, i, &value))
            ictus_params_set(x, &membrane_tilde_params, x->x_core, id, value);
    }
    if (argc - first > NARGS)
        pd_error(x, "membrane~: arguments are NAME radius tension density modes; "
                    "extra arguments ignored");
    x->x_silent = 0;
    membrane_tilde_check_silent(x);
    outlet_new(&x->x_obj, &s_signal);
    outlet_new(&x->x_obj, &s_signal);
    return x;
}

static void membrane_tilde_free(t_membrane_tilde *x)
{
    int i;
    /* The objects that attached keep a pointer to us: detach them all, then tell
     * them, so that none dangles. */
    for (i = 0; i < MEMBRANE_MAX_CONTACTS; i++)
        if (x->x_attached[i].a_owner) {
            void *owner = x->x_attached[i].a_owner;
            t_ictus_gonefn gone = x->x_attached[i].a_gone;
            ictus_membrane_tilde_detach(x, owner);
            gone(owner);
        }
    if (x->x_name != &s_)
        pd_unbind(&x->x_obj.ob_pd, x->x_name);
    snare_wires_free(x->x_wires);
    membrane_free(x->x_core);
}

void ictus_membrane_tilde_setup(void)
{
    ictus_membrane_tilde_class = class_new(gensym("membrane~"), (t_newmethod)membrane_tilde_new,
                                           (t_method)membrane_tilde_free, sizeof(t_membrane_tilde),
                                           CLASS_DEFAULT, A_GIMME, 0);
    CLASS_MAINSIGNALIN(ictus_membrane_tilde_class, t_membrane_tilde, x_f);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_dsp, gensym("dsp"), A_CANT,
                    0);
    ictus_params_addmethods(ictus_membrane_tilde_class, &membrane_tilde_params,
                            (t_method)membrane_tilde_setparam);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_preset, gensym("preset"),
                    A_GIMME, 0);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_wires, gensym("wires"),
                    A_GIMME, 0);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_pickup, gensym("pickup"),
                    A_GIMME, 0);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_position,
                    gensym("position"), A_GIMME, 0);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_strike, gensym("strike"),
                    A_GIMME, 0);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_clear, gensym("clear"), 0);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_print, gensym("print"), 0);
}
