/* bench_membrane.c -- cost of the modal membrane core per mode and sample.
 *
 * For N = 16, 256, 1024, 4096 modes (default head, 48 kHz, blocks of 64) it times
 * (a) free ringing after a strike and (b) a stick held in contact throughout
 * (10 kg on a soft tip, a fresh stroke before each timed run, which is shorter
 * than the stroke; the "touching" column shows the share of blocks with force > 0), with the
 * run-time selected kernel and with the generic one. Best of several repeats (clock_gettime,
 * CLOCK_MONOTONIC). Usage: bench_membrane_core [seconds] */
#define _POSIX_C_SOURCE 199309L
#include "contact.h"
#include "membrane.h"
#include "membrane_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define BLOCK 64

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Returns the best ns per mode-sample over `repeats` runs of `blocks` blocks. */
static double run(int modes, int with_contact, int generic, int blocks, int repeats,
                  double *contact_fraction, const char **kernel)
{
    membrane *m = membrane_new(48000.0);
    contact *c = contact_new();
    if (!m || !c) {
        fprintf(stderr, "bench_membrane_core: out of memory\n");
        exit(1);
    }
    if (generic)
        membrane_use_generic_kernel_(m);
    *kernel = membrane_kernel_name(m);
    membrane_set_modes(m, modes);
    membrane_set_t60(m, 60.0); /* keep ringing: no denormal shortcut */
    membrane_attach_contact(m, c);
    contact_set_mass(c, 10.0);
    contact_set_stiffness(c, 1.0e6);
    float o0[BLOCK], o1[BLOCK];
    float *out[2] = {o0, o1};
    membrane_strike(m, 0.3, 10.0, 0.01, 0);
    double best = 1e30;
    long touching = 0, total = 0;
    for (int r = 0; r < repeats; r++) {
        if (with_contact) {
            /* A fresh stroke before every timed run (untimed), landed and pressing:
             * 10 kg on the head stays in contact for ~0.1 s, longer than a run. */
            contact_hit(c, 0.3, 0.3, 0.0, 0);
            for (int b = 0; b < 4; b++)
                membrane_process(m, NULL, out, BLOCK);
        }
        double t0 = now_s();
        for (int b = 0; b < blocks; b++) {
            membrane_process(m, NULL, out, BLOCK);
            if (with_contact) {
                touching += contact_last_force(c) > 0.0;
                total++;
            }
        }
        double dt = now_s() - t0;
        double ns = dt * 1e9 / ((double)blocks * BLOCK * modes);
        if (ns < best)
            best = ns;
    }
    *contact_fraction = total ? (double)touching / total : 0.0;
    membrane_free(m);
    contact_free(c);
    return best;
}

int main(int argc, char **argv)
{
    double seconds = argc > 1 ? atof(argv[1]) : 0.04;
    if (!(seconds > 0.0))
        seconds = 0.05;
    const int sizes[] = {16, 256, 1024, 4096};
    printf("membrane~ core: ns per mode per sample (48 kHz, blocks of %d, best of 7)\n", BLOCK);
    printf("%-6s %-9s %12s %12s %10s\n", "modes", "kernel", "free", "contact", "touching");
    for (int generic = 0; generic <= 1; generic++) {
        for (int i = 0; i < 4; i++) {
            int modes = sizes[i];
            int blocks = (int)(seconds * 48000.0 / BLOCK);
            if (blocks < 1)
                blocks = 1;
            double frac = 0.0;
            const char *kernel = "";
            double ring = run(modes, 0, generic, blocks, 7, &frac, &kernel);
            double held = run(modes, 1, generic, blocks, 7, &frac, &kernel);
            printf("%-6d %-9s %12.3f %12.3f %9.0f%%\n", modes, kernel, ring, held, frac * 100.0);
        }
    }
    return 0;
}
