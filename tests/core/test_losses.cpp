// Losses from physics: each mode's T60 measured from the rendered output (complex
// demodulation at the mode's frequency, log-envelope slope) against the model's
// formula computed here with the standard library's Bessel functions: the
// baffled-membrane radiation integral, the internal loss eta w / 2 and the t60 term.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "membrane.h"

namespace
{
const double kFs = 48000.0, kA = 0.178, kT = 3000.0, kSigma = 0.262;
const double kT60 = 60.0, kEta = 0.002, kRad = 0.5;

// Decay rate of mode (m, n) with Bessel zero j (1/s), from the formula in
// docs/membrane.md, "Losses" (std::cyl_bessel_j, Simpson's rule on 2000 intervals).
double rate_theory(int m, double j)
{
    const double rho = 1.2, c_air = 343.0;
    const double w = j * std::sqrt(kT / kSigma) / kA, ka = w / c_air * kA;
    const int n = 2000;
    double sum = 0.0;
    for (int i = 0; i <= n; i++) {
        double t = 0.5 * M_PI * i / n, x = ka * std::sin(t), den = j * j - x * x;
        double f =
            std::fabs(den) < 1e-9 ? 0.0 : std::pow(std::cyl_bessel_j(m, x) / den, 2) * std::sin(t);
        sum += f * (i == 0 || i == n ? 1.0 : (i % 2 ? 4.0 : 2.0));
    }
    double integral = sum * (0.5 * M_PI / n) / 3.0;
    double rad = rho * w * w * kA * kA * j * j / (c_air * kSigma) * integral;
    return std::log(1000.0) / kT60 + 0.5 * kEta * w + kRad * rad;
}

// T60 (s) of the partial at f: the output demodulated at f under a 40 ms Hann window
// (the neighbours, >= 100 Hz away, leak in below -60 dB), its level fitted by least
// squares from 20 ms until it has fallen 40 dB (or the signal ends).
double t60_measured(const std::vector<float> &x, double f)
{
    const size_t avg = (size_t)(0.04 * kFs), hop = 240;
    std::vector<double> t, db;
    for (size_t s = (size_t)(0.0 * kFs); s + avg < x.size(); s += hop) {
        double re = 0.0, im = 0.0;
        for (size_t i = s; i < s + avg; i++) {
            double ph = 2.0 * M_PI * f * (double)i / kFs;
            double w = 0.5 - 0.5 * std::cos(2.0 * M_PI * (double)(i - s) / (double)avg);
            re += w * x[i] * std::cos(ph);
            im += w * x[i] * std::sin(ph);
        }
        double level = 10.0 * std::log10(re * re + im * im + 1e-300);
        if (!db.empty() && level < db.front() - 40.0)
            break;
        t.push_back((double)s / kFs + 0.02); // the window's centre
        db.push_back(level);
    }
    double mt = 0.0, md = 0.0;
    for (size_t i = 0; i < t.size(); i++)
        mt += t[i], md += db[i];
    mt /= (double)t.size(), md /= (double)t.size();
    double sxy = 0.0, sxx = 0.0;
    for (size_t i = 0; i < t.size(); i++)
        sxy += (t[i] - mt) * (db[i] - md), sxx += (t[i] - mt) * (t[i] - mt);
    return -60.0 / (sxy / sxx);
}

std::vector<float> render(double strike_r, double strike_th, double pick_r, double pick_th,
                          double seconds)
{
    membrane *m = membrane_new(kFs);
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_TENSION_MOD, 0.0); // a steady pitch
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_T60, kT60);
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_HF_DAMPING, 0.0);
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_LOSS_FACTOR, kEta);
    ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_RADIATION, kRad);
    membrane_set_modes(m, 40);
    membrane_set_pickup(m, 0, pick_r, pick_th);
    membrane_strike(m, strike_r, strike_th, 0.01, 0);
    std::vector<float> out((size_t)(seconds * kFs));
    for (size_t s = 0; s + 64 <= out.size(); s += 64) {
        float *o[2] = {&out[s], nullptr};
        membrane_process(m, nullptr, o, 64);
    }
    membrane_free(m);
    return out;
}
} // namespace

TEST_CASE("Losses: each mode's T60 from the output matches the radiation + internal law",
          "[core][membrane][losses]")
{
    struct row {
        int m, n;
        double j;
    };
    const double fscale = std::sqrt(kT / kSigma) / (2.0 * M_PI * kA);
    // m = 0 modes: struck and heard at the centre, nothing else sounds.
    const std::vector<float> centre = render(0.0, 0.0, 0.0, 0.0, 2.0);
    // (1,1) and (3,1): struck on the 0 degree diameter, heard at 45 degrees, where
    // the (2,1) cos mode has its nodal line.
    const std::vector<float> side = render(0.5, 0.0, 0.5, 45.0, 3.0);
    const row rows[] = {{0, 1, 2.4048255576957729},
                        {0, 2, 5.5200781102863106},
                        {0, 3, 8.6537279129110125},
                        {1, 1, 3.8317059702075125},
                        {3, 1, 6.3801618959239841}};
    double t01 = 0.0, t11 = 0.0;
    for (const row &r : rows) {
        double model = std::log(1000.0) / rate_theory(r.m, r.j);
        double meas = t60_measured(r.m == 0 ? centre : side, r.j * fscale);
        WARN("(" << r.m << "," << r.n << ") " << r.j * fscale << " Hz: T60 model " << model
                 << " s, measured " << meas << " s");
        CHECK(std::fabs(meas / model - 1.0) < 0.02);
        if (r.m == 0 && r.n == 1)
            t01 = meas;
        if (r.m == 1)
            t11 = meas;
    }
    // The monopole radiates most: the (0,1) mode dies before the (1,1) dipole.
    CHECK(t01 < 0.5 * t11);
}
