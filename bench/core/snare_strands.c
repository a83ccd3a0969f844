/* snare_strands.c -- a prototype of distributed snare wires, measured beside the
 * product's (snare_wires.c): one stroke of a stick on the `snare` preset, and the 95 %
 * point of the first 50 ms' energy of both pickups together (from the first sample that
 * is not zero; a plain DFT) with its share above 4 kHz. A measurement, not a test.
 *
 * The snare side is the product's (the snare head, modal, trapezoidal with prewarped
 * frequencies; the shell's air as a spring between the heads' mean displacements, on
 * the batter through one coupling point) with other wires, after Bilbao's strings
 * colliding along their length (S. Bilbao, JASA 131(1), 2012): S strands laid parallel
 * to the wires' diameter, evenly across a band BAND m wide, each an ideal string of
 * linear density MU and tension TENSION (spread evenly over +-SPREAD across the set, in a
 * scrambled order) fixed at the rim (its chord of the head), modal (sin(n pi s / L) to
 * FMAX, T60 of its own), touching the head at the centres of P equal parts of its
 * length. Each point collides one-sidedly, F = k [w_head - y_strand]+^1.5 (k = 1e9
 * N/m^1.5 as snare_wires.c, env K_LAW), as the discrete gradient of the collision
 * potential (energy-consistent; Torin, Hamilton & Bilbao, DAFx-14), every gap of the
 * sample solved together by Newton on the compliance matrix (head + strand + air), the
 * air eliminated, as snare_wires.c's newton_forces. Energy of heads, air and strands is
 * checked block by block once the stick has left (it must never grow).
 *
 * The head has every mode below FMAX, both partners cos(m theta) and sin(m theta). With
 * SYM=1 in the environment the strands come in mirrored pairs about the wires' diameter,
 * each pair alike: then the whole snare side is symmetric under both reflections (the
 * air's force is axisymmetric), and only the cos(m theta) modes of even m move, which
 * the prototype then keeps alone (exact, a quarter of the modes). Double precision,
 * plain loops: no kernel.
 *
 *   bench_snare_strands product SR FMAX V MASS [off]     the product's wires (FMAX unused)
 *   bench_snare_strands strands SR FMAX V MASS S P MU TENSION SPREAD BAND T60 [off]
 *
 * SR Hz, FMAX Hz (head and strands), V m/s and MASS kg: the stick, at r/a STRIKE_R
 * (env, 0.3), with the tip TIP (env, contact~'s default). `off` lifts the wires.
 * Env BEND (N m^2): the strands' bending stiffness (stiff strings). Env PRELOAD (N/m):
 * the strands pressed onto the head, the snare side starting at its static equilibrium
 * under it (preload()). NPMAX points in all.
 *
 * Grounded values (a real set: ~20 strands, each a close-wound steel coil; per strand):
 *   wire d = 0.35 mm, coil D = 2.0 mm (mean Dm = 1.65 mm), pitch p = d (close-wound),
 *   steel rho = 7850 kg/m^3, E = 207 GPa, G = 79.3 GPa.
 *   mu = rho (pi d^2 / 4) (pi Dm / p) = 11.2 g/m (d 0.3-0.4, D 1.5-2.5 mm: 7-16 g/m).
 *   T = 2 N (the coil's initial tension tau_i pi d^3 / (8 Dm) = 0.5-1.5 N for tau_i =
 *   50-150 MPa, plus the strainer's stretch on an axial rate G d^4 / (8 Dm^3 N) = 35 N/m,
 *   N = 0.33 m / p turns; range 1-3 N), so f1 = sqrt(T / mu) / (2 L) = 19 Hz (11-29 Hz).
 *   B = 2 p EI GJ / (pi Dm (EI + GJ)) = 8.9e-6 N m^2 (the open coil: each turn's bending
 *   and torsion under a moment, energy per turn; J = 2 I = pi d^4 / 32): the string
 *   dispersion crosses to bending near 1.4 kHz. A locked tube (turns pressed together by
 *   the initial tension) bounds it above: 0.13 N m^2.
 *   Preload q0 = 2 T sin(theta) / L - mu g: the strand's pull where it leaves the head for
 *   the strainer (wrap angle theta, an estimate: 5 / 10 / 20 deg) spread evenly along its
 *   length, less its weight (the snare side faces down): 0.87 / 1.85 / 3.74 N/m.
 *   S model strands stand for 20 / S real ones each: mu, T, B and q0 times 20 / S (f1 and
 *   the dispersion unchanged). E.g. S = 8: mu 0.028, T 5, BEND 2.23e-5, PRELOAD 4.63:
 *   SYM=1 TIP=wood STRIKE_R=0.2 BEND=2.23e-5 PRELOAD=4.63 bench_snare_strands strands
 *   96000 10000 3.0 0.0138 8 30 0.028 5 0 0.07 0.5
 * At 48 kHz the preloaded contacts chatter at the time step (a 48 kHz figure is not to
 * be trusted with PRELOAD: check it at 96 and 192 kHz).
 *
 * Measured 2026-12-02 (SYM=1 TIP=wood STRIKE_R=0.2, 13.8 g; 95 % point, share > 4 kHz;
 * head modes to 10 kHz unless said; energy never grew; wires off 700 Hz):
 *   grounded strings, no preload (f1 19 Hz): 800-1060 Hz with or without BEND (S 2, 8).
 *   BEND + PRELOAD (theta 10 deg), S = 2 (10 strands a line): 1560 Hz at 96 and 192 kHz.
 *   BEND + PRELOAD, S = 8, P = 30 (P = 50: the same): mf 8660 Hz 16.8 % (96 kHz), 7740
 *   Hz 13.3 % (192 kHz), 8280 Hz 14.8 % (384 kHz); heads to 19.2 kHz: 15880 Hz
 *   17.9 % (96), 13520 Hz 14.5 % (192);
 *   ff 7120 / 7500 Hz (96 / 192 kHz); pp 920 Hz at 192 kHz (the preload holds the wires
 *   on the head: 0.3 % of point-samples apart). S = 16, P = 24: mf 7360 Hz 9.9 % (96).
 *   PRELOAD alone (S = 8): 5920 Hz 6.9 %; BEND alone: 1060 Hz 0.7 % (96 kHz).
 *   theta 5 deg: mf 7160 / 7600 Hz, ff 3340 / 3040 Hz (96 / 192 kHz), pp 5600 / 3700 /
 *   2480 Hz at 96 / 192 / 384 kHz (not converged); theta 20 deg: mf 4640 Hz (96 kHz).
 *   Cost: S = 8, P = 30 at 48 kHz, 9.4 s of one core for 0.061 s (~150x real time).
 * E.g. SYM=1 TIP=wood STRIKE_R=0.2 bench_snare_strands strands 48000 10000 3.0 0.0138
 * 8 12 0.003 34.14 0.1 0.07 0.5: strands of 3 g/m at 34.14 N, whose fundamental along
 * the diameter is 150 Hz (TENSION = MU (2 L f1)^2, L = 2a = 0.3556 m). */
