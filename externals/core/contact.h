/* contact.h -- nonlinear stick-membrane impact (Hunt-Crossley), plain C99.
 *
 * A stick of lumped mass m (kg) hits the membrane at (r/a, theta). With the
 * compression x = stick position - membrane displacement at the contact point
 * (positive into the membrane), the contact force is
 *     F = k x^alpha + lambda x^alpha dx/dt     for x > 0, else 0, and F >= 0
 * (Hunt & Crossley; lambda in N s / m^(alpha+1)), the law of stick_tip.h, which
 * the daemon's physics uses too. The ratio mu = lambda / k (s/m) is the damping
 * per unit stiffness. contact_set_tip() takes alpha, k and lambda from the table
 * of stick tips (stick_tip.h: wood, nylon, felt).
 * The head's stretching under a point load (stick_tip_head_k3 in stick_tip.h: a
 * force k3 y^3 on top of the modes' linear stiffness, y the head's deflection under
 * the stick) is the "stretch" parameter, k3 in N/m^3. It is carried by the head
 * under the stick while a stroke lasts: the potential k3 w^4 / 4 of the head's depth
 * w there (w > 0), so the modes take F - k3 w^3 and the stick F alone. With a stiff
 * tip the two move together and the stick meets the physics' head F = k1 y + k3 y^3
 * (daemon/src/sim), the modes as k1; when the head falls behind the stick, the stick
 * no longer feels the stretching (docs/contact.md, "Stick tips").
 * The contact is solved jointly with the membrane's modes, sample by sample
 * (Avanzini & Rocchesso), with an energy-consistent discretisation: the
 * spring term is a discrete gradient of V(x) = k x^(alpha+1)/(alpha+1) and the
 * modes and the stick advance with the midpoint rule, so the discrete energy
 * of stick + membrane + spring never grows (docs/membrane.md). The stick
 * therefore never rebounds faster than it came in, by construction.
 *
 * A contact does nothing on its own: attach it to a membrane
 * (membrane_attach_contact), then contact_hit() starts a stroke. The contact is
 * one of the membrane's coupling points (membrane_internal.h): the membrane folds
 * its force into the modes, contact.c computes the force and runs the stroke.
 */
#ifndef ICTUS_CONTACT_H
#define ICTUS_CONTACT_H

#include "membrane.h"

