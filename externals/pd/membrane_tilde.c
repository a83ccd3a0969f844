/* membrane~ -- a circular drum head (modal membrane, externals/core/membrane.h).
 *
 * [membrane~ NAME radius tension density modes]: NAME lets contact~ objects find
 * it (as delread~ finds delwrite~); the numbers are optional.
 * Inlet: force (N) applied at the strike point ("position"); messages below.
 * Outlets: pickup 1 and pickup 2 (membrane velocity scaled by "gain", see
 * docs/membrane.md).
 *
 * Timing: a "strike" (and a contact~ "hit") lands on the sample its logical time
 * names, for any block size. Each instance keeps its own sample counter,
 * advanced by n in perform and anchored to logical time at the first perform
 * after a dsp method, like vline~ it treats a block computed while logical time
 * is `now` as ending at `now`. A counter (not the logical time of the perform
 * call) is what makes [block~ 1] work: its 64 blocks per tick all run at the same
 * logical time. Overlap (block~ N M with M > 1) and up/down-sampling are not
 * supported (the anchor is re-taken every block and timing is block-accurate).
 */
#include <math.h>
#include <string.h>

#include "ictus_pd.h"

#if PD_FLOATSIZE != 32
#error "ictus: the DSP core works on 32-bit float signals; build against a 32-bit Pd"
#endif

t_class *ictus_membrane_tilde_class;

#define ICTUS_STRIKE_IMPULSE_MAX 10.0 /* N s */
#define ICTUS_PI                 3.14159265358979323846

/* ---------------- logical time -> sample offset ---------------- */

int ictus_clock_offset_now(const t_ictus_clock *c)
{
    double offset;
    if (!c->c_anchored || !(c->c_sr > 0))
        return 0;
    /* Stream index of `now`, minus the index of the next block's first sample. */
    offset = floor(clock_gettimesince(c->c_anchor) * c->c_sr / 1000.0 + 0.5) - c->c_samples_done;
    if (!(offset > 0))
        return 0; /* a message from the past (cannot happen from the scheduler) */
    /* A message always falls inside the window the next block will cover; past
     * it, DSP has stopped since the anchor was taken (dsp 0, switch~ off): the
     * next perform re-anchors, so the message lands at its start. Exactly at
     * the window's end is not past it: a time in the window's last half sample
     * rounds to the first sample of the block after, and the core carries a
     * pending hit over (offset - n); returning 0 there started it a whole
     * block early (found by tests/e2e: a strike at 9.483993 s, 48 kHz). */
    if (offset > c->c_window)
        return 0;
    return (int)offset;
}

/* Called at the top of every perform. Samples in one scheduler tick at this
 * instance's rate: the anchor is the start of the window the first block covers,
 * max(n, tick) samples before now (a bigger block~ gathers n samples of input
 * before it runs; smaller ones run tick/n times at the same logical time). */
static void ictus_clock_advance_check(t_ictus_clock *c, int n)
{
    double ms_per_sample = 1000.0 / c->c_sr;
    double tick_samples = (double)sys_getblksize() * c->c_sr / sys_getsr();
    double window = (n > tick_samples) ? n : tick_samples;
    c->c_window = window;
    if (c->c_anchored) {
        /* The block about to run ends at samples_done + n; with small blocks the
         * logical time may be up to one tick later. Anything else means DSP was
         * stopped in between (switch~) or blocks overlap: re-anchor. */
        double elapsed = clock_gettimesince(c->c_anchor) / ms_per_sample;
        double end = c->c_samples_done + n;
        double slack = n < tick_samples ? tick_samples - n : 0;
        if (elapsed < end - 0.5 || elapsed > end + slack + 0.5)
            c->c_anchored = 0;
    }
    if (!c->c_anchored) {
        /* now is `window` samples after stream sample 0 */
        c->c_anchor = clock_getsystimeafter(-window * ms_per_sample);
        c->c_samples_done = 0;
        c->c_anchored = 1;
    }
}

/* ---------------- parameters ---------------- */

typedef ictus_status (*t_setter)(membrane *, double);
typedef double (*t_getter)(const membrane *);

typedef struct _param {
    const char *p_name;
    const char *p_unit;
    double p_min, p_max;
    t_setter p_set;
    t_getter p_get;
} t_param;

static ictus_status membrane_tilde_set_modes(membrane *m, double count)
{
    return membrane_set_modes(m, (int)count); /* count already clamped and rounded */
}
static double membrane_tilde_get_modes(const membrane *m)
{
    return membrane_get_modes(m);
}

