/* Portable build of the modal kernel (SSE2 on x86-64, whatever GCC targets elsewhere). */
#define KERNEL_NAME membrane_kernel_generic
#include "membrane_kernel.inc"
