/* bench_membrane.c -- cost of the modal membrane core per mode and sample.
 *
 * For N = 32, 256, 1024, 4096 modes (default head, 48 kHz, blocks of 64) it times
 * (a) free ringing after a strike and (b) a stick held in contact throughout
 * (10 kg on a soft tip, a fresh stroke before each timed run, which is shorter
 * than the stroke; the "touching" column shows the share of blocks with force > 0), with the
 * run-time selected kernel and with the generic one. Best of several repeats (clock_gettime,
 * CLOCK_MONOTONIC).
 *
 * Then the machine's memory floor for the kernel (docs/benchmarks.md): a loop that moves
 * what the kernel moves per mode and sample with a stick pressed -- 7 floats loaded (state
 * q, p; coefficients c1, cd, c3; the point's and the pickup's shapes), 2 stored -- with
 * only vector adds in between, over arrays allocated as the membrane allocates them. No
 * kernel that streams those arrays once per sample can beat it on this machine: it says
 * how much of the kernel's time is the cache's and how much the arithmetic's (measured
 * 0.39-0.50 ns at 1024 modes on a Zen 1 core, where a 256-bit load is two 128-bit ones;
 * docs/benchmarks.md).
 * Usage: bench_membrane_core [seconds]
 *        bench_membrane_core --floor MODES [seconds]   (the floor alone: one number, for
 *                                                       bench/peers/bench_peers.py) */
#define _POSIX_C_SOURCE 200112L
#include "contact.h"
#include "membrane.h"
#include "membrane_internal.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
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
    /* keep ringing: no denormal shortcut */
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_T60, 60.0);
    membrane_attach_contact(m, c);
    ictus_param_set(&contact_params, c, CONTACT_PARAM_MASS, 10.0);
    ictus_param_set(&contact_params, c, CONTACT_PARAM_STIFFNESS, 1.0e6);
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

/* ---------------------------------------------------------------- the memory floor */

enum { FLOOR_LOADS = 7, FLOOR_STORES = 2 };

#if defined(__x86_64__) && defined(__GNUC__)
#define FLOOR_TARGET __attribute__((target("avx2"), noinline))
#define FLOOR_WIDTH  8
#else
#define FLOOR_TARGET __attribute__((noinline))
#define FLOOR_WIDTH  4
#endif
typedef float floor_vec __attribute__((vector_size(4 * FLOOR_WIDTH)));

/* One pass over n modes: the kernel's loads and stores, adds only (no FMA-pipe work). */
static FLOOR_TARGET float floor_pass(float *const *a, int n)
{
    floor_vec acc = {0};
    for (int i = 0; i < n; i += FLOOR_WIDTH) {
        floor_vec q = *(floor_vec *)(a[0] + i), p = *(floor_vec *)(a[1] + i);
        floor_vec c1 = *(const floor_vec *)(a[2] + i), cd = *(const floor_vec *)(a[3] + i);
        floor_vec c3 = *(const floor_vec *)(a[4] + i), psi = *(const floor_vec *)(a[5] + i);
        floor_vec pick = *(const floor_vec *)(a[6] + i);
        *(floor_vec *)(a[0] + i) = q + c1 + cd;
        *(floor_vec *)(a[1] + i) = p + c3 + psi;
        acc += pick;
    }
    float s = 0.0f;
    for (int j = 0; j < FLOOR_WIDTH; j++)
        s += acc[j];
    return s;
}

static double cpu_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Best ns per mode-sample of floor_pass over `modes` modes, `samples` passes a run, in
 * CPU time (as bench/peers/bench_peers.py measures Pd: a busy machine's scheduler out). */
static double memory_floor(int modes, long samples, int repeats)
{
    float *a[FLOOR_LOADS];
    for (int j = 0; j < FLOOR_LOADS; j++) {
        void *ptr = NULL;
        if (posix_memalign(&ptr, 64, sizeof(float) * (size_t)modes) != 0) {
            fprintf(stderr, "bench_membrane_core: out of memory\n");
            exit(1);
        }
        memset(ptr, 0, sizeof(float) * (size_t)modes); /* zeros: no denormals, no overflow */
        a[j] = ptr;
    }
    double best = 1e30;
    volatile float sink = 0.0f;
    for (int r = 0; r < repeats; r++) {
        double t0 = cpu_now_s();
        for (long s = 0; s < samples; s++)
            sink += floor_pass(a, modes);
        double ns = (cpu_now_s() - t0) * 1e9 / ((double)samples * modes);
        if (ns < best)
            best = ns;
    }
    (void)sink;
    for (int j = 0; j < FLOOR_LOADS; j++)
        free(a[j]);
    return best;
}

int main(int argc, char **argv)
{
    if (argc > 2 && strcmp(argv[1], "--floor") == 0) {
        int modes = atoi(argv[2]);
        double sec = argc > 3 ? atof(argv[3]) : 0.2;
        if (modes < MEMBRANE_PAD || modes % MEMBRANE_PAD != 0 || !(sec > 0.0)) {
            fprintf(stderr,
                    "bench_membrane_core: --floor takes a mode count that is a positive "
                    "multiple of %d and a positive time, got %s\n",
                    MEMBRANE_PAD, argv[2]);
            return 2;
        }
        printf("%.4f\n", memory_floor(modes, (long)(sec * 48000.0) + 64, 7));
        return 0;
    }
    double seconds = argc > 1 ? atof(argv[1]) : 0.04;
    if (!(seconds > 0.0))
        seconds = 0.05;
    const int sizes[] = {32, 256, 1024, 4096}; /* multiples of MEMBRANE_PAD */
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
    printf("\nmemory floor: %d floats loaded and %d stored per mode and sample (a stick pressed),\n"
           "%d-float vectors, adds only: ns per mode per sample\n",
           FLOOR_LOADS, FLOOR_STORES, FLOOR_WIDTH);
    for (int i = 1; i < 4; i++) {
        long samples = (long)(seconds * 48000.0);
        if (samples < 64)
            samples = 64;
        printf("%-6d %12.3f\n", sizes[i], memory_floor(sizes[i], samples, 7));
    }
    return 0;
}