/* hfdamp and gain have no range macros in membrane.h; these are the ranges
 * membrane.c clamps to (docs/membrane.md). Should they drift apart, the core's
 * ICTUS_CLAMPED still produces an error line below. A negative gain inverts. */
static const t_param membrane_tilde_params[] = {
    {"radius", "m", MEMBRANE_RADIUS_MIN, MEMBRANE_RADIUS_MAX, membrane_set_radius,
     membrane_get_radius},
    {"tension", "N/m", MEMBRANE_TENSION_MIN, MEMBRANE_TENSION_MAX, membrane_set_tension,
     membrane_get_tension},
    {"density", "kg/m^2", MEMBRANE_DENSITY_MIN, MEMBRANE_DENSITY_MAX, membrane_set_density,
     membrane_get_density},
    {"mass", "kg", 0, HUGE_VAL, membrane_set_mass, membrane_get_mass},
    {"modes", "", MEMBRANE_MODES_MIN, MEMBRANE_MODES_MAX, membrane_tilde_set_modes,
     membrane_tilde_get_modes},
    {"t60", "s", MEMBRANE_T60_MIN, MEMBRANE_T60_MAX, membrane_set_t60, membrane_get_t60},
    {"hfdamp", "", 0, 1000.0, membrane_set_hf_damping, membrane_get_hf_damping},
    {"gain", "", -1.0e6, 1.0e6, membrane_set_output_gain, membrane_get_output_gain},
};
#define NPARAMS (int)(sizeof(membrane_tilde_params) / sizeof(membrane_tilde_params[0]))

/* Reads argv[i] as a finite number; otherwise reports it (naming the message and
 * argument) and returns 0. */
int ictus_getnumber(void *x, const char *obj, const char *msg, const char *arg, int argc,
                    const t_atom *argv, int i, double *value)
{
    if (i >= argc) {
        pd_error(x, "%s: %s: missing %s", obj, msg, arg);
        return 0;
    }
    if (argv[i].a_type != A_FLOAT) {
        char buf[MAXPDSTRING];
        atom_string(&argv[i], buf, sizeof(buf));
        pd_error(x, "%s: %s: %s must be a number, got '%s'", obj, msg, arg, buf);
        return 0;
    }
    *value = atom_getfloat(&argv[i]);
    if (!isfinite(*value)) {
        pd_error(x, "%s: %s: %s must be finite, got %g", obj, msg, arg, *value);
        return 0;
    }
    return 1;
}

static void membrane_tilde_param(t_membrane_tilde *x, const t_param *p, double value)
{
    ictus_status status;
    const char *space = *p->p_unit ? " " : "";
    double lo = p->p_min, hi = p->p_max;
    if (!strcmp(p->p_name, "mass")) {
        /* the mass is density times area: its range follows the radius */
        double a = membrane_get_radius(x->x_core);
        lo = MEMBRANE_DENSITY_MIN * ICTUS_PI * a * a;
        hi = MEMBRANE_DENSITY_MAX * ICTUS_PI * a * a;
    }
    if (!strcmp(p->p_name, "modes"))
        value = floor(value + 0.5);
    if (value < lo || value > hi) {
        double used = value < lo ? lo : hi;
        if (hi == HUGE_VAL)
            pd_error(x, "membrane~: %s must be >= %g%s%s, got %g; using %g", p->p_name, lo, space,
                     p->p_unit, value, used);
        else
            pd_error(x, "membrane~: %s must be in [%g, %g]%s%s, got %g; using %g", p->p_name, lo,
                     hi, space, p->p_unit, value, used);
        value = used;
    }
    status = p->p_set(x->x_core, value);
    if (status == ICTUS_ENOMEM)
        pd_error(x, "membrane~: %s %g: out of memory; keeping %g", p->p_name, value,
                 p->p_get(x->x_core));
    else if (status == ICTUS_CLAMPED)
        pd_error(x, "membrane~: %s %g%s%s is out of range; using %g", p->p_name, value, space,
                 p->p_unit, p->p_get(x->x_core));
}

/* radius, tension, density, mass, modes, t60, hfdamp, gain: one number each. */
static void membrane_tilde_setparam(t_membrane_tilde *x, t_symbol *s, int argc, t_atom *argv)
{
    int i;
    double value;
    for (i = 0; i < NPARAMS; i++)
        if (!strcmp(s->s_name, membrane_tilde_params[i].p_name))
            break;
    if (i == NPARAMS)
        return;
    if (argc > 1)
        pd_error(x, "membrane~: %s takes one number; extra arguments ignored", s->s_name);
    if (ictus_getnumber(x, "membrane~", s->s_name, "value", argc, argv, 0, &value))
        membrane_tilde_param(x, &membrane_tilde_params[i], value);
}