#include "bessel_internal.h"
#include "contact.h"
#include "membrane_internal.h"
#include "membrane_presets.h"
#include "snare_wires.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* The snare head and the shell: snare_wires.c's values (sources there). */
#define HEAD_DENSITY 0.105
#define HEAD_F01     330.0
#define HEAD_T60     0.5
#define HEAD_ETA     0.002
#define SHELL_DEPTH  0.1397
static double K_LAW = 1.0e9; /* N/m^1.5, as snare_wires.c (env K_LAW) */
#define PICK_R 0.5
#define NPMAX  400

typedef struct strands {
    membrane_point point; /* first member */
    int n;                /* head modes */
    double *x, *v, *xf, *ca, *cb, *g, *w2, *mean, *pick[2];
    double *psi;                                /* [NP][n] */
    int S, P, NP, nm;                           /* strands, points each, points, modes per strand */
    double *q, *qv, *qf, *sca, *scb, *sg, *sw2; /* [S][nm] */
    double *phi;                                /* [NP][nm]: strand mode at its point */
    int *strand_of;
    double phi_norm[64]; /* sqrt(2 / (mu L)) of each strand */
    double k_air, Kmm, *Kmw, *C; /* C: [NP][NP] gap compliance */
    double *fl, ustat;           /* the preload on each strand mode; the head's static mean */
    double d[NPMAX], gap0;
    int engaged;
    long contact_samples, newton_fail;
    long open_sum, open_n, open_events; /* points apart, summed over samples; openings */
    long newton_solves, newton_steps, active_sum; /* the cost: steps, gaps in them */
} strands;

static double pot(double d)
{
    return d > 0.0 ? K_LAW / 2.5 * d * d * sqrt(d) : 0.0;
}

static double grad_force(double d0, double v0, double d1, double *df)
{
    double dx = d1 - d0, scale = fabs(d0) > fabs(d1) ? fabs(d0) : fabs(d1);
    if (d0 <= 0.0 && d1 <= 0.0) {
        *df = 0.0;
        return 0.0;
    }
    if (fabs(dx) > 1.0e-6 * scale) {
        const double r1 = d1 > 0.0 ? sqrt(d1) : 0.0, f1 = K_LAW * d1 * r1, inv = 1.0 / dx;
        const double f = (f1 * d1 / 2.5 - v0) * inv;
        *df = (f1 - f) * inv;
        return f > 0.0 ? f : 0.0;
    }
    double mid = 0.5 * (d0 + d1);
    *df = mid > 0.0 ? 0.75 * K_LAW * sqrt(mid) : 0.0;
    return mid > 0.0 ? K_LAW * mid * sqrt(mid) : 0.0;
}

