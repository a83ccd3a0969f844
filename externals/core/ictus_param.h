/* ictus_param.h -- the one-number parameters of a core object (membrane, contact) as
 * a table: each entry names the parameter, its unit and its range, and says where
 * the object keeps it. One setter, getter and range serve every entry of every
 * table; the Pd wrappers turn the names into messages (externals/pd/ictus_pd_common.h). */
#ifndef ICTUS_PARAM_H
#define ICTUS_PARAM_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Result of a setter: the value was taken as given, clamped into range (the
 * clamped value can be read back with the matching getter), or refused
 * because memory could not be had (state unchanged). NaN counts as out of
 * range and is replaced by the parameter's default. */
typedef enum {
    ICTUS_OK = 0,      /* taken as given */
    ICTUS_CLAMPED = 1, /* clamped or NaN replaced (also: no such pickup, strike queue full) */
    ICTUS_ENOMEM = 2   /* refused: memory could not be had, state unchanged */
} ictus_status;

/* A parameter's legal range and its default, in the units of its setter. */
typedef struct ictus_range {
    double min, max, def;
} ictus_range;

typedef struct ictus_param_def {
    const char *name;  /* the Pd message that sets it, and its name in errors */
    const char *unit;  /* SI, "" for none */
    ictus_range range; /* the setter clamps into it (NaN: the default) */
    size_t field;      /* offset of the double the object keeps it in (when get is NULL) */
    /* Optional: runs after the field is stored, with the clamp's status; returns the
     * setter's status (e.g. recomputing the membrane's coefficients). */
    ictus_status (*changed)(void *obj, ictus_status s);
    /* Optional, for a parameter that is not one double field: set, get and range. */
    ictus_status (*set)(void *obj, double value);
    double (*get)(const void *obj);
    ictus_range (*range_of)(const void *obj);
} ictus_param_def;

typedef struct ictus_param_table {
    const ictus_param_def *def; /* indexed by the object's parameter enum */
    int count;
} ictus_param_table;

/* Sets parameter id of obj (clamped into its range, and said so: ICTUS_CLAMPED). An
 * unknown id does nothing and returns ICTUS_CLAMPED. */
ictus_status ictus_param_set(const ictus_param_table *t, void *obj, int id, double value);
/* Its value (0 for an unknown id). */
double ictus_param_get(const ictus_param_table *t, const void *obj, int id);
/* The range its setter clamps into now (empty for an unknown id). */
ictus_range ictus_param_range(const ictus_param_table *t, const void *obj, int id);
/* The id of the entry named `name`, or -1. */
int ictus_param_find(const ictus_param_table *t, const char *name);

#ifdef __cplusplus
}
#endif
#endif
