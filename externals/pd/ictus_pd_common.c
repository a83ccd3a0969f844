/* ictus_pd_common.c -- the sample clock, the argument readers and the parameter
 * tables shared by membrane~ and contact~ (see ictus_pd_common.h). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "ictus_pd_common.h"

/* ---------------- logical time -> sample offset ----------------
 *
 * Each membrane~ keeps its own sample counter, advanced by n in perform and anchored
 * to logical time at the first perform after a dsp method; like vline~ it treats a
 * block computed while logical time is `now` as ending at `now`. A counter (not the
 * logical time of the perform call) is what makes [block~ 1] work: its 64 blocks per
 * tick all run at the same logical time. Overlap (block~ N M with M > 1) and
 * up/down-sampling are not supported (the anchor is re-taken every block and timing
 * is block-accurate). */

void ictus_clock_dsp(t_ictus_clock *c, double sample_rate_hz)
{
    c->c_sr = sample_rate_hz;
    c->c_anchored = 0;
}

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

/* Samples in one scheduler tick at this instance's rate: the anchor is the start of
 * the window the first block covers, max(n, tick) samples before now (a bigger
 * block~ gathers n samples of input before it runs; smaller ones run tick/n times
 * at the same logical time). */
void ictus_clock_block_begin(t_ictus_clock *c, int n)
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

void ictus_clock_block_end(t_ictus_clock *c, int n)
{
    c->c_samples_done += n;
}

/* ---------------- objects built on a core ---------------- */

void *ictus_core_object_new(t_class *c, const char *name, const void *core)
{
    if (!core) {
        pd_error(0, "%s: out of memory", name);
        return 0;
    }
    return pd_new(c);
}

/* ---------------- message arguments ---------------- */

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

int ictus_getpoint(void *x, const char *obj, const char *msg, int argc, const t_atom *argv,
                   int first, double *r_over_a, double *theta_deg)
{
    const double lo = MEMBRANE_R_OVER_A_MIN, hi = MEMBRANE_R_OVER_A_MAX;
    if (!ictus_getnumber(x, obj, msg, "r/a", argc, argv, first, r_over_a) ||
        !ictus_getnumber(x, obj, msg, "theta (deg)", argc, argv, first + 1, theta_deg))
        return 0;
    if (*r_over_a < lo || *r_over_a > hi) {
        double used = *r_over_a < lo ? lo : hi;
        pd_error(x, "%s: %s: r/a must be in [%g, %g], got %g; using %g", obj, msg, lo, hi,
                 *r_over_a, used);
        *r_over_a = used;
    }
    if (fabs(*theta_deg) > 1.0e6) {
        pd_error(x, "%s: %s: theta must be in [-1e6, 1e6] deg, got %g; using 0", obj, msg,
                 *theta_deg);
        *theta_deg = 0;
    }
    return 1;
}

/* ---------------- parameter tables ---------------- */

/* Whether `value`, just outside a range, is its `limit` as the user wrote it. A Pd
 * message carries a t_float: a limit typed in a message (0.01, 1e-4) arrives as the
 * float nearest to it, up to half a float's step away from the double the core
 * compares with (0.01f is 0.0099999998); and the error line quotes limits with %g's
 * six digits (the mass's, pi a^2 times the density's, are not round). Either way
 * the user asked for the limit. */
static int ictus_is_limit(double value, double limit)
{
    char typed[32], quoted[32];
    if ((t_float)value == (t_float)limit)
        return 1;
    snprintf(typed, sizeof(typed), "%g", value);
    snprintf(quoted, sizeof(quoted), "%g", limit);
    return !strcmp(typed, quoted);
}

void ictus_params_set(void *x, const t_ictus_params *ps, void *core, int id, double value)
{
    const ictus_param_def *p = &ps->ps_table->def[id];
    /* The range before setting: the mass's follows the radius, not the mass. */
    ictus_range range = ictus_param_range(ps->ps_table, core, id);
    const char *space = *p->unit ? " " : "";
    ictus_status status;
    if (value < range.min && ictus_is_limit(value, range.min))
        value = range.min;
    else if (value > range.max && ictus_is_limit(value, range.max))
        value = range.max;
    status = ictus_param_set(ps->ps_table, core, id, value);
    if (status == ICTUS_ENOMEM)
        pd_error(x, "%s: %s %g: out of memory; keeping %g", ps->ps_class, p->name, value,
                 ictus_param_get(ps->ps_table, core, id));
    else if (status == ICTUS_CLAMPED)
        pd_error(x, "%s: %s must be in [%g, %g]%s%s, got %g; using %g", ps->ps_class, p->name,
                 range.min, range.max, space, p->unit, value,
                 ictus_param_get(ps->ps_table, core, id));
}

void ictus_params_message(void *x, const t_ictus_params *ps, void *core, const t_symbol *s,
                          int argc, const t_atom *argv)
{
    int id = ictus_param_find(ps->ps_table, s->s_name);
    double value;
    if (id < 0)
        return;
    if (argc > 1)
        pd_error(x, "%s: %s takes one number; extra arguments ignored", ps->ps_class, s->s_name);
    if (ictus_getnumber(x, ps->ps_class, s->s_name, "value", argc, argv, 0, &value))
        ictus_params_set(x, ps, core, id, value);
}

void ictus_params_addmethods(t_class *c, const t_ictus_params *ps, t_method method)
{
    int i;
    for (i = 0; i < ps->ps_table->count; i++)
        class_addmethod(c, method, gensym(ps->ps_table->def[i].name), A_GIMME, 0);
}
