/* Portable build of the cascade's potential (SSE2 on x86-64). */
#define CASCADE_POTENTIAL_NAME plate_cascade_potential_generic
#define CASCADE_WIDTH          4 /* SSE2 registers */
#include "plate_cascade_kernel.inc"
