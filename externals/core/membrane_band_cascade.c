/* membrane_band_cascade.c -- a plate's energy cascade (docs/plates.md, "The cascade").
 *
 * A struck cymbal brightens over its first hundreds of milliseconds: at large amplitude
 * its modes exchange energy through the von Karman nonlinearity, and the exchange runs
 * from the few strongly excited modes toward the many weakly excited ones, upward in
 * frequency (wave turbulence in plates: G. During, C. Josserand, S. Rica, PRL 97, 2006;
 * for cymbals and gongs M. Ducceschi, C. Touze, JSV 344, 2015). Simulating the exchange
 * mode by mode needs hundreds of coupled modes; this is its kinetic reduction:
 *
 *   - the modes are grouped into bands a third of an octave wide;
 *   - every BC_INTERVAL samples, each pair of neighbouring bands whose lower band holds
 *     more energy per mode than the upper one relaxes toward equal energy per mode (the
 *     equilibrium, Rayleigh-Jeans, state of a conservative wave system), upward only: a
 *     plate's wave turbulence conserves energy but not wave action, so it has a direct
 *     energy cascade and no inverse one (During, Josserand, Rica); the pair's departure
 *     decays at the rate
 *         Gamma = cascade x N / (2 sqrt(D rho h)),   N = (E h / 2) <|grad w|^2>,
 *     the frequency shift that the mean in-plane stress N of the vibration puts on every
 *     bending mode alike (w^2 = (D k^4 + N k^2) / rho h). With the modes' energies e_k
 *     and <|grad w|^2> = sum e_k k_k^2 / (w_k^2 M), k_k^2 = w_k / sqrt(D / rho h):
 *         Gamma = cascade x 3 (1 - nu^2) / (h^2 M) x sum_k e_k / w_k,
 *     h the thickness, M the plate's mass. Gamma grows as the amplitude squared: a soft
 *     stroke stays nearly linear;
 *   - a band's new energy is put back by scaling its modes' displacement and velocity
 *     alike (each keeps its phase and its share of the band).
 *
 * Every step moves energy between bands and never makes any: the sum is kept to float
 * rounding (about 1e-7 of a band per update, far below what the weakest damping the
 * parameters allow, t60 60 s, takes over an update: 1.5e-4), so the plate's energy never
 * grows (passive, whatever the amplitude). A pair relaxes by the
 * fraction 1 - exp(-Gamma dt) of its departure, never past the equilibrium, so no step
 * can overshoot. Even pairs then odd ones (operator splitting). The update waits while
 * a point (a stick) carries a force; it runs on absolute time (block-size independent).
 * Message time sets the bands and the rate's constant (no allocation anywhere).
 *
 * A drum head (docs/membrane.md, "The energy cascade") cascades the same way, with the
 * rate its stretch sets: the tension modulation's frequency factor g = sqrt(1 + kappa E)
 * shifts every mode by (g - 1) w_k, and a weakly nonlinear wave system exchanges energy
 * at the kinetic rate ~ w (dw / w)^2 (weak turbulence: Zakharov, Lvov, Falkovich,
 * "Kolmogorov Spectra of Turbulence I", Springer 1992). Here Gamma = cascade x w01 x
 * ((g - 1) / 0.1)^2, w01 the fundamental's: the amplitude to the fourth, so a soft
 * stroke stays linear. The same bands, steps and passivity. */
#include "membrane_internal.h"

#include <math.h>

/* kg/m^3: cymbal bronze, for the thickness h = density / rho (docs/plates.md) */
#define BC_BRONZE_RHO 8600.0
/* A drum head's relative frequency shift g - 1 at which its exchange runs at cascade x
 * w01 (docs/membrane.md, "The energy cascade"). */
#define BC_DRUM_SHIFT 0.1
/* J: a band below this takes no part (nothing to scale) */
#define BC_E_MIN 1.0e-30

/* The bands, the interval and, for a plate, Gamma per unit of sum e_k / w_k (a head's rate
 * needs no constant: it reads the tension modulation's g). */
void membrane_band_cascade_refresh_(membrane *m)
{
    m->bc_on = 0;
    m->bc_bands = 0;
    const int live = m->modes;
    if (!(m->cascade > 0.0) || live < 2)
        return;
    if (m->plate ? !m->table.plate : !(membrane_tension_kappa(m) > 0.0))
        return; /* a membrane's cascade rides on its stretch: none on a linear head */
    /* f_k = j_k c / (2 pi a): third-octave bands from the lowest mode up */
    const double step = pow(2.0, 1.0 / 3.0);
    double edge = m->table.j[0] * step;
    int b = 0;
    m->bc_start[0] = 0;
    for (int k = 1; k < live; k++) {
        if (m->table.j[k] < edge || b + 1 >= BC_MAX_BANDS)
            continue;
        m->bc_start[++b] = k;
        while (edge <= m->table.j[k])
            edge *= step;
    }
    m->bc_start[++b] = live;
    m->bc_bands = b;
    if (m->bc_bands < 2)
        return;
    m->bc_interval = m->plate ? BC_INTERVAL : BC_DRUM_INTERVAL;
    m->bc_dt = m->bc_interval / m->sample_rate;
    m->bc_gamma_per_ew = 0.0;
    if (m->plate) {
        const double nu = MODE_TABLE_PLATE_NU, h = m->density / BC_BRONZE_RHO;
        const double mass = m->density * M_PI * m->radius * m->radius;
        m->bc_gamma_per_ew = m->cascade * 3.0 * (1.0 - nu * nu) / (h * h * mass);
    }
    m->bc_on = 1;
}

