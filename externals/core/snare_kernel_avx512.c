/* AVX-512 build of the snare head's kernel (snare_kernel.inc, 16 floats per vector).
 * This file alone is compiled with the AVX-512 flags (externals/core/CMakeLists.txt);
 * snare_wires.c only selects it when ictus_simd_level() says the CPU has them. */
#define KERNEL_FREE  snare_kernel_free_avx512
#define KERNEL_FORCE snare_kernel_force_avx512
#define KERNEL_WIDTH 16
#include "snare_kernel.inc"
