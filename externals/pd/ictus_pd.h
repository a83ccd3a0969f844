/* ictus_pd.h -- private to the ictus Pd library (libictus_pd.so).
 *
 * membrane~ and contact~ live in one shared library so that contact~ can find
 * a membrane~ with pd_findbyclass() (the class pointer must be one and the
 * same), the way delread~ finds delwrite~. The tiny loader binaries
 * membrane~.pd_linux, contact~.pd_linux and ictus.pd_linux only call
 * ictus_pd_setup(), which is idempotent.
 */
#ifndef ICTUS_PD_H
#define ICTUS_PD_H

#include "m_pd.h"
#include "membrane.h"
#include "contact.h"

#if defined(__GNUC__)
#define ICTUS_EXPORT __attribute__((visibility("default")))
#else
#define ICTUS_EXPORT
#endif

#define ICTUS_PD_VERSION "0.1.0"

/* Creates both classes once; later calls do nothing. Exported for the loaders. */
ICTUS_EXPORT void ictus_pd_setup(void);

struct _contact_tilde;

/* Maps Pd's logical time onto one membrane~'s own sample stream, so that a
 * message (strike, or a contact~ hit) lands on the sample its logical time
 * names, whatever the block size of the canvas (see membrane_tilde.c). */
typedef struct _ictus_clock {
    double c_anchor;       /* logical time (clock_getlogicaltime) of stream sample 0 */
    double c_samples_done; /* samples computed since the anchor (exact in a double) */
    double c_sr;           /* this instance's sample rate (Hz), from its dsp method */
    double c_window;       /* samples one block spans in logical time: max(n, one tick) */
    int c_anchored;        /* 0 until the first perform after a dsp method */
} t_ictus_clock;

/* Sample offset, relative to the start of the next block this membrane~ will
 * compute, of the current logical time. 0 before DSP runs. */
int ictus_clock_offset_now(const t_ictus_clock *c);

typedef struct _membrane_tilde {
    t_object x_obj;
    t_float x_f; /* force (N) when the inlet gets a float */
    membrane *x_core;
    t_symbol *x_name; /* bound name for contact~, or &s_ */
    t_ictus_clock x_clock;
    struct _contact_tilde *x_contacts[MEMBRANE_MAX_CONTACTS]; /* attached contact~s */
} t_membrane_tilde;

typedef struct _contact_tilde {
    t_object x_obj;
    t_float x_f;
    contact *x_core;
    t_symbol *x_name;             /* the membrane~ to play */
    t_membrane_tilde *x_membrane; /* attached membrane~, or NULL (cleared by its _free) */
    float *x_force;               /* force buffer the membrane's perform writes */
    int x_force_size;
    t_outlet *x_report_out;
    t_clock *x_report_clock;
    contact_report x_report; /* the last finished stroke, output from the clock */
} t_contact_tilde;

/* Reads argv[i] as a finite number into *value, or reports (object, message,
 * argument) with pd_error and returns 0. */
int ictus_getnumber(void *x, const char *obj, const char *msg, const char *arg, int argc,
                    const t_atom *argv, int i, double *value);
/* r/a in [0, 1] and theta (deg) from argv[first], argv[first + 1], clamped and reported. */
int ictus_getpoint(void *x, const char *obj, const char *msg, int argc, const t_atom *argv,
                   int first, double *r_over_a, double *theta_deg);

extern t_class *ictus_membrane_tilde_class;
extern t_class *ictus_contact_tilde_class;

void ictus_membrane_tilde_setup(void);
void ictus_contact_tilde_setup(void);

/* Called by contact~: attach to / detach from a membrane~ (both sides kept in step). */
int ictus_membrane_tilde_attach(t_membrane_tilde *m, t_contact_tilde *c);
void ictus_membrane_tilde_detach(t_membrane_tilde *m, t_contact_tilde *c);
/* Drops a stroke in progress (the membrane~ it was hitting is being deleted). */
void ictus_contact_tilde_abandon_stroke(t_contact_tilde *x);

#endif