static int solve_linear(double *A, double *b, int n)
{
    for (int c = 0; c < n; c++) {
        int piv = c;
        for (int r = c + 1; r < n; r++)
            if (fabs(A[r * n + c]) > fabs(A[piv * n + c]))
                piv = r;
        if (!(fabs(A[piv * n + c]) > 0.0))
            return 0;
        if (piv != c) {
            for (int k = 0; k < n; k++) {
                double t = A[c * n + k];
                A[c * n + k] = A[piv * n + k], A[piv * n + k] = t;
            }
            double t = b[c];
            b[c] = b[piv], b[piv] = t;
        }
        for (int r = c + 1; r < n; r++) {
            const double f = A[r * n + c] / A[c * n + c];
            for (int k = c; k < n; k++)
                A[r * n + k] -= f * A[c * n + k];
            b[r] -= f * b[c];
        }
    }
    for (int r = n - 1; r >= 0; r--) {
        double s = b[r];
        for (int k = r + 1; k < n; k++)
            s -= A[r * n + k] * b[k];
        b[r] = s / A[r * n + r];
    }
    return 1;
}

/* Newton on d = a - Ceff F(d), Ceff = C - beta Kmw Kmw^T (snare_wires.c, newton_forces). */
static int newton(strands *w, double beta, const double *a, double *F)
{
    const int N = w->NP;
    static double Ce[NPMAX * NPMAX], J[NPMAX * NPMAX];
    double d[NPMAX], v0[NPMAX], df[NPMAX], R[NPMAX], Ra[NPMAX];
    int act[NPMAX], any = 0;
    for (int i = 0; i < N; i++)
        any |= a[i] > 0.0 || w->d[i] > 0.0;
    if (!any) {
        for (int i = 0; i < N; i++)
            F[i] = 0.0;
        return 1;
    }
    for (int i = 0; i < N; i++)
        for (int j = 0; j < N; j++)
            Ce[i * N + j] = w->C[i * N + j] - beta * w->Kmw[i] * w->Kmw[j];
    for (int i = 0; i < N; i++)
        v0[i] = pot(w->d[i]), d[i] = a[i];
    w->newton_solves++;
    for (int it = 0; it < 60; it++) {
        int na = 0;
        double worst = 0.0;
        for (int i = 0; i < N; i++) {
            if (w->d[i] <= 0.0 && d[i] <= 0.0) {
                F[i] = df[i] = 0.0;
                continue;
            }
            F[i] = grad_force(w->d[i], v0[i], d[i], &df[i]);
            if (df[i] != 0.0)
                act[na++] = i;
        }
        for (int i = 0; i < N; i++) {
            double cf = 0.0;
            for (int j = 0; j < N; j++)
                if (F[j] != 0.0)
                    cf += Ce[i * N + j] * F[j];
            R[i] = d[i] - a[i] + cf;
            worst = fabs(R[i]) > worst ? fabs(R[i]) : worst;
        }
        if (worst <= 1.0e-15)
            return 1;
        w->newton_steps++, w->active_sum += na;
        for (int r = 0; r < na; r++) {
            for (int c = 0; c < na; c++)
                J[r * na + c] = Ce[act[r] * N + act[c]] * df[act[c]] + (r == c ? 1.0 : 0.0);
            Ra[r] = R[act[r]];
        }
        if (!solve_linear(J, Ra, na))
            return 0;
        for (int i = 0; i < N; i++) {
            if (df[i] != 0.0)
                continue;
            double s = R[i];
            for (int r = 0; r < na; r++)
                s -= Ce[i * N + act[r]] * df[act[r]] * Ra[r];
            d[i] -= s;
        }
        for (int r = 0; r < na; r++)
            d[act[r]] -= Ra[r];
    }
    return 0;
}

