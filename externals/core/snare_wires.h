/* snare_wires.h -- snare wires against a membrane: a few lumped masses, each held by
 * a spring and a damper (the strainer's pull) and colliding one-sidedly with the head
 * under a power law, F = k [w_head - y_wire]+^alpha, solved implicitly each sample as
 * an energy-consistent discrete gradient (as contact.c; Torin, Hamilton & Bilbao,
 * DAFx-14). The collisions give the snare's buzz (docs/sound.md, "Snare wires").
 * Plain C99, no Pd.
 *
 * The wires lie on the head the membrane models (one head: in a real snare drum they
 * lie under the resonant head, coupled to the batter through the shell's air; that
 * second head is not modelled). Each mass is one of the membrane's coupling points
 * (MEMBRANE_MAX_POINTS in all, with the sticks). Threading: as membrane.h. */
#ifndef ICTUS_SNARE_WIRES_H
#define ICTUS_SNARE_WIRES_H

#include "membrane.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SNARE_WIRES_MASSES 2

typedef struct snare_wires snare_wires;

/* Wires at rest, detached. Allocates; NULL when memory cannot be had. */
snare_wires *snare_wires_new(void);
/* Detaches them if attached, and frees them. */
void snare_wires_free(snare_wires *w);
/* Lays the wires on m (detaching them from another membrane first): the masses start at
 * rest touching the head. ICTUS_ENOMEM when m has no room for SNARE_WIRES_MASSES more
 * coupling points or memory cannot be had (nothing attached). Allocates. */
ictus_status snare_wires_attach(snare_wires *w, membrane *m);
/* Lifts them off their membrane (no-op when detached). */
void snare_wires_detach(snare_wires *w);
/* The membrane they lie on, or NULL. */
membrane *snare_wires_membrane(const snare_wires *w);
/* Kinetic and potential energy of the masses (springs and collisions), J. */
double snare_wires_energy(const snare_wires *w);
/* Collisions so far (samples in which a mass was in contact), for tests. */
long snare_wires_contact_samples(const snare_wires *w);

#ifdef __cplusplus
}
#endif
#endif
