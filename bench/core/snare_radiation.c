/* snare_radiation.c -- what a far-field microphone hears of the snare preset, against
 * the pickups (docs/sound.md, "The snare"). A measurement, not a test: it prints the
 * 95 % bandwidth of the first 50 ms of one stroke (a 50 g stick at 2.5 m/s, r/a 0.3,
 * through the contact, 48 kHz), wires on and off, for pickup 1 and for the pressure
 * radiated by each head into its half-space, at elevations phi from the head's axis.
 *
 * The pressure is the Rayleigh integral of a baffled head in the far field,
 *     p(R, phi, theta_m, t) = rho / (2 pi R) * integral of a(r_s, t - R/c + r_s.u / c) dS,
 * with each mode's share evaluated at its own frequency (the modes ring at it):
 *     integral of psi e^{i k r_s.u} dS = 2 pi N i^m ang(m theta_m) a^2 j J_{m+1}(j) J_m(beta a)
 *                                         / (j^2 - (beta a)^2),  beta = (w / c) sin(phi)
 * (Jacobi-Anger over theta, Lommel's integral over r, J_m(j) = 0). rho / (2 pi R) and
 * the delay R / c are left out. Even m: a real weight on the mode's acceleration, the
 * first difference of its velocity (so the forces of the sample are in it); odd m: i
 * times the acceleration, which for a ringing mode is -w v. The microphone lies at
 * theta_m = 90 degrees from the wires' line and from the strike's radius, where the
 * cos(m theta) modes of odd m cancel by symmetry.
 *
 * It reads the snare head's modes, so it includes snare_wires.c (the library's copy is
 * not linked). Run: build/bench/core/bench_snare_radiation [velocity].
 *
 * `bench_snare_radiation tom` asks the expression ladder's question of the same microphone
 * (docs/sound.md, "Expression"): the `tom` preset struck by a 13.8 g stick at r/a 0.33 with
 * the head's stretching (the Begley & Mackin k3 of its Mylar, stick_tip.h) at the ladder's
 * impact speeds; it prints the spectral centroid of the first 50 ms (Hann window) of each
 * pickup and of the batter's pressure at each elevation. */
#include "snare_wires.c"
#include "contact.h"
#include "membrane_presets.h"
#include "stick_tip.h"
#include "ictus_param.h"

#include <stdio.h>

#define SR        48000.0
#define SAMPLES   2400 /* 50 ms */
#define NPHI      5
#define C_AIR     MEMBRANE_AIR_C
#define MIC_THETA (0.5 * M_PI)
static const double phis[NPHI] = {0.0, 30.0, 45.0, 60.0, 85.0};

/* Mode (m, j) of mass-normalised amplitude nphys, angular factor ang, at w rad/s: its
 * weight (on the acceleration for even m, on the velocity for odd m). */
static double weight(int m, double j, double nphys, double a, double w, double phi_deg, double ang)
{
    const double ba = w / C_AIR * sin(phi_deg * M_PI / 180.0) * a;
    const double integral = a * a * j * jn(m + 1, j) * jn(m, ba) / (j * j - ba * ba);
    const int quarter = m % 2 == 0 ? m / 2 : (m - 1) / 2; /* i^m = (-1)^quarter (times i, odd m) */
    const double s = 2.0 * M_PI * nphys * integral * ang * (quarter % 2 ? -1.0 : 1.0);
    return m % 2 ? -w * s : s;
}

/* Frequency below which 95 % of the periodogram of x[0 .. n) lies (plain DFT), and the
 * share of the energy at or above 4 kHz. */
static double bandwidth95(const double *x, int n, double *above4k)
{
    static double p[SAMPLES / 2 + 1];
    double total = 0.0, high = 0.0, cum = 0.0;
    for (int k = 0; k <= n / 2; k++) {
        double re = 0.0, im = 0.0;
        for (int i = 0; i < n; i++) {
            const double ph = -2.0 * M_PI * (double)((long)k * i % n) / n;
            re += x[i] * cos(ph), im += x[i] * sin(ph);
        }
        p[k] = re * re + im * im;
        total += p[k];
        high += k * SR / n >= 4000.0 ? p[k] : 0.0;
    }
    *above4k = high / total;
    for (int k = 0; k <= n / 2; k++)
        if ((cum += p[k]) >= 0.95 * total)
            return k * SR / n;
    return SR / 2;
}

