/* AVX2 + FMA build of the modal kernel. This file alone is compiled with
 * -mavx2 -mfma (externals/core/CMakeLists.txt); membrane_new() only selects it
 * when ictus_simd_level() says so (the CPU has both). */
#define KERNEL_NAME      membrane_kernel_avx2
#define KERNEL_PAIR_NAME membrane_kernel_pair_avx2
#define KERNEL_TENSION_NAME membrane_tension_kernel_avx2
#define KERNEL_COUPLINGS_NAME membrane_couplings_kernel_avx2
#define KERNEL_ENERGY_NAME  membrane_energy_kernel_avx2
#include "membrane_kernel.inc"