static void step(strands *w, double ub, double kb, double T, double extra[MEMBRANE_PICKUPS])
{
    const int n = w->n, NP = w->NP, nm = w->nm;
    double uf = 0.0, wf[NPMAX], yf[NPMAX], F[NPMAX] = {0}, a[NPMAX];
    for (int k = 0; k < n; k++) {
        w->xf[k] = w->ca[k] * w->x[k] + w->cb[k] * w->v[k];
        uf += w->mean[k] * w->xf[k];
    }
    for (int p = 0; w->engaged && p < NP; p++) {
        const double *ps = w->psi + (size_t)p * n;
        double s = 0.0;
        for (int k = 0; k < n; k++)
            s += ps[k] * w->xf[k];
        wf[p] = s;
    }
    for (int s = 0; w->engaged && s < w->S; s++)
        for (int k = 0; k < nm; k++) {
            const int i = s * nm + k;
            w->qf[i] = w->sca[i] * w->q[i] + w->scb[i] * w->qv[i];
        }
    for (int p = 0; w->engaged && p < NP; p++) {
        const double *ph = w->phi + (size_t)p * nm, *qf = w->qf + (size_t)w->strand_of[p] * nm;
        double s = 0.0;
        for (int k = 0; k < nm; k++)
            s += ph[k] * qf[k];
        yf[p] = s;
    }
    const double ka = w->k_air;
    uf -= w->ustat; /* the air sees the head's mean from its static state (the vent) */
    const double beta = ka / (2.0 + ka * (kb + w->Kmm)), alpha = beta * (w->gap0 + ub - uf);
    double fa = alpha;
    if (w->engaged) {
        for (int p = 0; p < NP; p++)
            a[p] = wf[p] - yf[p] + w->Kmw[p] * alpha;
        if (!newton(w, beta, a, F))
            w->newton_fail++;
        for (int p = 0; p < NP; p++)
            fa += beta * w->Kmw[p] * F[p];
    }
    /* Forces into the head and the strands. */
    double pv[2] = {0, 0};
    int touching = 0;
    for (int p = 0; p < NP; p++)
        touching |= F[p] > 0.0;
    for (int k = 0; k < n; k++) {
        double f = w->mean[k] * fa;
        if (touching)
            for (int p = 0; p < NP; p++)
                if (F[p] != 0.0)
                    f -= w->psi[(size_t)p * n + k] * F[p];
        const double x1 = w->xf[k] + w->g[k] * f;
        const double v1 = 2.0 / T * (x1 - w->x[k]) - w->v[k];
        w->x[k] = x1, w->v[k] = v1;
        pv[0] += w->pick[0][k] * v1, pv[1] += w->pick[1][k] * v1;
    }
    for (int s = 0; w->engaged && s < w->S; s++)
        for (int k = 0; k < nm; k++) {
            const int i = s * nm + k;
            double f = 0.0;
            for (int p = s * w->P; p < (s + 1) * w->P; p++)
                f += w->phi[(size_t)p * nm + k] * F[p];
            const double x1 = w->qf[i] + w->sg[i] * (f + w->fl[i]);
            w->qv[i] = 2.0 / T * (x1 - w->q[i]) - w->qv[i];
            w->q[i] = x1;
        }
    double u1 = uf + w->ustat + w->Kmm * fa;
    for (int p = 0; w->engaged && p < NP; p++)
        u1 -= w->Kmw[p] * F[p];
    w->gap0 = (ub - kb * fa) - (u1 - w->ustat);
    for (int p = 0; w->engaged && p < NP; p++) { /* the new gaps, exactly */
        const double *ps = w->psi + (size_t)p * n, *ph = w->phi + (size_t)p * nm,
                     *q = w->q + (size_t)w->strand_of[p] * nm;
        double hs = 0.0, ys = 0.0;
        for (int k = 0; k < n; k++)
            hs += ps[k] * w->x[k];
        for (int k = 0; k < nm; k++)
            ys += ph[k] * q[k];
        if (w->d[p] > 0.0 && hs - ys <= 0.0)
            w->open_events++;
        w->d[p] = hs - ys;
        w->open_sum += w->d[p] <= 0.0;
    }
    w->open_n += w->engaged;
    w->contact_samples += touching;
    membrane_point *pt = &w->point;
    pt->force_pending = -fa;
    const double to_batter = 1.0 / pt->owner->mass_scale;
    for (int j = 0; j < MEMBRANE_PICKUPS; j++)
        extra[j] += -fa * pt->pick_coupling[j] + pv[j] * to_batter;
}

static void st_solve(membrane_point *const *pts, int count, const double *w_free,
                     const double (*K)[MEMBRANE_MAX_POINTS], double T, int sample,
                     double extra[MEMBRANE_PICKUPS])
{
    (void)sample;
    for (int i = 0; i < count; i++)
        step((strands *)pts[i], w_free[i], K[i][i], T, extra);
}
static void st_shapes(const membrane *m, const membrane_point *pt, int live, float *psi)
{
    (void)pt;
    for (int k = 0; k < m->capacity; k++) {
        psi[k] = 0.0f;
        if (k < live && m->table.m[k] == 0) {
            double j = m->table.j[k];
            psi[k] = (float)(m->table.norm[k] * m->table.scale[k] * 2.0 * ictus_bessel_j(1, j) / j);
        }
    }
}
static void st_landed(membrane_point *pt, double d, double v)
{
    (void)pt, (void)d, (void)v;
}
static void st_begin(membrane_point *pt, int n)
{
    (void)pt, (void)n;
}
static void st_cleared(membrane_point *pt)
{
    pt->active = 1;
}
static void st_detached(membrane_point *pt)
{
    (void)pt;
}
static const membrane_point_ops st_ops = {st_landed,  st_solve,    st_begin,
                                          st_cleared, st_detached, st_shapes};

static double *dz(size_t n)
{
    double *p = calloc(n ? n : 1, sizeof(double));
    if (!p) {
        fprintf(stderr, "bench_snare_strands: out of memory\n");
        exit(1);
    }
    return p;
}

static void strands_free(strands *w)
{
    if (!w)
        return;
    membrane_point_free_(&w->point); /* detached from the batter first */
    double *arrs[] = {w->x,    w->v,       w->xf,      w->ca,  w->cb,  w->g,   w->w2,
                      w->mean, w->pick[0], w->pick[1], w->psi, w->q,   w->qv,  w->qf,
                      w->sca,  w->scb,     w->sg,      w->sw2, w->phi, w->Kmw, w->C, w->fl};
    for (size_t i = 0; i < sizeof(arrs) / sizeof(arrs[0]); i++)
        free(arrs[i]);
    free(w->strand_of);
    free(w);
}

typedef struct cfg {
    double sr, fmax, v, mass;
    int S, P;
    double mu, tension, spread, band, t60;
    int off;
} cfg;