/* The snare head's weights, slot by slot (its modes listed again as build_head does). */
static void head_weights(snare_wires *w, double phi, double *W)
{
    const double a = w->radius, c01 = 2.0 * M_PI * a * HEAD_F01 / ictus_bessel_zero(0, 1);
    const int n = list_modes(c01, a, fmin(SNARE_HEAD_F_MAX, 0.4 * w->sr), NULL, NULL, 0);
    int *mm = malloc(sizeof(int) * (size_t)n), next[3] = {0, w->ka.n0, w->ka.ne};
    double *jj = malloc(sizeof(double) * (size_t)n);
    list_modes(c01, a, fmin(SNARE_HEAD_F_MAX, 0.4 * w->sr), mm, jj, n);
    memset(W, 0, sizeof(double) * (size_t)w->n);
    for (int k = 0; k < n; k++) {
        const int slot = next[mm[k] == 0 ? 0 : (mm[k] % 2 == 0 ? 1 : 2)]++;
        const double nphys = sqrt((mm[k] ? 2.0 : 1.0) / M_PI) /
                             fabs(ictus_bessel_j(mm[k] + 1, jj[k])) / sqrt(HEAD_DENSITY * a * a);
        W[slot] = weight(mm[k], jj[k], nphys, a, w->om[slot], phi, cos(mm[k] * MIC_THETA));
    }
    free(mm), free(jj);
}

/* The batter's weights W[f * modes + k] for the microphone at each elevation phis[f]. */
static double *batter_weights(const membrane *m)
{
    const double a = m->radius, cm = sqrt(m->tension / m->density);
    double *W = calloc((size_t)m->modes * NPHI, sizeof(double));
    for (int f = 0; f < NPHI; f++)
        for (int k = 0; k < m->modes; k++) {
            const int mk = m->table.m[k];
            const double ang = m->table.sin[k] ? sin(mk * MIC_THETA) : cos(mk * MIC_THETA);
            W[f * m->modes + k] = weight(mk, m->table.j[k], m->mass_scale * m->table.norm[k], a,
                                         m->table.j[k] * cm / a, phis[f], ang);
        }
    return W;
}

/* The batter's pressure at each elevation for the sample just processed, into out[f];
 * prev[f] keeps the even modes' weighted velocity for the difference. Displacements
 * grow downwards: the batter radiates up (-a). */
static void batter_pressure(const membrane *m, const double *W, double *prev, double *out)
{
    for (int f = 0; f < NPHI; f++) {
        double se = 0.0, so = 0.0;
        for (int k = 0; k < m->modes; k++) {
            double u = 0.0; /* the forces of the sample, not yet in the state */
            for (int q = 0; q < m->point_count; q++)
                u += m->points[q]->force_pending * m->points[q]->psi[k];
            const double v = (double)m->sc[k] * m->p[k] + (double)m->ep[k] * u;
            if (m->table.m[k] % 2)
                so += W[f * m->modes + k] * v;
            else
                se += W[f * m->modes + k] * v;
        }
        out[f] = -((se - prev[f]) * SR + so);
        prev[f] = se;
    }
}

