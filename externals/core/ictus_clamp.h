/* ictus_clamp.h -- private to the core: the one clamping rule of every setter
 * (membrane, contact, the parameter tables of ictus_param.c). */
#ifndef ICTUS_CLAMP_H
#define ICTUS_CLAMP_H

#include <math.h>

#include "ictus_param.h"

/* Clamps *v into [lo, hi]; NaN becomes `fallback`. ICTUS_CLAMPED when *v changed.
 * Every setter of the core validates through this one rule. */
static inline ictus_status ictus_clamp(double *v, double lo, double hi, double fallback)
{
    if (isnan(*v)) {
        *v = fallback;
        return ICTUS_CLAMPED;
    }
    if (*v < lo) {
        *v = lo;
        return ICTUS_CLAMPED;
    }
    if (*v > hi) {
        *v = hi;
        return ICTUS_CLAMPED;
    }
    return ICTUS_OK;
}

/* A force (N) from outside into the audio loop (membrane_process's force_in):
 * NaN and +-inf become 0, finite values beyond +-cap are clamped to it. One test
 * and a min and a max per sample, no allocation. */
static inline float ictus_clamp_force(float f, float cap)
{
    if (!isfinite(f))
        return 0.0f;
    return fminf(fmaxf(f, -cap), cap);
}

#endif
