/* ictus_export.h -- marks a Pd setup function as exported from its binary.
 *
 * The externals are built with hidden visibility; Pd finds a class by its
 * setup function's name, so each binary exports its setup functions and
 * nothing else.
 */
#ifndef ICTUS_EXPORT_H
#define ICTUS_EXPORT_H

#if defined(__GNUC__)
#define ICTUS_EXPORT __attribute__((visibility("default")))
#else
#define ICTUS_EXPORT
#endif

#endif /* ICTUS_EXPORT_H */
