/* ictus_param.c -- table-driven access to the core's one-number parameters
 * (ictus_param.h). */
#include "ictus_param.h"
#include "ictus_clamp.h"

#include <string.h>

static const ictus_param_def *param_def(const ictus_param_table *t, int id)
{
    return (id >= 0 && id < t->count) ? &t->def[id] : NULL;
}

ictus_status ictus_param_set(const ictus_param_table *t, void *obj, int id, double value)
{
    const ictus_param_def *d = param_def(t, id);
    if (!d)
        return ICTUS_CLAMPED;
    if (d->set)
        return d->set(obj, value);
    ictus_status s = ictus_clamp(&value, d->range.min, d->range.max, d->range.def);
    *(double *)((char *)obj + d->field) = value;
    return d->changed ? d->changed(obj, s) : s;
}

double ictus_param_get(const ictus_param_table *t, const void *obj, int id)
{
    const ictus_param_def *d = param_def(t, id);
    if (!d)
        return 0.0;
    return d->get ? d->get(obj) : *(const double *)((const char *)obj + d->field);
}

ictus_range ictus_param_range(const ictus_param_table *t, const void *obj, int id)
{
    const ictus_param_def *d = param_def(t, id);
    const ictus_range none = {0.0, 0.0, 0.0};
    if (!d)
        return none;
    return d->range_of ? d->range_of(obj) : d->range;
}

int ictus_param_find(const ictus_param_table *t, const char *name)
{
    for (int i = 0; i < t->count; i++)
        if (strcmp(t->def[i].name, name) == 0)
            return i;
    return -1;
}
