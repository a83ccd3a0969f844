/* Portable build of the snare head's kernel (SSE2 on x86-64). */
#define KERNEL_FREE  snare_kernel_free_generic
#define KERNEL_FORCE snare_kernel_force_generic
#define KERNEL_WIDTH 4
#include "snare_kernel.inc"
