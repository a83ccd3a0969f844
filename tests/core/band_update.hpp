// One forced update of the energy cascade (membrane_band_cascade.c) against the relaxation
// computed in the test: the shared part of test_band_cascade.cpp and test_drum_cascade.cpp.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

extern "C" {
#include "membrane_internal.h"
}

// mode k's energy from the stored state (the energy kernel's formula)
inline double mode_energy(const membrane *m, int k)
{
    const double x = m->coef_h * m->wm[k] * m->sc[k] * m->q[k], v = (double)m->sc[k] * m->p[k];
    return 0.5 * (x * x + v * v);
}

inline std::vector<double> band_energies(const membrane *m)
{
    std::vector<double> e(m->bc_bands, 0.0);
    for (int b = 0; b < m->bc_bands; b++)
        for (int k = m->bc_start[b]; k < m->bc_start[b + 1]; k++)
            e[b] += mode_energy(m, k);
    return e;
}

struct band_update {
    double moved = 0.0, err = 0.0, before = 0.0, after = 0.0;
};

// Each band pair (even, then odd) whose lower band holds more energy per mode relaxes toward
// equal energy per mode by the fraction r (upward only); then the membrane runs its update at
// the next sample and the bands are compared with that prediction.
inline band_update forced_band_update(membrane *m, const std::vector<double> &e, double r)
{
    const int nb = m->bc_bands;
    std::vector<double> want = e;
    for (int parity = 0; parity < 2; parity++)
        for (int b = parity; b + 1 < nb; b += 2) {
            const double na = m->bc_start[b + 1] - m->bc_start[b];
            const double nn = m->bc_start[b + 2] - m->bc_start[b + 1];
            const double d = std::min(0.0, (want[b] + want[b + 1]) * na / (na + nn) - want[b]) * r;
            want[b] += d;
            want[b + 1] -= d;
        }
    m->bc_countdown = 0;
    membrane_process(m, nullptr, nullptr, 1);
    band_update u;
    const std::vector<double> got = band_energies(m);
    for (int b = 0; b < nb; b++) {
        u.before += e[b];
        u.after += got[b];
        u.moved += std::fabs(want[b] - e[b]);
        u.err += std::fabs(got[b] - want[b]);
    }
    return u;
}
