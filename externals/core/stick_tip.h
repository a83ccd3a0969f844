/* stick_tip.h -- the stick-head contact law and the table of stick tips, plain C99.
 *
 * One law for the sound (contact~, contact.c) and the physics (the daemon's
 * stick-drum contact, daemon/src/sim): with the compression x (m, positive when
 * the tip presses into the head) and its rate dx/dt (m/s),
 *     F = k x^alpha + lambda x^alpha dx/dt     for x > 0, else 0, and F >= 0
 * (Hertz's power law with Hunt & Crossley's damping; lambda in N s / m^(alpha+1),
 * mu = lambda / k in s/m). stick_tip_force() is that law; contact.c integrates
 * it with an energy-consistent discretisation of the same terms (contact.h).
 *
 * The tips (docs/sound.md, "Stick tips", has the sources and the arithmetic):
 *   wood   hickory bead (radius 7 mm) on a Mylar head: Hertz sphere on a half-space
 *   nylon  nylon 6/6 bead (radius 7 mm) on Mylar: the same formula
 *   felt   a felt mallet: the power law of hammer felt (Chaigne & Askenfelt 1994)
 * Header only (static inline), so that C and C++ callers compile the same code
 * without linking the DSP core. */
#ifndef ICTUS_STICK_TIP_H
#define ICTUS_STICK_TIP_H

#include <math.h>
#include <stddef.h>
#include <string.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct stick_tip {
    const char *name;
    double alpha;     /* exponent of the power law */
    double stiffness; /* k, N/m^alpha */
    double mu;        /* lambda / k, s/m (Hunt-Crossley) */
    double mass_kg;   /* the stick's (or mallet's) effective mass at the tip */
} stick_tip;

/* Hertz stiffness of a sphere of radius r (m) on a flat half-space:
 * k = (4/3) E* sqrt(r), 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 (Johnson,
 * Contact Mechanics, 1985, eq. 4.22). Moduli in Pa. */
static inline double stick_tip_hertz_k(double e1, double nu1, double e2, double nu2, double r)
{
    return 4.0 / 3.0 / ((1.0 - nu1 * nu1) / e1 + (1.0 - nu2 * nu2) / e2) * sqrt(r);
}

/* The material constants behind the table (docs/sound.md, "Stick tips"). */
#define STICK_TIP_RADIUS_M   0.007 /* a snare stick's bead */
#define STICK_TIP_MYLAR_E    4.9e9 /* Pa, PET film (DuPont Teijin, Mylar datasheet) */
#define STICK_TIP_MYLAR_NU   0.38
#define STICK_TIP_HICKORY_E  14.9e9 /* Pa, shagbark hickory (USDA Wood Handbook, 2010) */
#define STICK_TIP_HICKORY_NU 0.30
#define STICK_TIP_NYLON_E    2.8e9 /* Pa, nylon 6/6, dry */
#define STICK_TIP_NYLON_NU   0.39

#define STICK_TIP_COUNT   3
#define STICK_TIP_DEFAULT 0 /* wood */

/* The table, in the order wood, nylon, felt (stick_tip.c). */
extern const stick_tip stick_tips[STICK_TIP_COUNT];

/* The tip called name, or NULL. */
static inline const stick_tip *stick_tip_find(const char *name)
{
    for (int i = 0; name && i < STICK_TIP_COUNT; i++)
        if (strcmp(stick_tips[i].name, name) == 0)
            return &stick_tips[i];
    return NULL;
}

/* The law: force (N) for compression x (m) and its rate xdot (m/s). */
static inline double stick_tip_force(double k, double alpha, double lambda, double x, double xdot)
{
    if (!(x > 0.0))
        return 0.0;
    double xa = pow(x, alpha);
    double f = xa * (k + lambda * xdot);
    return f > 0.0 ? f : 0.0;
}

#ifdef __cplusplus
}
#endif
#endif
