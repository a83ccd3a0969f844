/* Portable build of the modal kernel (SSE2 on x86-64, whatever GCC targets elsewhere). */
#define KERNEL_NAME      membrane_kernel_generic
#define KERNEL_PAIR_NAME membrane_kernel_pair_generic
#define KERNEL_TENSION_NAME membrane_tension_kernel_generic
#define KERNEL_COUPLINGS_NAME membrane_couplings_kernel_generic
#define KERNEL_ENERGY_NAME  membrane_energy_kernel_generic
#define KERNEL_WIDTH     4 /* SSE2 registers */
#include "membrane_kernel.inc"