#ifdef __cplusplus
extern "C" {
#endif

#define CONTACT_MASS_MIN      1.0e-4 /* kg */
#define CONTACT_MASS_MAX      10.0
#define CONTACT_STIFFNESS_MIN 1.0 /* N/m^alpha */
#define CONTACT_STIFFNESS_MAX 1.0e12
#define CONTACT_ALPHA_MIN     1.0
#define CONTACT_ALPHA_MAX     4.0
#define CONTACT_DAMPING_MIN   0.0 /* lambda, N s / m^(alpha+1) */
#define CONTACT_DAMPING_MAX   1.0e13
#define CONTACT_VELOCITY_MAX  50.0 /* m/s, |hit velocity| */
#define CONTACT_STRETCH_MIN   0.0  /* k3, N/m^3 */
#define CONTACT_STRETCH_MAX   1.0e12
/* Hits waiting behind the next one, and finished strokes not yet taken: a long block
 * (block~ 2048 is 43 ms at 48 kHz) holds a roll's hits and ends their strokes. */
#define CONTACT_HIT_QUEUE    64
#define CONTACT_REPORT_QUEUE 64

/* Contacts attached to one membrane at once: each is one of its coupling points. */
#define MEMBRANE_MAX_CONTACTS MEMBRANE_MAX_POINTS

/* Defaults: a 50 g snare stick, a tip 47 times softer than the "wood" of
 * stick_tip.h (docs/contact.md, "Stick tips": with the Hertz stiffness of wood on
 * Mylar the head's compliance is all there is, and a harder hit is no brighter). */
#define CONTACT_DEFAULT_MASS      0.05
#define CONTACT_DEFAULT_STIFFNESS 1.0e7
#define CONTACT_DEFAULT_ALPHA     1.5
#define CONTACT_DEFAULT_DAMPING   5.0e6 /* mu = lambda / k = 0.5 s/m */
/* The head's stretching under the stick, off in the core (contact~ sets the
 * default head's value, STICK_TIP_HEAD_K3_DEFAULT in stick_tip.h). */
#define CONTACT_DEFAULT_STRETCH 0.0

/* The one-number parameters, set, read and ranged through contact_params
 * (ictus_param.h): ictus_param_set(&contact_params, c, CONTACT_PARAM_MASS, 0.05). */
typedef enum contact_param {
    CONTACT_PARAM_MASS,      /* kg */
    CONTACT_PARAM_STIFFNESS, /* k, N/m^alpha */
    CONTACT_PARAM_ALPHA,     /* the exponent alpha */
    CONTACT_PARAM_DAMPING,   /* lambda, N s/m^(alpha+1) */
    CONTACT_PARAM_STRETCH,   /* k3, N/m^3: the head's stretching (below) */
    CONTACT_PARAM_COUNT
} contact_param;

/* Indexed by contact_param; names as the Pd messages. */
extern const ictus_param_table contact_params;

typedef struct contact contact;

/* What a finished stroke reports (on release: the stick leaves the membrane). */
typedef struct contact_report {
    double duration_ms;          /* first touch to release */
    double peak_force_n;         /* largest contact force */
    double rebound_velocity_mps; /* stick velocity away from the membrane at release (>= 0) */
    double impulse_ns;           /* integral of the force */
} contact_report;

/* Allocates. Returns NULL when memory cannot be had. */
contact *contact_new(void);

/* alpha, stiffness and damping (lambda = mu k) from the stick tip called name
 * (stick_tip.h). Returns ICTUS_CLAMPED and changes nothing for an unknown name.
 * The mass stays: it is the stick's, set with the hit or the "mass" parameter. */
ictus_status contact_set_tip(contact *c, const char *name);
void contact_free(contact *c);

/* Attach / detach a contact (at most MEMBRANE_MAX_CONTACTS per membrane). A contact
 * is solved jointly with the modes, sample by sample. Attaching an attached contact
 * does nothing; attaching it to another membrane detaches it first. Returns
 * ICTUS_ENOMEM when the table is full or memory cannot be had (allocates). */
ictus_status membrane_attach_contact(membrane *m, contact *c);
void membrane_detach_contact(membrane *m, contact *c);

/* Starts a stroke: the stick arrives at the membrane surface at (r/a, theta)
 * moving into it at velocity_mps (> 0), `sample_offset` samples into the next
 * membrane_process() call of the membrane it is attached to. Values out of
 * range are clamped (status says so). A new hit replaces a stroke in progress when it
 * lands. Hits for later samples than one waiting to land wait behind it (up to
 * CONTACT_HIT_QUEUE; more: ICTUS_ENOMEM, the hit is dropped), each landing on its own
 * sample; a hit for the same or an earlier sample replaces the hits waiting there and after. */
ictus_status contact_hit(contact *c, double velocity_mps, double r_over_a, double theta_deg,
                         int sample_offset);

/* The same, and the stick's mass (kg) becomes mass_kg when the hit lands, on
 * its sample (a stroke still under way keeps the old mass to its end). A
 * mass_kg of 0 keeps the mass; one out of range is clamped (status says so). */
ictus_status contact_hit_mass(contact *c, double velocity_mps, double r_over_a, double theta_deg,
                              int sample_offset, double mass_kg);

/* Force buffer: membrane_process() writes this contact's force (N), one value
 * per sample, into the buffer given here (capacity in samples; the membrane
 * writes min(n, capacity) values per call). NULL to stop writing. */
void contact_set_force_output(contact *c, float *buffer, int capacity);

/* 1 while the stick is in a stroke (touching, or away but not yet released). */
int contact_is_active(const contact *c);
/* Returns 1 and fills *report with the oldest finished stroke not yet taken (up to
 * CONTACT_REPORT_QUEUE are kept; beyond, the oldest go). A stroke
 * whose stick never touched the head (it landed on a head coming at it faster than the
 * hit, which drew back before the stick reached it) ends without a report. */
int contact_take_report(contact *c, contact_report *report);
/* Hits waiting to land (the next one and those queued behind it). */
int contact_hits_waiting(const contact *c);
/* Stick state (m, m/s; positive into the membrane) and the last force (N). */
double contact_stick_position(const contact *c);
double contact_stick_velocity(const contact *c);
double contact_last_force(const contact *c);
/* The compression of the contact law (m): the stick's position less the head's over the
 * patch (modes and the static compliance of the modes left out, membrane.h). */
double contact_compression(const contact *c);
/* The static compliance of the modes left out at the stick's point (m/N; 0 on a
 * point-like or detached head): it stores residual_compliance F^2 / 2. */
double contact_residual_compliance(const contact *c);

/* Stick on a rigid, immovable target: the same contact law and discretisation
 * with no membrane. Simulates one stroke at sample_rate_hz and fills *report.
 * Returns 0 if it did not release within max_seconds. For tests against Hertz's
 * contact time. */
int contact_simulate_rigid(const contact *c, double velocity_mps, double sample_rate_hz,
                           double max_seconds, contact_report *report);

#ifdef __cplusplus
}
#endif
#endif