/* r/a and theta (degrees) from argv[first], argv[first+1], clamped and reported. */
int ictus_getpoint(void *x, const char *obj, const char *msg, int argc, const t_atom *argv,
                   int first, double *r_over_a, double *theta_deg)
{
    if (!ictus_getnumber(x, obj, msg, "r/a", argc, argv, first, r_over_a) ||
        !ictus_getnumber(x, obj, msg, "theta (deg)", argc, argv, first + 1, theta_deg))
        return 0;
    if (*r_over_a < 0 || *r_over_a > 1) {
        double used = *r_over_a < 0 ? 0 : 1;
        pd_error(x, "%s: %s: r/a must be in [0, 1], got %g; using %g", obj, msg, *r_over_a, used);
        *r_over_a = used;
    }
    if (fabs(*theta_deg) > 1.0e6) {
        pd_error(x, "%s: %s: theta must be in [-1e6, 1e6] deg, got %g; using 0", obj, msg,
                 *theta_deg);
        *theta_deg = 0;
    }
    return 1;
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
    membrane_set_pickup(x->x_core, (int)index - 1, r, theta);
}

/* position <r/a> <theta deg>: where the signal inlet's force is applied. */
static void membrane_tilde_position(t_membrane_tilde *x, t_symbol *s, int argc, t_atom *argv)
{
    double r, theta;
    (void)s;
    if (ictus_getpoint(x, "membrane~", "position", argc, argv, 0, &r, &theta))
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
    /* 10 N s is four times a 0.05 kg stick at the core's 50 m/s limit */
    if (impulse < 0 || impulse > ICTUS_STRIKE_IMPULSE_MAX) {
        double used = impulse < 0 ? 0 : ICTUS_STRIKE_IMPULSE_MAX;
        pd_error(x, "membrane~: strike: impulse must be in [0, %g] N s, got %g; using %g",
                 ICTUS_STRIKE_IMPULSE_MAX, impulse, used);
        impulse = used;
    }
    membrane_strike(x->x_core, r, theta, impulse, ictus_clock_offset_now(&x->x_clock));
}

static void membrane_tilde_clear(t_membrane_tilde *x)
{
    membrane_clear(x->x_core);
}

/* print: the physics and the first modes, in the Pd window. */
static void membrane_tilde_print(t_membrane_tilde *x)
{
    int k, count = membrane_get_modes(x->x_core);
    post("membrane~ %s: radius %g m, tension %g N/m, density %g kg/m^2 (mass %g kg), "
         "%d modes, t60 %g s, hfdamp %g, gain %g, sr %g Hz",
         x->x_name != &s_ ? x->x_name->s_name : "(no name)", membrane_get_radius(x->x_core),
         membrane_get_tension(x->x_core), membrane_get_density(x->x_core),
         membrane_get_mass(x->x_core), count, membrane_get_t60(x->x_core),
         membrane_get_hf_damping(x->x_core), membrane_get_output_gain(x->x_core),
         membrane_get_sample_rate(x->x_core));
    for (k = 0; k < count && k < 12; k++) {
        double f, t60;
        int bm, bn, sinp;
        if (membrane_get_mode(x->x_core, k, &f, &t60, &bm, &bn, &sinp))
            post("  mode %2d (%d,%d)%s: %9.2f Hz  T60 %.3f s", k, bm, bn,
                 bm ? (sinp ? " sin" : " cos") : "    ", f, t60);
    }
}

/* ---------------- contacts ---------------- */

int ictus_membrane_tilde_attach(t_membrane_tilde *m, t_contact_tilde *c)
{
    int i, free_slot = -1;
    for (i = 0; i < MEMBRANE_MAX_CONTACTS; i++) {
        if (m->x_contacts[i] == c)
            return 1;
        if (!m->x_contacts[i] && free_slot < 0)
            free_slot = i;
    }
    if (free_slot < 0 || membrane_attach_contact(m->x_core, c->x_core) != ICTUS_OK)
        return 0;
    m->x_contacts[free_slot] = c;
    c->x_membrane = m;
    return 1;
}

void ictus_membrane_tilde_detach(t_membrane_tilde *m, t_contact_tilde *c)
{
    int i;
    for (i = 0; i < MEMBRANE_MAX_CONTACTS; i++)
        if (m->x_contacts[i] == c)
            m->x_contacts[i] = 0;
    membrane_detach_contact(m->x_core, c->x_core);
    if (c->x_membrane == m)
        c->x_membrane = 0;
}

/* ---------------- DSP ---------------- */

