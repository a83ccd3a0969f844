/* AVX-512 build of the modal kernel (16 floats per vector). This file alone is compiled
 * with -mavx512f -mavx512dq -mavx512bw -mavx512vl -mfma (externals/core/CMakeLists.txt);
 * membrane_new() only selects it when ictus_simd_level() says the CPU has them. */
#define KERNEL_NAME           membrane_kernel_avx512
#define KERNEL_PAIR_NAME      membrane_kernel_pair_avx512
#define KERNEL_TENSION_NAME   membrane_tension_kernel_avx512
#define KERNEL_COUPLINGS_NAME membrane_couplings_kernel_avx512
#define KERNEL_ENERGY_NAME    membrane_energy_kernel_avx512
#define KERNEL_WIDTH          16
#include "membrane_kernel.inc"
