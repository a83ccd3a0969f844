/* ictus_pd_common.h -- what membrane~ and contact~ share on the Pd side: the sample
 * clock that times their messages, the readers of message arguments, and the
 * parameter tables that turn one-number messages into calls of the core's setters.
 * Private to libictus_pd.so; no object's internals here (docs/externals.md, "Layout"). */
#ifndef ICTUS_PD_COMMON_H
#define ICTUS_PD_COMMON_H

#include "m_pd.h"
#include "membrane.h"

/* ---------------- the sample clock ----------------
 *
 * Maps Pd's logical time onto one membrane~'s own sample stream, so that a message
 * (strike, or a contact~ hit) lands on the sample its logical time names, whatever
 * the block size of the canvas (docs/externals.md, "Timing"). */
typedef struct _ictus_clock {
    double c_anchor;       /* logical time (clock_getlogicaltime) of stream sample 0 */
    double c_samples_done; /* samples computed since the anchor (exact in a double) */
    double c_sr;           /* this instance's sample rate (Hz), from its dsp method */
    double c_window;       /* samples one block spans in logical time: max(n, one tick) */
    int c_anchored;        /* 0 until the first perform after a dsp method */
} t_ictus_clock;

/* From the dsp method: the sample rate the core runs at; re-anchors at the next block. */
void ictus_clock_dsp(t_ictus_clock *c, double sample_rate_hz);
/* From perform, before computing a block of n samples. */
void ictus_clock_block_begin(t_ictus_clock *c, int n);
/* From perform, after it. */
void ictus_clock_block_end(t_ictus_clock *c, int n);
/* Sample offset, relative to the start of the next block the clock's object will
 * compute, of the current logical time. 0 before DSP runs. */
int ictus_clock_offset_now(const t_ictus_clock *c);

/* ---------------- objects built on a core ---------------- */

/* pd_new(c) for an object of class `name` whose core is `core`; NULL, with the error
 * said, when the core could not be made (core NULL: out of memory). */
void *ictus_core_object_new(t_class *c, const char *name, const void *core);

/* ---------------- message arguments ---------------- */

/* Reads argv[i] as a finite number into *value, or reports (object, message,
 * argument) with pd_error and returns 0. */
int ictus_getnumber(void *x, const char *obj, const char *msg, const char *arg, int argc,
                    const t_atom *argv, int i, double *value);
/* r/a and theta (deg) from argv[first], argv[first + 1]. r/a outside the core's range
 * [MEMBRANE_R_OVER_A_MIN, MEMBRANE_R_OVER_A_MAX] is clamped and reported; so is a
 * theta beyond +-1e6 deg, where a Pd float has no fraction of a degree left (set to 0;
 * the core itself takes any angle). */
int ictus_getpoint(void *x, const char *obj, const char *msg, int argc, const t_atom *argv,
                   int first, double *r_over_a, double *theta_deg);

/* ---------------- parameter tables ----------------
 *
 * The core's table of a class lists its one-number messages (ictus_param.h), one
 * message per entry, named as the entry. Setting goes through the core,
 * which clamps into its own range and says so (ICTUS_CLAMPED); the error line then
 * quotes the core's range (ictus_range) and the value it kept. */
typedef struct _ictus_params {
    const char *ps_class;              /* "membrane~": errors start with it */
    const ictus_param_table *ps_table; /* the core's (membrane_params, contact_params) */
} t_ictus_params;

/* Sets parameter id (an entry of the core's table) on core and reports, on x, what
 * the core clamped or refused. A value just outside the range that is its limit as a
 * Pd float, or as the error line prints it (%g), is taken as that limit, without a
 * word. */
void ictus_params_set(void *x, const t_ictus_params *ps, void *core, int id, double value);
/* The A_GIMME method body for every entry's message: one number, checked and set. */
void ictus_params_message(void *x, const t_ictus_params *ps, void *core, const t_symbol *s,
                          int argc, const t_atom *argv);
/* Adds `method` (an A_GIMME method calling ictus_params_message) under every name. */
void ictus_params_addmethods(t_class *c, const t_ictus_params *ps, t_method method);

#endif
