/* AVX2 + FMA build of the cascade's potential. This file alone is compiled with
 * -mavx2 -mfma (externals/core/CMakeLists.txt); plate_cascade_build() only selects it
 * when __builtin_cpu_supports says the CPU has both. */
#define CASCADE_POTENTIAL_NAME plate_cascade_potential_avx2
#define CASCADE_WIDTH          8
#include "plate_cascade_kernel.inc"