/* Trapezoidal (prewarped) coefficients of x'' + 2 s x' + W^2 x = f. */
static void coeffs(double om, double s, double T, double *ca, double *cb, double *g, double *w2)
{
    const double wm = 2.0 / T * tan(0.5 * om * T);
    const double D = 2.0 / T + 0.5 * T * wm * wm + 2.0 * s;
    *w2 = wm * wm;
    *ca = (2.0 / T - 0.5 * T * wm * wm + 2.0 * s) / D;
    *cb = 2.0 / D;
    *g = T / D;
}

/* The preload (env PRELOAD, N/m toward the head, on each strand evenly along its length):
 * the strands pressed against the head by the strainer (the strands' pull over the snare
 * beds, spread along them; the strands' weight, the snare side down, takes mu g off it).
 * The snare side starts at its static equilibrium under it: head modes, strands and the
 * gaps' Hertz forces, by Newton on d = d_load - Cs F(d), Cs the static compliance (the
 * discrete one: 1/W^2 of the prewarped modes, so the state is exactly at rest). The air
 * does not hold the static load (the shell's vent hole equalises the static pressure):
 * it acts on the head's mean relative to its static state. */
static void preload(strands *w, double q0, const double *Ls)
{
    const int NP = w->NP, nm = w->nm, n = w->n;
    double *Cs = dz((size_t)NP * NP), dl[NPMAX], d[NPMAX], F[NPMAX], df[NPMAX], R[NPMAX];
    static double J[NPMAX * NPMAX];
    for (int s = 0; s < w->S; s++)
        for (int q = 0; q < nm; q++) {
            const int i = s * nm + q;
            if (w->sg[i] == 0.0)
                continue;
            const double mu_l = w->phi_norm[s]; /* sqrt(2 / (mu L)) */
            w->fl[i] = -q0 * mu_l * Ls[s] * (1.0 - cos((q + 1) * M_PI)) / ((q + 1) * M_PI);
        }
    for (int p = 0; p < NP; p++) {
        dl[p] = 0.0;
        const int s = w->strand_of[p];
        for (int q = 0; q < nm; q++) {
            const int i = s * nm + q;
            if (w->sw2[i] > 0.0)
                dl[p] -= w->phi[(size_t)p * nm + q] * w->fl[i] / w->sw2[i];
        }
        for (int r = 0; r < NP; r++) {
            double c = 0.0;
            for (int k = 0; k < n; k++)
                if (w->w2[k] > 0.0)
                    c += w->psi[(size_t)p * n + k] * w->psi[(size_t)r * n + k] / w->w2[k];
            if (w->strand_of[r] == s)
                for (int q = 0; q < nm; q++)
                    if (w->sw2[s * nm + q] > 0.0)
                        c += w->phi[(size_t)p * nm + q] * w->phi[(size_t)r * nm + q] /
                             w->sw2[s * nm + q];
            Cs[(size_t)p * NP + r] = c;
        }
        d[p] = dl[p] > 0.0 ? 1e-3 * dl[p] : 0.0;
    }
    int it;
    double worst = 1.0;
    for (it = 0; it < 500; it++) {
        for (int p = 0; p < NP; p++) {
            F[p] = d[p] > 0.0 ? K_LAW * d[p] * sqrt(d[p]) : 0.0;
            df[p] = d[p] > 0.0 ? 1.5 * K_LAW * sqrt(d[p]) : 0.0;
        }
        worst = 0.0;
        for (int p = 0; p < NP; p++) {
            double cf = 0.0;
            for (int r = 0; r < NP; r++)
                cf += Cs[(size_t)p * NP + r] * F[r];
            R[p] = d[p] - dl[p] + cf;
            worst = fmax(worst, fabs(R[p]));
        }
        if (worst < 1e-16)
            break;
        for (int p = 0; p < NP; p++)
            for (int r = 0; r < NP; r++)
                J[p * NP + r] = Cs[(size_t)p * NP + r] * df[r] + (p == r);
        if (!solve_linear(J, R, NP))
            break;
        for (int p = 0; p < NP; p++) { /* damped: a gap at most halves, or opens to 0 */
            double nd = d[p] - R[p];
            if (d[p] > 0.0 && nd < 0.5 * d[p])
                nd = 0.5 * d[p];
            d[p] = nd;
        }
    }
    for (int k = 0; k < n; k++) {
        double f = 0.0;
        for (int p = 0; p < NP; p++)
            f -= w->psi[(size_t)p * n + k] * F[p];
        w->x[k] = w->w2[k] > 0.0 ? f / w->w2[k] : 0.0;
        w->ustat += w->mean[k] * w->x[k];
    }
    for (int s = 0; s < w->S; s++)
        for (int q = 0; q < nm; q++) {
            const int i = s * nm + q;
            double f = w->fl[i];
            for (int p = s * w->P; p < (s + 1) * w->P; p++)
                f += w->phi[(size_t)p * nm + q] * F[p];
            w->q[i] = w->sw2[i] > 0.0 ? f / w->sw2[i] : 0.0;
        }
    double tot = 0.0, dmax = 0.0;
    int touching = 0;
    for (int p = 0; p < NP; p++) { /* the gaps, exactly as step() computes them */
        double hs = 0.0, ys = 0.0;
        for (int k = 0; k < n; k++)
            hs += w->psi[(size_t)p * n + k] * w->x[k];
        for (int q = 0; q < nm; q++)
            ys += w->phi[(size_t)p * nm + q] * w->q[w->strand_of[p] * nm + q];
        w->d[p] = hs - ys;
        tot += F[p], dmax = fmax(dmax, w->d[p]), touching += w->d[p] > 0.0;
    }
    printf("preload %.3g N/m: static solve %d iterations (residual %.1e m), %d of %d points "
           "pressing, %.3g N in all, deepest %.3g m, head's static mean %.3g m\n",
           q0, it, worst, touching, NP, tot, dmax, w->ustat);
    free(Cs);
}

