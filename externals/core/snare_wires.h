/* snare_wires.h -- the snare side of a snare drum, coupled to a membrane (the batter):
 * the snare (resonant) head, the air enclosed by the shell between the two heads, and
 * the snare wires colliding with the snare head (docs/sound.md, "The snare"). Plain C99,
 * no Pd.
 *
 * - The snare head is a modal membrane of its own (thinner than the batter, tuned
 *   higher), with the modes to SNARE_HEAD_F_MAX that the wires and the air can excite
 *   (the cos(m theta) partners about the wires' line).
 * - The air is a lumped spring between the two heads' mean displacements (their volume
 *   displacements over the head's area): k = rho c^2 A / H for a shell of depth H. On
 *   the batter it acts through one coupling point whose shapes are each mode's mean
 *   over the head (a uniform pressure), so the batter's modes see it exactly as the
 *   membrane sees a stick.
 * - The wires are SNARE_WIRE_SEGMENTS light masses lying end to end along a diameter of
 *   the snare head, each meeting the head's mean displacement along its length, held by
 *   the wire's tension and colliding one-sidedly with the head under a
 *   power law, F = k [w_head - y_wire]+^alpha, solved implicitly each sample as an
 *   energy-consistent discrete gradient (Torin, Hamilton & Bilbao, DAFx-14).
 * The pickups hear both heads: the batter's pickups plus the snare head's velocity at
 * its own pickup points.
 *
 * Threading: as membrane.h; the snare advances inside membrane_process() of the
 * batter it is attached to (one coupling point), never allocating there. */
#ifndef ICTUS_SNARE_WIRES_H
#define ICTUS_SNARE_WIRES_H

#include "membrane.h"

#ifdef __cplusplus
extern "C" {
#endif

#define SNARE_WIRE_SEGMENTS 8       /* snare_step() sums over eight at once */
#define SNARE_POINTS        1       /* coupling points taken on the batter */
#define SNARE_HEAD_F_MAX    10000.0 /* Hz, at most 0.4 x the sample rate */

typedef struct snare_wires snare_wires;

/* The snare side at rest, wires engaged, detached. Allocates; NULL when memory cannot
 * be had. */
snare_wires *snare_wires_new(void);
/* Detaches it if attached, and frees it. */
void snare_wires_free(snare_wires *w);
/* Puts the snare side under batter m (detaching it from another membrane first), at
 * m's sample rate and radius: the heads and the wires start at rest. ICTUS_ENOMEM when
 * m has no room for SNARE_POINTS more coupling points or memory cannot be had (nothing
 * attached). Allocates. */
ictus_status snare_wires_attach(snare_wires *w, membrane *m);
/* Takes it from under its membrane (no-op when detached). */
void snare_wires_detach(snare_wires *w);
/* The membrane it is attached to, or NULL. */
membrane *snare_wires_membrane(const snare_wires *w);
/* Wires on the snare head (1) or lifted off it by the strainer (0); the two heads
 * stay coupled either way. Lifted wires come to rest at once; engaged again, they lie
 * on the head where it is. Message time. */
void snare_wires_engage(snare_wires *w, int on);
int snare_wires_engaged(const snare_wires *w);
/* Energy of the snare side (J): the snare head's modes, the air spring, the wires. */
double snare_wires_energy(const snare_wires *w);
/* Samples in which some wire segment touched the head, for tests. */
long snare_wires_contact_samples(const snare_wires *w);
/* The snare head: its mode count, and its (0, 1) frequency alone (Hz). */
int snare_wires_head_modes(const snare_wires *w);
double snare_wires_head_f01(const snare_wires *w);
/* The air spring between the heads' mean displacements, N/m. */
double snare_wires_air_stiffness(const snare_wires *w);

#ifdef __cplusplus
}
#endif
#endif
