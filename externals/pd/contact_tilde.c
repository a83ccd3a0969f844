/* contact~ -- a stick that hits a membrane~ (Hunt-Crossley contact,
 * externals/core/contact.h), solved jointly with the membrane's modes.
 *
 * [contact~ NAME [TIP]] plays the membrane~ named NAME with the stick tip TIP
 * (stick_tip.h: wood, nylon, felt; message "tip NAME"; without
 * TIP, contact.h's defaults). It finds it in its dsp
 * method with pd_findbyclass(), as delread~ finds delwrite~, and attaches its
 * core contact to the membrane's core. The membrane's perform computes the
 * stroke and writes the contact force into a buffer owned here; contact~'s
 * perform copies it to the signal outlet. If Pd happens to sort contact~ before
 * membrane~, the force outlet lags one block; the sound (membrane~'s outlets)
 * is exact either way, since the contact is solved inside membrane~'s perform.
 *
 * Outlets: contact force (N, signal); on release, a list
 * duration_ms peak_force_N rebound_velocity_mps (from a clock, never from perform).
 */
#include <string.h>

#include "ictus_pd.h"
#include "stick_tip.h"

typedef struct _contact_tilde {
    t_object x_obj;
    t_float x_f;
    contact *x_core;
    t_symbol *x_name;             /* the membrane~ to play */
    t_membrane_tilde *x_membrane; /* attached membrane~, or NULL (cleared when it goes) */
    int x_refused;  /* the last DSP sort found its membrane~ full: hits are refused (1: four
                       contact~s, 2: fewer, its snare side takes the point left) */
    float *x_force; /* force buffer the membrane's perform writes */
    int x_force_size;
    t_outlet *x_report_out;
    t_clock *x_report_clock;
    /* Finished strokes taken in perform, output from the clock (a long block may end
     * several) */
    contact_report x_reports[CONTACT_REPORT_QUEUE];
    int x_reports_ready;
} t_contact_tilde;

t_class *ictus_contact_tilde_class;

/* ---------------- parameters ---------------- */

static const t_ictus_params contact_tilde_params = {"contact~", &contact_params};

/* mass, stiffness, alpha, damping: one number each. */
static void contact_tilde_setparam(t_contact_tilde *x, t_symbol *s, int argc, t_atom *argv)
{
    ictus_params_message(x, &contact_tilde_params, x->x_core, s, argc, argv);
}

/* The names of the stick tips, "wood, nylon, felt", into known. */
static void contact_tilde_tip_names(char *known, size_t size)
{
    int i;
    known[0] = '\0';
    for (i = 0; i < STICK_TIP_COUNT; i++) {
        strncat(known, i ? ", " : "", size - strlen(known) - 1);
        strncat(known, stick_tips[i].name, size - strlen(known) - 1);
    }
}

/* tip NAME: alpha, stiffness and damping from the table of stick tips (stick_tip.h). */
static void contact_tilde_set_tip(t_contact_tilde *x, t_symbol *name)
{
    char known[64];
    if (contact_set_tip(x->x_core, name->s_name) == ICTUS_OK)
        return;
    contact_tilde_tip_names(known, sizeof(known));
    pd_error(x, "contact~: tip: no stick tip named '%s' (%s); the tip is unchanged", name->s_name,
             known);
}

/* The "tip" message: one name; anything else is refused, the tip unchanged. */
static void contact_tilde_tip(t_contact_tilde *x, t_symbol *s, int argc, t_atom *argv)
{
    char known[64], got[MAXPDSTRING];
    (void)s;
    if (argc < 1 || argv[0].a_type != A_SYMBOL) {
        contact_tilde_tip_names(known, sizeof(known));
        if (argc < 1)
            pd_error(x, "contact~: tip: missing the name of a stick tip (%s); the tip is unchanged",
                     known);
        else {
            atom_string(&argv[0], got, sizeof(got));
            pd_error(x,
                     "contact~: tip: expected the name of a stick tip (%s), got '%s'; the tip is "
                     "unchanged",
                     known, got);
        }
        return;
    }
    if (argc > 1)
        pd_error(x, "contact~: tip takes one name; extra arguments ignored");
    contact_tilde_set_tip(x, atom_getsymbol(&argv[0]));
}

/* The membrane~ whose sample clock times our messages: the attached one, else
 * the one the name finds now (before DSP has attached us), else none. */
static t_membrane_tilde *contact_tilde_timing_membrane(t_contact_tilde *x)
{
    if (x->x_membrane)
        return x->x_membrane;
    if (x->x_name == &s_)
        return 0;
    return (t_membrane_tilde *)pd_findbyclass(x->x_name, ictus_membrane_tilde_class);
}