static strands *build(const cfg *c, double a)
{
    strands *w = (strands *)dz((sizeof(strands) + sizeof(double) - 1) / sizeof(double));
    const double T = 1.0 / c->sr;
    const double c01 = 2.0 * M_PI * a * HEAD_F01 / ictus_bessel_zero(0, 1);
    ictus_bessel_zero_entry *z = NULL;
    int nz = ictus_bessel_zeros_below(2.0 * M_PI * a * c->fmax / c01, &z);
    /* Symmetric (env SYM): strands in mirrored pairs about the wires' diameter, each pair
     * alike, every strand symmetric about the head's centre line across it; the air's
     * force is axisymmetric, so only the cos(m theta) modes of even m are ever moved. */
    const int sym = getenv("SYM") && atoi(getenv("SYM"));
    int n = 0;
    for (int i = 0; i < nz; i++)
        n += sym ? (z[i].m % 2 == 0) : (z[i].m ? 2 : 1);
    w->n = n;
    w->x = dz(n), w->v = dz(n), w->xf = dz(n), w->ca = dz(n), w->cb = dz(n), w->g = dz(n);
    w->w2 = dz(n), w->mean = dz(n), w->pick[0] = dz(n), w->pick[1] = dz(n);
    w->S = c->S, w->P = c->P, w->NP = c->S * c->P;
    if (w->NP > NPMAX || c->S > 64) {
        fprintf(stderr, "bench_snare_strands: at most %d points and 64 strands\n", NPMAX);
        exit(2);
    }
    w->psi = dz((size_t)w->NP * n);
    /* Strand geometry: S strands at y_s evenly across the band, each a chord of the head
     * (fixed at the rim), P points at the centres of P equal parts of its length. */
    double ys[64], Ls[64], px[NPMAX], py[NPMAX];
    for (int s = 0; s < c->S; s++) {
        ys[s] = c->S > 1 ? -0.5 * c->band + c->band * s / (c->S - 1) : 0.0;
        Ls[s] = 2.0 * sqrt(a * a - ys[s] * ys[s]);
        for (int p = 0; p < c->P; p++) {
            px[s * c->P + p] = -0.5 * Ls[s] + (p + 0.5) * Ls[s] / c->P;
            py[s * c->P + p] = ys[s];
        }
    }
    const double mass_norm = 1.0 / sqrt(HEAD_DENSITY * a * a);
    int k = 0;
    for (int i = 0; i < nz; i++) {
        if (sym && z[i].m % 2)
            continue;
        for (int part = 0; part < (z[i].m && !sym ? 2 : 1); part++, k++) {
            const int m = z[i].m;
            const double j = z[i].j;
            const double norm =
                sqrt((m ? 2.0 : 1.0) / M_PI) / fabs(ictus_bessel_j(m + 1, j)) * mass_norm;
            const double om = j * c01 / a, s = log(1000.0) / HEAD_T60 + 0.5 * HEAD_ETA * om;
            if (om < 0.9 * M_PI * c->sr)
                coeffs(om, s, T, &w->ca[k], &w->cb[k], &w->g[k], &w->w2[k]);
            w->mean[k] = m == 0 ? norm * 2.0 * ictus_bessel_j(1, j) / j : 0.0;
            for (int pk = 0; pk < 2; pk++) {
                const double th = (pk ? 135.0 : 45.0) * M_PI / 180.0;
                w->pick[pk][k] =
                    norm * ictus_bessel_j(m, j * PICK_R) * (part ? sin(m * th) : cos(m * th));
            }
            for (int p = 0; p < w->NP; p++) {
                const double r = sqrt(px[p] * px[p] + py[p] * py[p]) / a, th = atan2(py[p], px[p]);
                w->psi[(size_t)p * n + k] =
                    norm * ictus_bessel_j(m, j * r) * (part ? sin(m * th) : cos(m * th));
            }
        }
    }
    free(z);
    /* Strands: modes to fmax, tension varying across the set by +-spread. With env BEND
     * (N m^2, the strand's bending stiffness B), a stiff string: omega^2 = (T k^2 + B k^4)
     * / mu, k = n pi / L, the same sine shapes (simply supported ends). */
    const double bend = getenv("BEND") ? atof(getenv("BEND")) : 0.0;
    const double cw = sqrt(c->tension / c->mu);
    int nm = (int)(c->fmax * 2.0 * 2.0 * a / (cw * (1.0 - c->spread)));
    if (bend > 0.0) { /* the largest k with omega(k) < 2 pi fmax at the lowest tension */
        const double tb = c->tension * (1.0 - c->spread) / c->mu, bb = bend / c->mu,
                     om = 2.0 * M_PI * c->fmax;
        const double k2 = (-tb + sqrt(tb * tb + 4.0 * bb * om * om)) / (2.0 * bb);
        nm = (int)(sqrt(k2) * 2.0 * a / M_PI) + 1;
    }
    if (nm < 1)
        nm = 1;
    w->nm = nm;
    const size_t sn = (size_t)c->S * nm;
    w->q = dz(sn), w->qv = dz(sn), w->qf = dz(sn), w->sca = dz(sn), w->scb = dz(sn);
    w->sg = dz(sn), w->sw2 = dz(sn);
    w->phi = dz((size_t)w->NP * nm);
    w->strand_of = (int *)dz((size_t)w->NP);
    for (int s = 0; s < c->S; s++) {
        /* Tensions spread evenly over +-spread, in a scrambled order (pairs alike when sym). */
        const int idx = sym ? (s < c->S - 1 - s ? s : c->S - 1 - s) : s,
                  cnt = sym ? c->S / 2 : c->S;
        const double ten =
            c->tension *
            (1.0 + (cnt > 1 ? c->spread * (2.0 * ((idx * 7) % cnt) / (cnt - 1) - 1.0) : 0));
        const double cs = sqrt(ten / c->mu), sig = log(1000.0) / c->t60;
        for (int q = 0; q < nm; q++) {
            const double kq = (q + 1) * M_PI / Ls[s],
                         om = kq * sqrt(cs * cs + bend / c->mu * kq * kq);
            const int i = s * nm + q;
            if (om < 2.0 * M_PI * c->fmax && om < 0.9 * M_PI * c->sr)
                coeffs(om, sig, T, &w->sca[i], &w->scb[i], &w->sg[i], &w->sw2[i]);
            for (int p = s * c->P; p < (s + 1) * c->P; p++) {
                w->strand_of[p] = s;
                w->phi_norm[s] = sqrt(2.0 / (c->mu * Ls[s]));
                if (w->sg[i] != 0.0)
                    w->phi[(size_t)p * nm + q] =
                        sqrt(2.0 / (c->mu * Ls[s])) *
                        sin((q + 1) * M_PI * (px[p] + 0.5 * Ls[s]) / Ls[s]);
            }
        }
    }
    /* Couplings. */
    const int NP = w->NP;
    w->Kmw = dz(NP), w->C = dz((size_t)NP * NP);
    for (int kk = 0; kk < n; kk++)
        w->Kmm += w->mean[kk] * w->mean[kk] * w->g[kk];
    for (int p = 0; p < NP; p++) {
        for (int kk = 0; kk < n; kk++)
            w->Kmw[p] += w->mean[kk] * w->psi[(size_t)p * n + kk] * w->g[kk];
        for (int q = 0; q < NP; q++) {
            double s = 0.0;
            for (int kk = 0; kk < n; kk++)
                s += w->psi[(size_t)p * n + kk] * w->psi[(size_t)q * n + kk] * w->g[kk];
            if (w->strand_of[p] == w->strand_of[q])
                for (int m = 0; m < nm; m++) {
                    const int i = w->strand_of[p] * nm + m;
                    s += w->phi[(size_t)p * nm + m] * w->phi[(size_t)q * nm + m] * w->sg[i];
                }
            w->C[(size_t)p * NP + q] = s;
        }
    }
    w->k_air = MEMBRANE_AIR_RHO * MEMBRANE_AIR_C * MEMBRANE_AIR_C * M_PI * a * a / SHELL_DEPTH;
    w->engaged = !c->off;
    w->point.ops = &st_ops;
    w->fl = dz((size_t)c->S * nm);
    if (w->engaged && getenv("PRELOAD") && atof(getenv("PRELOAD")) != 0.0)
        preload(w, atof(getenv("PRELOAD")), Ls);
    return w;
}

