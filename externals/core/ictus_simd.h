/* ictus_simd.h -- which instruction set the DSP kernels run (membrane.c, snare_wires.c,
 * plate_cascade.c). Each kernel is compiled once per level (externals/core/CMakeLists.txt)
 * and chosen at run time, so the library loads on any x86-64. Not part of the API. */
#ifndef ICTUS_SIMD_H
#define ICTUS_SIMD_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum ictus_simd {
    ICTUS_SIMD_GENERIC = 0, /* portable: SSE2 on x86-64 */
    ICTUS_SIMD_AVX2 = 1,    /* AVX2 + FMA, 8 floats per vector */
    ICTUS_SIMD_AVX512 = 2   /* AVX-512 F/DQ/BW/VL + FMA, 16 floats per vector */
} ictus_simd;

/* The level the kernels run at: the highest this CPU (and its OS) runs, except AVX2 on
 * AMD family 19h (Zen 4 splits each 512-bit operation in two: AVX2 is faster there).
 * The environment variable ICTUS_MEMBRANE_KERNEL, read at each call (the objects made
 * after it is set follow it), overrides: generic; avx2 (at most); avx512 (the highest
 * the CPU runs, Zen 4 included). Does not allocate. */
ictus_simd ictus_simd_level(void);

/* The highest level this CPU and its OS run, whatever is preferred or asked for (tests
 * compare every copy the CPU can run). */
ictus_simd ictus_simd_cpu(void);

/* "generic", "avx2+fma" or "avx512". */
const char *ictus_simd_name(ictus_simd level);

#ifdef __cplusplus
}
#endif

#endif