/* hit <velocity m/s> <r/a> <theta deg>: the stick reaches the surface at this
 * message's logical time, to the sample. */
static void contact_tilde_hit(t_contact_tilde *x, t_symbol *s, int argc, t_atom *argv)
{
    double velocity, r, theta, mass = 0.0;
    t_membrane_tilde *m;
    (void)s;
    if (!ictus_getnumber(x, "contact~", "hit", "velocity (m/s)", argc, argv, 0, &velocity) ||
        !ictus_getpoint(x, "contact~", "hit", argc, argv, 1, &r, &theta))
        return;
    /* The core takes 0 (a stick at rest on the head); a hit from Pd must move. */
    if (!(velocity > 0) || velocity > CONTACT_VELOCITY_MAX) {
        double used = velocity > 0 ? CONTACT_VELOCITY_MAX : 0.001;
        pd_error(x, "contact~: hit: velocity must be in (0, %g] m/s, got %g; using %g",
                 CONTACT_VELOCITY_MAX, velocity, used);
        velocity = used;
    }
    /* An optional stick mass (kg) for this stroke, set on the hit's sample: a
     * "mass" message would change the stroke still under way from the start of
     * the block. 0 keeps the mass. */
    if (argc > 3) {
        if (!ictus_getnumber(x, "contact~", "hit", "stick mass (kg)", argc, argv, 3, &mass))
            mass = 0.0;
        else if (mass < 0.0 || (mass > 0.0 && (mass < (t_float)CONTACT_MASS_MIN ||
                                               mass > (t_float)CONTACT_MASS_MAX))) {
            double used = mass < CONTACT_MASS_MIN ? CONTACT_MASS_MIN : CONTACT_MASS_MAX;
            if (mass < 0.0) {
                pd_error(x,
                         "contact~: hit: stick mass must be >= 0 kg (0: unchanged), got %g; "
                         "the stick keeps its mass",
                         mass);
                mass = 0.0;
            } else {
                pd_error(x, "contact~: hit: stick mass must be in [%g, %g] kg, got %g; using %g",
                         CONTACT_MASS_MIN, CONTACT_MASS_MAX, mass, used);
                mass = used;
            }
        } else if (mass > 0.0) {
            /* Pd's numbers are floats: a bound typed in a message (0.0001) arrives a
             * rounding away from it, and is the bound. */
            mass = mass < CONTACT_MASS_MIN ? CONTACT_MASS_MIN
                                           : (mass > CONTACT_MASS_MAX ? CONTACT_MASS_MAX : mass);
        }
    }
    if (argc > 4)
        pd_error(x, "contact~: hit takes at most four numbers (velocity, r/a, theta, stick mass); "
                    "extra arguments ignored");
    /* A contact~ created while DSP runs with nothing on its signal outlet has not been
     * through a DSP sort (Pd sorts again for a new object only when a signal connection is
     * made): it is not attached, and the hit would go to a stick nobody solves, in silence.
     * Ask for the sort now (message time, as "set" does); its dsp method attaches it, or
     * finds the membrane~ full. The membrane~'s clock re-anchors: this hit starts on the
     * next block's first sample. */
    if (!x->x_membrane && !x->x_refused && pd_getdspstate() && contact_tilde_timing_membrane(x))
        canvas_update_dsp();
    if (x->x_refused == 2 && !x->x_membrane) {
        pd_error(x,
                 "contact~: hit: membrane~ '%s' has no free coupling point (its snare side "
                 "takes one of the %d); this one is silent: ignored",
                 x->x_name->s_name, MEMBRANE_MAX_POINTS);
        return;
    }
    if (x->x_refused && !x->x_membrane) {
        pd_error(x,
                 "contact~: hit: membrane~ '%s' already has %d contact~s; this one is silent: "
                 "ignored",
                 x->x_name->s_name, MEMBRANE_MAX_CONTACTS);
        return;
    }
    m = contact_tilde_timing_membrane(x);
    if (!m) {
        /* a stroke kept for a membrane~ that may come later would start at a random time */
        pd_error(x, "contact~: hit: no membrane~ named '%s'; ignored", x->x_name->s_name);
        return;
    }
    if (contact_hit_mass(x->x_core, velocity, r, theta,
                         ictus_clock_offset_now(ictus_membrane_tilde_clock(m)),
                         mass) == ICTUS_ENOMEM)
        pd_error(x, "contact~: hit: %d hits already wait for their samples; ignored",
                 contact_hits_waiting(x->x_core));
}

