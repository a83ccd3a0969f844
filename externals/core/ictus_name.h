/* ictus_name.h -- how the core matches the names of its tables (membrane presets,
 * stick tips): in any casing, as ictusd's command line and OSC take words ("Snare",
 * "SNARE" and "snare" are one preset). ASCII letters only: every name is ASCII.
 * Header only (static inline), for C and C++ callers alike. */
#ifndef ICTUS_NAME_H
#define ICTUS_NAME_H

#ifdef __cplusplus
extern "C" {
#endif

/* 1 when a and b spell the same name, ignoring the case of ASCII letters; 0 otherwise
 * (also when either is NULL). */
static inline int ictus_name_equal(const char *a, const char *b)
{
    if (!a || !b)
        return 0;
    for (;; a++, b++) {
        unsigned char ca = (unsigned char)*a, cb = (unsigned char)*b;
        if (ca >= 'A' && ca <= 'Z')
            ca = (unsigned char)(ca - 'A' + 'a');
        if (cb >= 'A' && cb <= 'Z')
            cb = (unsigned char)(cb - 'A' + 'a');
        if (ca != cb)
            return 0;
        if (!ca)
            return 1;
    }
}

#ifdef __cplusplus
}
#endif
#endif