/* The fraction 1 - exp(-Gamma dt) of a pair's departure one update moves. A plate's Gamma:
 * cascade x 3 (1 - nu^2) / (h^2 M) x sum e_k / w_k (sum_e_over_j = sum e_k / j_k); a
 * membrane's: cascade x w01 x ((g - 1) / BC_DRUM_SHIFT)^2, g = sqrt(1 + kappa E) its
 * tension modulation's frequency factor as the coefficients have it (updated every
 * TM_INTERVAL samples from the same energy). */
static double cascade_fraction(const membrane *m, double sum_e_over_j)
{
    const double cw = membrane_wave_speed_(m) / m->radius; /* w_k = j_k c / a */
    double gamma;
    if (m->plate) {
        gamma = m->bc_gamma_per_ew * sum_e_over_j / cw;
    } else {
        const double eps = (m->tm_g - 1.0) / BC_DRUM_SHIFT;
        gamma = m->cascade * m->table.j[0] * cw * eps * eps;
    }
    return -expm1(-gamma * m->bc_dt);
}

int membrane_band_cascade_update_(membrane *m)
{
    for (int c = 0; c < m->point_count; c++)
        if (m->points[c]->active || m->points[c]->force_pending != 0.0)
            return 0;
    double r = m->plate ? 0.0 : cascade_fraction(m, 0.0);
    if (!m->plate && !(r > 1.0e-12 && r <= 1.0))
        return 1; /* a head's rate needs no sums: nothing to move */
    const float h = (float)m->coef_h;
    const int nb = m->bc_bands;
    double e0[BC_MAX_BANDS], ew = 0.0;
    /* e_k = ((h w' sc q)^2 + (sc p)^2) / 2 (the energy kernel's); a plate's sum e_k / j_k */
    for (int b = 0; b < nb; b++) {
        double e = 0.0;
        if (m->plate) {
            for (int k = m->bc_start[b]; k < m->bc_start[b + 1]; k++) {
                const float x = h * m->wm[k] * m->sc[k] * m->q[k], v = m->sc[k] * m->p[k];
                const double ek = 0.5 * ((double)x * x + (double)v * v);
                e += ek;
                ew += ek / m->table.j[k];
            }
        } else {
            /* in float, eight partial sums (vectorised): ~1e-7 of a band, far below the
             * energy a head's weakest damping takes over an update (6e-4 at t60 60 s) */
            float acc[8] = {0};
            const int end = m->bc_start[b + 1];
            int k = m->bc_start[b];
            for (; k + 8 <= end; k += 8)
                for (int l = 0; l < 8; l++) {
                    const float x = h * m->wm[k + l] * m->sc[k + l] * m->q[k + l];
                    const float v = m->sc[k + l] * m->p[k + l];
                    acc[l] += x * x + v * v;
                }
            for (; k < end; k++) {
                const float x = h * m->wm[k] * m->sc[k] * m->q[k], v = m->sc[k] * m->p[k];
                acc[0] += x * x + v * v;
            }
            for (int l = 0; l < 8; l++)
                e += 0.5 * acc[l];
        }
        e0[b] = m->bc_e[b] = e;
    }
    if (m->plate)
        r = cascade_fraction(m, ew);
    if (!(r > 1.0e-12) || !(r <= 1.0))
        return 1; /* nothing to move (or a state that is not finite: left to emit_sample) */
    double *e = m->bc_e;
    for (int parity = 0; parity < 2; parity++) {
        for (int b = parity; b + 1 < nb; b += 2) {
            if (!(e[b] > BC_E_MIN && e[b + 1] > BC_E_MIN))
                continue;
            const double na = m->bc_start[b + 1] - m->bc_start[b];
            const double nn = m->bc_start[b + 2] - m->bc_start[b + 1];
            const double d = fmin(0.0, (e[b] + e[b + 1]) * na / (na + nn) - e[b]) * r;
            e[b] += d;
            e[b + 1] -= d;
        }
    }
    int scaled = 0;
    for (int b = 0; b < nb; b++) {
        if (e[b] == e0[b] || !(e0[b] > BC_E_MIN) || !(e[b] > 0.0))
            continue;
        const float s = (float)(sqrt(e[b] / e0[b]));
        for (int k = m->bc_start[b]; k < m->bc_start[b + 1]; k++) {
            m->q[k] *= s;
            m->p[k] *= s;
        }
        scaled = 1;
    }
    /* The von Karman coupling follows the rescaled state (membrane_cascade.c). */
    if (scaled)
        membrane_cascade_rescaled_(m);
    return 1;
}