static t_int *membrane_tilde_perform(t_int *w)
{
    t_membrane_tilde *x = (t_membrane_tilde *)(w[1]);
    t_sample *force_in = (t_sample *)(w[2]);
    t_sample *out[MEMBRANE_PICKUPS];
    int n = (int)(w[5]);
    out[0] = (t_sample *)(w[3]);
    out[1] = (t_sample *)(w[4]);
    ictus_clock_advance_check(&x->x_clock, n);
    membrane_process(x->x_core, force_in, out, n);
    x->x_clock.c_samples_done += n;
    return (w + 6);
}

static void membrane_tilde_dsp(t_membrane_tilde *x, t_signal **sp)
{
    double sr = sp[0]->s_sr;
    if (membrane_set_sample_rate(x->x_core, sr) != ICTUS_OK)
        pd_error(x, "membrane~: sample rate %g Hz is outside [%g, %g]; using %g", sr,
                 MEMBRANE_SR_MIN, MEMBRANE_SR_MAX, membrane_get_sample_rate(x->x_core));
    x->x_clock.c_sr = membrane_get_sample_rate(x->x_core);
    x->x_clock.c_anchored = 0;
    dsp_add(membrane_tilde_perform, 5, x, sp[0]->s_vec, sp[1]->s_vec, sp[2]->s_vec,
            (t_int)sp[0]->s_n);
}

/* ---------------- life cycle ---------------- */

static void *membrane_tilde_new(t_symbol *s, int argc, t_atom *argv)
{
    t_membrane_tilde *x;
    membrane *core = membrane_new(sys_getsr() > 0 ? sys_getsr() : 44100);
    int first = 0, i;
    (void)s;
    if (!core) {
        pd_error(0, "membrane~: out of memory");
        return 0;
    }
    x = (t_membrane_tilde *)pd_new(ictus_membrane_tilde_class);
    x->x_core = core;
    x->x_f = 0;
    x->x_name = &s_;
    memset(&x->x_clock, 0, sizeof(x->x_clock));
    for (i = 0; i < MEMBRANE_MAX_CONTACTS; i++)
        x->x_contacts[i] = 0;
    if (argc > 0 && argv[0].a_type == A_SYMBOL) {
        x->x_name = atom_getsymbol(&argv[0]);
        pd_bind(&x->x_obj.ob_pd, x->x_name);
        first = 1;
    }
    /* optional: radius tension density modes */
    {
        static const int order[] = {0, 1, 2, 4};
        for (i = first; i < argc && i - first < 4; i++) {
            double value;
            const t_param *p = &membrane_tilde_params[order[i - first]];
            if (ictus_getnumber(x, "membrane~", "creation argument", p->p_name, argc, argv, i,
                                &value))
                membrane_tilde_param(x, p, value);
        }
        if (argc - first > 4)
            pd_error(x, "membrane~: arguments are NAME radius tension density modes; "
                        "extra arguments ignored");
    }
    outlet_new(&x->x_obj, &s_signal);
    outlet_new(&x->x_obj, &s_signal);
    return x;
}

static void membrane_tilde_free(t_membrane_tilde *x)
{
    int i;
    /* contact~ objects keep a pointer to us: detach them all so none dangles. */
    for (i = 0; i < MEMBRANE_MAX_CONTACTS; i++)
        if (x->x_contacts[i]) {
            t_contact_tilde *c = x->x_contacts[i];
            ictus_membrane_tilde_detach(x, c);
            ictus_contact_tilde_abandon_stroke(c);
        }
    if (x->x_name != &s_)
        pd_unbind(&x->x_obj.ob_pd, x->x_name);
    membrane_free(x->x_core);
}

void ictus_membrane_tilde_setup(void)
{
    int i;
    ictus_membrane_tilde_class = class_new(gensym("membrane~"), (t_newmethod)membrane_tilde_new,
                                           (t_method)membrane_tilde_free, sizeof(t_membrane_tilde),
                                           CLASS_DEFAULT, A_GIMME, 0);
    CLASS_MAINSIGNALIN(ictus_membrane_tilde_class, t_membrane_tilde, x_f);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_dsp, gensym("dsp"), A_CANT,
                    0);
    for (i = 0; i < NPARAMS; i++)
        class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_setparam,
                        gensym(membrane_tilde_params[i].p_name), A_GIMME, 0);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_pickup, gensym("pickup"),
                    A_GIMME, 0);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_position,
                    gensym("position"), A_GIMME, 0);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_strike, gensym("strike"),
                    A_GIMME, 0);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_clear, gensym("clear"), 0);
    class_addmethod(ictus_membrane_tilde_class, (t_method)membrane_tilde_print, gensym("print"), 0);
}
