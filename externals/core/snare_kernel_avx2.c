/* AVX2 + FMA build of the snare head's kernel (snare_kernel.inc). This file alone is
 * compiled with -mavx2 -mfma (externals/core/CMakeLists.txt); snare_wires.c only selects
 * it when ictus_simd_level() says so (the CPU has both). */
#define KERNEL_FREE  snare_kernel_free_avx2
#define KERNEL_FORCE snare_kernel_force_avx2
#include "snare_kernel.inc"
