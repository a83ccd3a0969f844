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

/* The highest level this CPU (and its OS) runs, capped by the environment variable
 * ICTUS_MEMBRANE_KERNEL (generic, avx2 or avx512; any other value caps nothing), read
 * at each call: the objects made after it is set follow it. Does not allocate. */
ictus_simd ictus_simd_level(void);

/* "generic", "avx2+fma" or "avx512". */
const char *ictus_simd_name(ictus_simd level);

#ifdef __cplusplus
}
#endif

#endif
