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
 * The tips (docs/contact.md, "Stick tips", has the sources and the arithmetic):
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

#include "ictus_name.h"

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

/* The material constants behind the table (docs/contact.md, "Stick tips"). */
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

/* The tip called name, in any casing ("Wood", "WOOD"), or NULL. */
static inline const stick_tip *stick_tip_find(const char *name)
{
    for (int i = 0; name && i < STICK_TIP_COUNT; i++)
        if (ictus_name_equal(stick_tips[i].name, name))
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

/* The head's point stiffness with its stretching: a clamped circular membrane of
 * pre-tension T under a central point load deflects y (m) with
 *     F_head(y) = k1 y + k3 y^3,   k3 = E h q^3 / a^2,   q = 1 / (1.05 - 0.15 nu - 0.16 nu^2)
 * (large-deflection membrane under a point load: Begley & Mackin, J. Mech. Phys.
 * Solids 52, 2004, 2005-2023; the form used by Lee, Wei, Kysar & Hone, Science 321,
 * 2008, 385). E (Pa), nu, thickness h (m), radius a (m); k1 is the linear point
 * stiffness the caller has (2 pi T / ln(a / r_tip)). Returns k3 in N/m^3. */
static inline double stick_tip_head_k3(double e, double nu, double thickness_m, double radius_m)
{
    double q = 1.0 / (1.05 - 0.15 * nu - 0.16 * nu * nu);
    return e * thickness_m * q * q * q / (radius_m * radius_m);
}

/* The default head's stretching (N/m^3): a 14-inch Mylar head, radius 0.178 m,
 * 0.262 kg/m^2 over PET's 1390 kg/m^3 = 0.188 mm thick, E 4.5 GPa, nu 0.38 (the
 * film constants membrane.h's tension modulation uses): 2.93e7 N/m^3. The
 * physics' default drum (DrumParams) has the same. */
#define STICK_TIP_HEAD_K3_DEFAULT (stick_tip_head_k3(4.5e9, 0.38, 0.262 / 1390.0, 0.178))

/* The tip's law k x^alpha in series with the head's F_head(y) = k1 y + k3 y^3 at a
 * total depth d = x + y (m): both carry the same force. Returns that force (N) and,
 * when head_y is not NULL, the head's share y (m). k <= 0: the head alone. The root
 * of g(y) = k1 y + k3 y^3 - k (d - y)^alpha, increasing on [0, d], by Newton's
 * method kept inside its bracket (bisection where it leaves it). */
static inline double stick_tip_series_force(double k, double alpha, double k1, double k3, double d,
                                            double *head_y)
{
    double y = d;
    if (!(d > 0.0)) {
        y = 0.0;
    } else if (k > 0.0) {
        double lo = 0.0, hi = d;
        y = d * 0.5;
        for (int it = 0; it < 100; it++) {
            double x = d - y;
            double xa = x > 0.0 ? pow(x, alpha) : 0.0;
            double g = k1 * y + k3 * y * y * y - k * xa;
            double dg = k1 + 3.0 * k3 * y * y + (x > 0.0 ? k * alpha * xa / x : 0.0);
            if (g > 0.0)
                hi = y;
            else
                lo = y;
            double next = dg > 0.0 ? y - g / dg : 0.5 * (lo + hi);
            if (!(next > lo && next < hi))
                next = 0.5 * (lo + hi);
            if (fabs(next - y) <= 1.0e-14 * d || hi - lo <= 1.0e-14 * d) {
                y = next;
                break;
            }
            y = next;
        }
    }
    if (head_y)
        *head_y = y;
    return y > 0.0 ? k1 * y + k3 * y * y * y : 0.0;
}

#ifdef __cplusplus
}
#endif
#endif