static double energy(const strands *w)
{
    double e = 0.5 * w->k_air * w->gap0 * w->gap0;
    for (int k = 0; k < w->n; k++)
        e += 0.5 * (w->v[k] * w->v[k] + w->w2[k] * w->x[k] * w->x[k]);
    for (int i = 0; w->engaged && i < w->S * w->nm; i++)
        e += 0.5 * (w->qv[i] * w->qv[i] + w->sw2[i] * w->q[i] * w->q[i]);
    for (int p = 0; w->engaged && p < w->NP; p++)
        e += pot(w->d[p]);
    for (int i = 0; w->engaged && i < w->S * w->nm; i++)
        e -= w->fl[i] * w->q[i]; /* the constant preload's potential */
    return e;
}

/* 95 % point and share above 4 kHz of the first 50 ms of both pickups (DFT). */
static void band(const float *a, const float *b, int len, double sr)
{
    int start = 0;
    while (start < len && a[start] == 0.0f && b[start] == 0.0f)
        start++;
    const int n = (int)(0.05 * sr);
    double *p = dz(n / 2 + 1), total = 0.0, hi = 0.0;
    for (int k = 0; k <= n / 2; k++) {
        for (int ch = 0; ch < 2; ch++) {
            const float *x = ch ? b : a;
            double re = 0.0, im = 0.0;
            for (int i = 0; i < n && start + i < len; i++) {
                const double ph = -2.0 * M_PI * (double)((long)k * i % n) / n;
                re += x[start + i] * cos(ph), im += x[start + i] * sin(ph);
            }
            p[k] += re * re + im * im;
        }
        total += p[k];
        if (k * sr / n > 4000.0)
            hi += p[k];
    }
    double cum = 0.0, f95 = sr / 2;
    for (int k = 0; k <= n / 2; k++)
        if ((cum += p[k]) >= 0.95 * total) {
            f95 = k * sr / n;
            break;
        }
    printf("95%% point %.0f Hz, above 4 kHz %.2f %%\n", f95, 100.0 * hi / total);
    free(p);
}