/* set NAME: play another membrane~ (takes effect at the next DSP sort, as delread~).
 * Anything but a name is refused: the contact~ plays what it played. */
static void contact_tilde_set(t_contact_tilde *x, t_symbol *s, int argc, t_atom *argv)
{
    (void)s;
    if (argc < 1 || (argv[0].a_type == A_SYMBOL && atom_getsymbol(&argv[0]) == &s_)) {
        pd_error(x, "contact~: set: needs the name of a membrane~");
        return;
    }
    if (argv[0].a_type != A_SYMBOL) {
        char got[MAXPDSTRING];
        atom_string(&argv[0], got, sizeof(got));
        pd_error(x, "contact~: set: needs the name of a membrane~, got '%s'; ignored", got);
        return;
    }
    if (argc > 1)
        pd_error(x, "contact~: set takes one name; extra arguments ignored");
    x->x_name = atom_getsymbol(&argv[0]);
    x->x_refused = 0; /* the next DSP sort says whether the new membrane~ has room */
    canvas_update_dsp();
}

/* The membrane~ went away (it detached our contact first): forget it, and drop a
 * stroke in progress (a membrane~ created later must not be hit by it) by swapping
 * in a fresh core contact with the same parameters. Called from membrane~'s free
 * method, never from perform. */
static void contact_tilde_membrane_gone(void *owner)
{
    t_contact_tilde *x = (t_contact_tilde *)owner;
    contact *fresh;
    int id;
    x->x_membrane = 0;
    if (!contact_is_active(x->x_core))
        return;
    fresh = contact_new();
    if (!fresh) {
        pd_error(x, "contact~: out of memory; the interrupted stroke is kept");
        return;
    }
    for (id = 0; id < CONTACT_PARAM_COUNT; id++)
        ictus_param_set(&contact_params, fresh, id,
                        ictus_param_get(&contact_params, x->x_core, id));
    contact_set_force_output(fresh, x->x_force, x->x_force_size);
    contact_free(x->x_core);
    x->x_core = fresh;
}

/* ---------------- report clock ---------------- */

static void contact_tilde_report_tick(t_contact_tilde *x)
{
    contact_report reports[CONTACT_REPORT_QUEUE];
    int i, count = x->x_reports_ready;
    /* Copied first: a receiver of the list may send a hit, whose stroke cannot end now. */
    memcpy(reports, x->x_reports, sizeof(reports[0]) * (size_t)count);
    x->x_reports_ready = 0;
    for (i = 0; i < count; i++) {
        t_atom list[3];
        SETFLOAT(&list[0], (t_float)reports[i].duration_ms);
        SETFLOAT(&list[1], (t_float)reports[i].peak_force_n);
        SETFLOAT(&list[2], (t_float)reports[i].rebound_velocity_mps);
        outlet_list(x->x_report_out, &s_list, 3, list);
    }
}

/* ---------------- DSP ---------------- */

static t_int *contact_tilde_perform(t_int *w)
{
    t_contact_tilde *x = (t_contact_tilde *)(w[1]);
    t_sample *out = (t_sample *)(w[2]);
    int n = (int)(w[3]), i, have = n < x->x_force_size ? n : x->x_force_size;
    float *force = x->x_force;
    /* The membrane's perform filled the buffer (this block, or the last one if
     * Pd sorted us first); zero it so a missing membrane gives silence. */
    for (i = 0; i < have; i++) {
        out[i] = force[i];
        force[i] = 0;
    }
    for (; i < n; i++)
        out[i] = 0;
    while (x->x_reports_ready < CONTACT_REPORT_QUEUE &&
           contact_take_report(x->x_core, &x->x_reports[x->x_reports_ready]))
        if (x->x_reports_ready++ == 0)
            clock_delay(x->x_report_clock, 0);
    return (w + 4);
}

