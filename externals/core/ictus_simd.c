/* ictus_simd.c -- the run-time choice of the kernels' instruction set (ictus_simd.h). */
#include "ictus_simd.h"

#include <stdlib.h>
#include <string.h>

#if (defined(__x86_64__) || defined(__i386__)) && defined(__GNUC__) && !defined(ICTUS_NO_AVX2)
#define SIMD_X86 1
#endif

ictus_simd ictus_simd_cpu(void)
{
#ifdef SIMD_X86
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

/* AMD family 19h with AVX-512 (Zen 4; Zen 3 has none) runs a 512-bit operation as two
 * 256-bit halves: there the AVX-512 kernel measured 0.160 ns per mode-sample against
 * AVX2's 0.149 (docs/benchmarks.md), so AVX2 is preferred. Called only where
 * ictus_simd_cpu() found AVX-512, after its __builtin_cpu_init(). */
static int halves_512(void)
{
#ifdef SIMD_X86
    return __builtin_cpu_is("amdfam19h");
#else
    return 0;
#endif
}

ictus_simd ictus_simd_level(void)
{
    const ictus_simd level = ictus_simd_cpu();
    const char *want = getenv("ICTUS_MEMBRANE_KERNEL");
    if (want && strcmp(want, "generic") == 0)
        return ICTUS_SIMD_GENERIC;
    if (want && strcmp(want, "avx512") == 0) /* the widest the CPU has, wherever */
        return level;
    if (level == ICTUS_SIMD_AVX512 && ((want && strcmp(want, "avx2") == 0) || halves_512()))
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
