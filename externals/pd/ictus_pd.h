/* ictus_pd.h -- private to the ictus Pd library (libictus_pd.so).
 *
 * membrane~ and contact~ live in one shared library so that contact~ can find
 * a membrane~ with pd_findbyclass() (the class pointer must be one and the
 * same), the way delread~ finds delwrite~. The tiny loader binaries
 * membrane~.pd_linux, contact~.pd_linux and ictus.pd_linux only call
 * ictus_pd_setup(), which is idempotent.
 *
 * Each object's struct is private to its file. contact~ uses membrane~ only
 * through the few functions below; membrane~ knows nothing of contact~ (it hosts
 * core contacts and calls back whoever attached them). docs/externals.md, "Layout".
 */
#ifndef ICTUS_PD_H
#define ICTUS_PD_H

#include "m_pd.h"
#include "contact.h"
#include "ictus_pd_common.h"

#include "ictus_export.h"

#define ICTUS_PD_VERSION "0.1.0"

/* Creates both classes once; later calls do nothing. Exported for the loaders. */
ICTUS_EXPORT void ictus_pd_setup(void);

extern t_class *ictus_membrane_tilde_class;
extern t_class *ictus_contact_tilde_class;

void ictus_membrane_tilde_setup(void);
void ictus_contact_tilde_setup(void);

/* ---------------- what membrane~ offers to objects that play it ---------------- */

typedef struct _membrane_tilde t_membrane_tilde;

/* Called when the membrane~ is deleted, after it has detached `owner`'s contact. */
typedef void (*t_ictus_gonefn)(void *owner);

/* Attaches core contact c, on behalf of owner (at most MEMBRANE_MAX_CONTACTS at
 * once); gone(owner) is called if the membrane~ is deleted first. Returns 1 when
 * attached (or already), 0 when the membrane~ is full or memory cannot be had. */
int ictus_membrane_tilde_attach(t_membrane_tilde *m, contact *c, void *owner, t_ictus_gonefn gone);
/* How many objects have a contact attached (the snare side's point is not counted). */
int ictus_membrane_tilde_contacts(const t_membrane_tilde *m);
/* Detaches owner's contact; does nothing when owner is not attached. */
void ictus_membrane_tilde_detach(t_membrane_tilde *m, void *owner);
/* The membrane~'s sample clock: messages that act on its core are timed by it. */
const t_ictus_clock *ictus_membrane_tilde_clock(const t_membrane_tilde *m);

#endif