static void contact_tilde_dsp(t_contact_tilde *x, t_signal **sp)
{
    int n = sp[0]->s_n;
    t_membrane_tilde *m = 0;
    if (x->x_name != &s_) {
        m = (t_membrane_tilde *)pd_findbyclass(x->x_name, ictus_membrane_tilde_class);
        if (!m)
            pd_error(x, "contact~: no membrane~ named '%s'", x->x_name->s_name);
    }
    if (x->x_membrane && x->x_membrane != m) {
        ictus_membrane_tilde_detach(x->x_membrane, x);
        x->x_membrane = 0;
    }
    /* The force buffer: allocated here (a dsp method, never in perform). */
    if (x->x_force_size != n) {
        float *grown =
            (float *)resizebytes(x->x_force, sizeof(float) * x->x_force_size, sizeof(float) * n);
        if (grown) {
            x->x_force = grown;
            x->x_force_size = n;
        } else
            pd_error(x, "contact~: out of memory for the force outlet");
    }
    if (x->x_force)
        memset(x->x_force, 0, sizeof(float) * x->x_force_size);
    contact_set_force_output(x->x_core, x->x_force, x->x_force_size);
    x->x_refused = 0;
    if (m) {
        if (ictus_membrane_tilde_attach(m, x->x_core, x, contact_tilde_membrane_gone))
            x->x_membrane = m;
        else if (ictus_membrane_tilde_contacts(m) >= MEMBRANE_MAX_CONTACTS) {
            x->x_refused = 1;
            pd_error(x, "contact~: membrane~ '%s' already has %d contact~s; this one is silent",
                     x->x_name->s_name, MEMBRANE_MAX_CONTACTS);
        } else {
            /* the snare side (wires on or off) holds a coupling point of its own */
            x->x_refused = 2;
            pd_error(x,
                     "contact~: membrane~ '%s' has no free coupling point: %d contact~s and its "
                     "snare side take the %d; this one is silent",
                     x->x_name->s_name, ictus_membrane_tilde_contacts(m), MEMBRANE_MAX_POINTS);
        }
    }
    dsp_add(contact_tilde_perform, 3, x, sp[0]->s_vec, (t_int)n);
}

/* ---------------- life cycle ---------------- */

static void *contact_tilde_new(t_symbol *s, int argc, t_atom *argv)
{
    contact *core = contact_new();
    t_contact_tilde *x = ictus_core_object_new(ictus_contact_tilde_class, "contact~", core);
    (void)s;
    if (!x)
        return 0;
    x->x_core = core;
    x->x_f = 0;
    x->x_membrane = 0;
    x->x_force = 0;
    x->x_force_size = 0;
    x->x_reports_ready = 0;
    x->x_name = &s_;
    /* The head's stretching under the stick: the default head's, as the physics'. */
    ictus_param_set(&contact_params, core, CONTACT_PARAM_STRETCH, STICK_TIP_HEAD_K3_DEFAULT);
    if (argc > 0 && argv[0].a_type == A_SYMBOL)
        x->x_name = atom_getsymbol(&argv[0]);
    else
        pd_error(x, "contact~: needs the name of a membrane~ as argument ([contact~ NAME]); "
                    "silent until 'set NAME'");
    if (argc > 1) {
        if (argv[1].a_type == A_SYMBOL)
            contact_tilde_set_tip(x, atom_getsymbol(&argv[1]));
        else
            pd_error(x, "contact~: the second argument is a stick tip name (wood, nylon, felt); "
                        "ignored");
    }
    if (argc > 2)
        pd_error(x, "contact~: takes two arguments, a membrane~ name and a stick tip; extra "
                    "arguments ignored");
    outlet_new(&x->x_obj, &s_signal);
    x->x_report_out = outlet_new(&x->x_obj, &s_list);
    x->x_report_clock = clock_new(x, (t_method)contact_tilde_report_tick);
    return x;
}

static void contact_tilde_free(t_contact_tilde *x)
{
    /* Detach before the buffer goes: the membrane's perform writes into it. */
    if (x->x_membrane)
        ictus_membrane_tilde_detach(x->x_membrane, x);
    contact_set_force_output(x->x_core, 0, 0);
    clock_free(x->x_report_clock);
    if (x->x_force)
        freebytes(x->x_force, sizeof(float) * x->x_force_size);
    contact_free(x->x_core);
}

void ictus_contact_tilde_setup(void)
{
    ictus_contact_tilde_class =
        class_new(gensym("contact~"), (t_newmethod)contact_tilde_new, (t_method)contact_tilde_free,
                  sizeof(t_contact_tilde), CLASS_DEFAULT, A_GIMME, 0);
    class_addmethod(ictus_contact_tilde_class, (t_method)contact_tilde_dsp, gensym("dsp"), A_CANT,
                    0);
    ictus_params_addmethods(ictus_contact_tilde_class, &contact_tilde_params,
                            (t_method)contact_tilde_setparam);
    class_addmethod(ictus_contact_tilde_class, (t_method)contact_tilde_hit, gensym("hit"), A_GIMME,
                    0);
    class_addmethod(ictus_contact_tilde_class, (t_method)contact_tilde_set, gensym("set"), A_GIMME,
                    0);
    class_addmethod(ictus_contact_tilde_class, (t_method)contact_tilde_tip, gensym("tip"), A_GIMME,
                    0);
}
