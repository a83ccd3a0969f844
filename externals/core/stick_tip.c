/* stick_tip.c -- the table of stick tips (stick_tip.h; sources in docs/contact.md,
 * "Stick tips"). */
#include "stick_tip.h"

/* Hunt-Crossley mu = lambda / k from a coefficient of restitution e at impact
 * speed v: mu ~ 3 (1 - e) / (2 v) for e near 1 (Hunt & Crossley 1975; Marhefka &
 * Orin 1999). wood and nylon: e ~ 0.8 at 1 m/s on the tip's own material, mu 0.3;
 * felt: its hysteresis (Stulov 1995) as mu 0.6. */
const stick_tip stick_tips[STICK_TIP_COUNT] = {
    /* name, alpha, k (N/m^alpha), mu (s/m), mass (kg) */
    {"wood", 1.5, 4.73e8, 0.3, 0.05},
    {"nylon", 1.5, 2.34e8, 0.3, 0.05},
    {"felt", 2.5, 4.5e9, 0.6, 0.03},
};
