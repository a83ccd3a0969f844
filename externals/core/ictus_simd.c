/* ictus_simd.c -- the run-time choice of the kernels' instruction set (ictus_simd.h). */
#include "ictus_simd.h"

#include <stdlib.h>
#include <string.h>

static ictus_simd cpu_level(void)
{
#if (defined(__x86_64__) || defined(__i386__)) && defined(__GNUC__) && !defined(ICTUS_NO_AVX2)
    /* libgcc's checks include the OS's (XCR0): a CPU whose OS does not save the
     * registers reports the feature absent. */
    __builtin_cpu_init();
    if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma"))
        return ICTUS_SIMD_GENERIC;
    if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
        __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl"))
        return ICTUS_SIMD_AVX512;
    return ICTUS_SIMD_AVX2;
#else
    return ICTUS_SIMD_GENERIC; /* the other kernels are built for x86-64 only */
#endif
}

ictus_simd ictus_simd_level(void)
{
    ictus_simd level = cpu_level();
    const char *want = getenv("ICTUS_MEMBRANE_KERNEL");
    if (want && strcmp(want, "generic") == 0)
        return ICTUS_SIMD_GENERIC;
    if (want && strcmp(want, "avx2") == 0 && level > ICTUS_SIMD_AVX2)
        return ICTUS_SIMD_AVX2;
    return level;
}

const char *ictus_simd_name(ictus_simd level)
{
    switch (level) {
    case ICTUS_SIMD_AVX512:
        return "avx512";
    case ICTUS_SIMD_AVX2:
        return "avx2+fma";
    default:
        return "generic";
    }
}