int main(int argc, char **argv)
{
    if (argc < 6) {
        fprintf(stderr, "usage: see the header\n");
        return 2;
    }
    cfg c = {0};
    const int product = strcmp(argv[1], "product") == 0;
    c.sr = atof(argv[2]), c.fmax = atof(argv[3]), c.v = atof(argv[4]), c.mass = atof(argv[5]);
    if (!product) {
        if (argc < 13)
            return 2;
        c.S = atoi(argv[6]), c.P = atoi(argv[7]), c.mu = atof(argv[8]), c.tension = atof(argv[9]);
        c.spread = atof(argv[10]), c.band = atof(argv[11]), c.t60 = atof(argv[12]);
        c.off = argc > 13 && strcmp(argv[13], "off") == 0;
    }
    if (getenv("K_LAW"))
        K_LAW = atof(getenv("K_LAW"));
    membrane *m = membrane_new(c.sr);
    membrane_apply_preset(m, membrane_preset_find("snare"));
    snare_wires *sw = NULL;
    strands *w = NULL;
    if (product) {
        sw = snare_wires_new();
        snare_wires_attach(sw, m);
        if (argc > 6 && strcmp(argv[6], "off") == 0)
            snare_wires_engage(sw, 0);
    } else {
        w = build(&c, m->radius);
        membrane_point_attach_(m, &w->point);
        w->point.active = 1;
        printf("head modes %d, strands %d x %d points, %d modes each\n", w->n, w->S, w->P, w->nm);
    }
    contact *ct = contact_new();
    membrane_attach_contact(m, ct);
    if (getenv("TIP"))
        contact_set_tip(ct, getenv("TIP"));
    contact_hit_mass(ct, c.v, getenv("STRIKE_R") ? atof(getenv("STRIKE_R")) : 0.3, 0.0, 0, c.mass);
    float force[64];
    contact_set_force_output(ct, force, 64);
    const int blocks = (int)(0.06 * c.sr / 64) + 1, len = blocks * 64;
    float *o1 = calloc(len, sizeof(float)), *o2 = calloc(len, sizeof(float));
    if (!o1 || !o2)
        return 1;
    /* Once the stick has left (a block without its force after one with it), the
     * energy of heads, air and strands must never grow. */
    double e_prev = -1.0, worst_gain = 0.0;
    int pressed = 0, left = 0;
    clock_t t0 = clock();
    for (int b = 0; b < blocks; b++) {
        float *o[2] = {o1 + 64 * b, o2 + 64 * b};
        membrane_process(m, NULL, o, 64);
        int any = 0;
        for (int i = 0; i < 64; i++)
            any |= force[i] != 0.0f;
        left |= pressed && !any;
        pressed |= any;
        if (w) {
            const double e = membrane_energy(m) + energy(w);
            if (left && e_prev > 0.0 && e > e_prev)
                worst_gain = fmax(worst_gain, (e - e_prev) / e_prev);
            e_prev = left ? e : -1.0;
        }
    }
    const double cpu = (double)(clock() - t0) / CLOCKS_PER_SEC;
    band(o1, o2, len, c.sr);
    if (w)
        printf("samples with a point pressing %ld, Newton failures %ld, largest energy growth "
               "per block after the stick left %.2e, cpu %.2f s for %.3f s\n",
               w->contact_samples, w->newton_fail, worst_gain, cpu, len / c.sr);
    if (w && w->open_n)
        printf("points apart: %.1f %% of point-samples, %ld openings (%.1f per point)\n",
               100.0 * w->open_sum / ((double)w->open_n * w->NP), w->open_events,
               (double)w->open_events / w->NP);
    if (w && w->newton_steps)
        printf("Newton: %ld solves, %.2f steps per solve, %.1f gaps active per step\n",
               w->newton_solves, (double)w->newton_steps / w->newton_solves,
               (double)w->active_sum / w->newton_steps);
    contact_free(ct);
    strands_free(w);
    snare_wires_free(sw);
    membrane_free(m);
    free(o1), free(o2);
    return 0;
}