static void stroke(int wires, double velocity)
{
    membrane *m = membrane_new(SR);
    membrane_apply_preset(m, membrane_preset_find("snare"));
    snare_wires *w = snare_wires_new();
    snare_wires_attach(w, m);
    snare_wires_engage(w, wires);
    contact *c = contact_new();
    membrane_attach_contact(m, c);
    contact_hit_mass(c, velocity, 0.3, 0.0, 0, 0.05);
    double *Wb = batter_weights(m);
    double *Ws = calloc((size_t)w->n * NPHI, sizeof(double));
    for (int f = 0; f < NPHI; f++)
        head_weights(w, phis[f], Ws + f * w->n);
    static double pick[SAMPLES], top[NPHI][SAMPLES], bottom[NPHI][SAMPLES];
    double prev_top[NPHI] = {0}, prev_bottom[NPHI] = {0};
    for (int i = 0; i < SAMPLES; i++) {
        float o0, o1, *o[2] = {&o0, &o1};
        membrane_process(m, NULL, o, 1);
        pick[i] = o0;
        double p[NPHI];
        batter_pressure(m, Wb, prev_top, p);
        for (int f = 0; f < NPHI; f++) {
            double te = 0.0, to = 0.0;
            for (int k = 0; k < w->n; k++) {
                if (k >= w->ka.ne)
                    to += Ws[f * w->n + k] * w->v[k];
                else
                    te += Ws[f * w->n + k] * w->v[k];
            }
            /* Displacements grow downwards: the snare head radiates down (+a). */
            top[f][i] = p[f];
            bottom[f][i] = (te - prev_bottom[f]) * SR + to;
            prev_bottom[f] = te;
        }
    }
    double h;
    int first = 0;
    while (first < SAMPLES && pick[first] == 0.0)
        first++;
    printf("wires %s: pickup 1 %.0f Hz", wires ? "on " : "off", bandwidth95(pick, SAMPLES, &h));
    printf(" (%.2f %% above 4 kHz; first sample %d)\n", 100.0 * h, first);
    for (int f = 0; f < NPHI; f++) {
        double both[SAMPLES], ht, hb, hs;
        for (int i = 0; i < SAMPLES; i++)
            both[i] = top[f][i] + bottom[f][i];
        const double bt = bandwidth95(top[f], SAMPLES, &ht),
                     bb = bandwidth95(bottom[f], SAMPLES, &hb);
        const double bs = bandwidth95(both, SAMPLES, &hs);
        printf("  phi %2.0f: batter side %5.0f Hz (%.2f %%), snare side %5.0f Hz (%.2f %%), "
               "both %5.0f Hz (%.2f %%)\n",
               phis[f], bt, 100.0 * ht, bb, 100.0 * hb, bs, 100.0 * hs);
    }
    free(Wb), free(Ws);
    contact_free(c);
    snare_wires_free(w);
    membrane_free(m);
}

/* Spectral centroid of x[0 .. n) under a Hann window (plain DFT). */
static double centroid(const double *x, int n)
{
    double num = 0.0, den = 0.0;
    for (int k = 0; k <= n / 2; k++) {
        double re = 0.0, im = 0.0;
        for (int i = 0; i < n; i++) {
            const double xi = x[i] * (0.5 - 0.5 * cos(2.0 * M_PI * i / (n - 1)));
            const double ph = -2.0 * M_PI * (double)((long)k * i % n) / n;
            re += xi * cos(ph), im += xi * sin(ph);
        }
        num += (re * re + im * im) * k * SR / n, den += re * re + im * im;
    }
    return num / den;
}

/* The tom struck at the expression ladder's speeds: its pickups against the microphone. */
static void tom_ladder(void)
{
    static const double speeds[] = {0.46, 1.02, 2.77, 5.87, 10.0};
    printf("tom, 13.8 g at r/a 0.33: centroid of the first 50 ms, Hz\n  v m/s  pickup 1  pickup 2");
    for (int f = 0; f < NPHI; f++)
        printf("  mic %2.0f", phis[f]);
    printf("\n");
    for (size_t s = 0; s < sizeof speeds / sizeof speeds[0]; s++) {
        membrane *m = membrane_new(SR);
        membrane_apply_preset(m, membrane_preset_find("tom"));
        contact *c = contact_new();
        ictus_param_set(&contact_params, c, CONTACT_PARAM_STRETCH,
                        stick_tip_head_k3(4.5e9, 0.38, m->density / 1390.0, m->radius));
        membrane_attach_contact(m, c);
        contact_hit_mass(c, speeds[s], 0.33, 0.0, 0, 0.0138);
        double *W = batter_weights(m), prev[NPHI] = {0}, p[NPHI];
        static double pick[2][SAMPLES], mic[NPHI][SAMPLES];
        for (int i = 0; i < SAMPLES; i++) {
            float o0, o1, *o[2] = {&o0, &o1};
            membrane_process(m, NULL, o, 1);
            pick[0][i] = o0, pick[1][i] = o1;
            batter_pressure(m, W, prev, p);
            for (int f = 0; f < NPHI; f++)
                mic[f][i] = p[f];
        }
        printf("  %5.2f  %8.0f  %8.0f", speeds[s], centroid(pick[0], SAMPLES),
               centroid(pick[1], SAMPLES));
        for (int f = 0; f < NPHI; f++)
            printf("  %6.0f", centroid(mic[f], SAMPLES));
        printf("\n");
        free(W);
        contact_free(c);
        membrane_free(m);
    }
}

int main(int argc, char **argv)
{
    if (argc > 1 && strcmp(argv[1], "tom") == 0) {
        tom_ladder();
        return 0;
    }
    const double velocity = argc > 1 ? atof(argv[1]) : 2.5;
    stroke(1, velocity);
    stroke(0, velocity);
    return 0;
}
