// Membrane physics: pitches, decay, mode selection by strike and pickup points,
// block-size independence and strike timing.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "ictus_simd.h"
#include "signal_tools.hpp"

namespace
{
// j_mn from scipy.special.jn_zeros (independent of ictus_bessel_zero), in the order
// of the first 20 modes of a circular membrane (cos/sin partners counted twice).
struct mode_row {
    int m, n;
    double j;
};
const mode_row first_modes[] = {
    {0, 1, 2.4048255576957729}, {1, 1, 3.8317059702075125}, {2, 1, 5.1356223018406828},
    {0, 2, 5.5200781102863106}, {3, 1, 6.3801618959239841}, {1, 2, 7.0155866698156188},
    {4, 1, 7.5883424345038035}, {2, 2, 8.4172441403998643}, {0, 3, 8.6537279129110125},
    {5, 1, 8.7714838159599537}, {3, 2, 9.7610231299816697}, {6, 1, 9.9361095242176845},
    {1, 3, 10.173468135062722},
};

struct membrane_deleter {
    void operator()(membrane *m) const { membrane_free(m); }
};
using membrane_ptr = std::unique_ptr<membrane, membrane_deleter>;

// The head of the Bessel tests (the `paper` head): no tension modulation, so every
// partial rings at j_mn c / (2 pi a) whatever the amplitude, and the t60/hfdamp law
// alone sets the decay (no radiation, no internal loss), and forces act at a point.
membrane *linear_membrane(double fs)
{
    membrane *m = membrane_new(fs);
    if (m) {
        ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_TENSION_MOD, 0.0);
        ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_RADIATION, 0.0);
        ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_LOSS_FACTOR, 0.0);
        ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_PATCH, 0.0);
    }
    return m;
}

double theory_hz(const membrane *m, double j)
{
    double c = std::sqrt(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_TENSION) /
                         ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_DENSITY));
    return j * c / (2.0 * M_PI * ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_RADIUS));
}
} // namespace

TEST_CASE("First 20 partials within 0.1 cent of j_mn c / (2 pi a)", "[core][membrane]")
{
    const double fs = 48000.0;
    membrane_ptr m(linear_membrane(fs));
    REQUIRE(m);
    membrane_set_modes(m.get(), 20);
    ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_T60, 60.0);
    ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_HF_DAMPING, 0.0);
    membrane_set_pickup(m.get(), 0, 0.61, 71.0);
    // Strike and pickup off every nodal line of the first 20 modes.
    membrane_strike(m.get(), 0.37, 23.0, 0.01, 0);
    const size_t n = 1u << 18, padded = 1u << 20;
    std::vector<float> x = tools::render(m.get(), n);
    std::vector<double> mag = tools::spectrum(x, padded);
    const double bin = fs / (double)padded;
    // 20 modes = the 13 distinct (m, n) above with partners: 1 + 2*... check count.
    int counted = 0;
    double worst = 0.0;
    for (const auto &row : first_modes) {
        counted += row.m ? 2 : 1;
        if (counted > 20)
            break;
        double f = theory_hz(m.get(), row.j);
        double measured = tools::peak_frequency(mag, bin, f, 2.0);
        double err = tools::cents(measured, f);
        INFO("mode (" << row.m << "," << row.n << ") theory " << f << " Hz, measured " << measured
                      << " Hz, " << err << " cent");
        CHECK(std::fabs(err) < 0.1);
        worst = std::max(worst, std::fabs(err));
    }
    WARN("worst partial error " << worst << " cent (48 kHz, FFT)");
}

TEST_CASE("Low modes at 96 kHz: pitch within 0.1 cent, T60 and hf law within 2 %",
          "[core][membrane]")
{
    const double fs = 96000.0;
    SECTION("fundamental near 50 Hz, t60 only")
    {
        membrane_ptr m(linear_membrane(fs));
        membrane_set_modes(m.get(), 3); // (0,1) and the (1,1) pair
        // c = 2 pi a f / j01 for f = 50 Hz.
        double c = 2.0 * M_PI * ictus_param_get(&membrane_params, m.get(), MEMBRANE_PARAM_RADIUS) *
                   50.0 / 2.4048255576957729;
        ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_TENSION,
                        c * c * ictus_param_get(&membrane_params, m.get(), MEMBRANE_PARAM_DENSITY));
        ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_T60, 4.0);
        ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_HF_DAMPING, 0.0);
        membrane_set_pickup(m.get(), 0, 0.5, 0.0);
        membrane_strike(m.get(), 0.5, 0.0, 0.01, 0); // theta 0: sin partner silent
        std::vector<float> x = tools::render(m.get(), (size_t)(fs * 2.0));
        auto modes = tools::prony(x, 2, fs, 240); // 400 Hz after decimation
        REQUIRE(modes.size() == 2);
        const double j[2] = {2.4048255576957729, 3.8317059702075125};
        for (int i = 0; i < 2; i++) {
            double f = theory_hz(m.get(), j[i]);
            double t60 = std::log(1000.0) / modes[i].decay_per_s;
            INFO("theory " << f << " Hz, measured " << modes[i].freq_hz << " Hz, T60 " << t60);
            CHECK(std::fabs(tools::cents(modes[i].freq_hz, f)) < 0.1);
            CHECK(std::fabs(t60 / 4.0 - 1.0) < 0.02);
            WARN("96 kHz mode " << i << ": " << tools::cents(modes[i].freq_hz, f)
                                << " cent, T60 error " << 100.0 * (t60 / 4.0 - 1.0) << " %");
        }
    }
    SECTION("single mode: log-envelope slope gives the T60")
    {
        membrane_ptr m(linear_membrane(fs));
        membrane_set_modes(m.get(), 1);
        double c = 2.0 * M_PI * ictus_param_get(&membrane_params, m.get(), MEMBRANE_PARAM_RADIUS) *
                   50.0 / 2.4048255576957729;
        ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_TENSION,
                        c * c * ictus_param_get(&membrane_params, m.get(), MEMBRANE_PARAM_DENSITY));
        const double t60 = 0.7;
        ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_T60, t60);
        membrane_strike(m.get(), 0.2, 0.0, 0.01, 0);
        std::vector<float> x = tools::render(m.get(), (size_t)(fs * 1.0));
        // Peak of |x| in each period (1920 samples at 50 Hz), regress log(peak) on time.
        const size_t period = 1920;
        double sx = 0, sy = 0, sxx = 0, sxy = 0;
        int count = 0;
        for (size_t start = period; start + period <= x.size(); start += period) {
            size_t best = start;
            for (size_t i = start; i < start + period; i++)
                if (std::fabs(x[i]) > std::fabs(x[best]))
                    best = i;
            double t = (double)best / fs, y = std::log(std::fabs(x[best]));
            sx += t, sy += y, sxx += t * t, sxy += t * y, count++;
        }
        double slope = (count * sxy - sx * sy) / (count * sxx - sx * sx);
        double measured = std::log(1000.0) / -slope;
        INFO("T60 set " << t60 << " s, measured " << measured << " s");
        CHECK(std::fabs(measured / t60 - 1.0) < 0.02);
        WARN("envelope T60 error " << 100.0 * (measured / t60 - 1.0) << " %");
    }
    SECTION("hf_damping law sigma = s0 + s1 w^2, s1 w_1k^2 = hf s0")
    {
        membrane_ptr m(linear_membrane(fs));
        membrane_set_modes(m.get(), 3);
        // Fundamental at 1 kHz so that the air-like term matters.
        double c = 2.0 * M_PI * ictus_param_get(&membrane_params, m.get(), MEMBRANE_PARAM_RADIUS) *
                   1000.0 / 2.4048255576957729;
        ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_TENSION,
                        c * c * ictus_param_get(&membrane_params, m.get(), MEMBRANE_PARAM_DENSITY));
        const double t60 = 1.5, hf = 2.0;
        ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_T60, t60);
        ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_HF_DAMPING, hf);
        membrane_set_pickup(m.get(), 0, 0.5, 0.0);
        membrane_strike(m.get(), 0.5, 0.0, 0.01, 0);
        std::vector<float> x = tools::render(m.get(), (size_t)(fs * 0.5));
        auto modes = tools::prony(x, 2, fs, 16); // 6 kHz after decimation
        REQUIRE(modes.size() == 2);
        // The law, computed here from the documented definition.
        const double w1 = 2.0 * M_PI * 1000.0, w2 = w1 * 3.8317059702075125 / 2.4048255576957729;
        const double wref = 2.0 * M_PI * 1000.0;
        const double rate1 = std::log(1000.0) / t60;
        const double s0 = rate1 / (1.0 + hf * (w1 / wref) * (w1 / wref));
        const double s1 = hf * s0 / (wref * wref);
        const double expect[2] = {std::log(1000.0) / (s0 + s1 * w1 * w1),
                                  std::log(1000.0) / (s0 + s1 * w2 * w2)};
        for (int i = 0; i < 2; i++) {
            double measured = std::log(1000.0) / modes[i].decay_per_s;
            INFO("mode " << i << " T60 expected " << expect[i] << " measured " << measured);
            CHECK(std::fabs(measured / expect[i] - 1.0) < 0.02);
            WARN("hf law mode " << i << " T60 error " << 100.0 * (measured / expect[i] - 1.0)
                                << " %");
        }
        CHECK(expect[1] < 0.75 * expect[0]); // the law really separates them
    }
}

TEST_CASE("Centre strike excites no m >= 1 mode", "[core][membrane]")
{
    const double fs = 48000.0;
    membrane_ptr m(linear_membrane(fs));
    membrane_set_modes(m.get(), 20);
    ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_T60, 30.0);
    ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_HF_DAMPING, 0.0);
    membrane_set_pickup(m.get(), 0, 0.55, 33.0);
    membrane_strike(m.get(), 0.0, 0.0, 0.01, 0);
    tools::render(m.get(), 100);
    // The state is axisymmetric: the same displacement on a circle at any angle.
    double w0 = membrane_displacement_at(m.get(), 0.5, 0.0);
    for (double th : {17.0, 90.0, 133.0, 270.0})
        CHECK(std::fabs(membrane_displacement_at(m.get(), 0.5, th) - w0) <= 1e-6 * std::fabs(w0));
    const size_t n = 1u << 16;
    std::vector<double> mag = tools::spectrum(tools::render(m.get(), n), n * 4, true);
    const double bin = fs / (double)(n * 4);
    double ref = 0.0;
    for (const auto &row : first_modes)
        if (row.m == 0)
            ref = std::max(ref, tools::band_max(mag, bin, theory_hz(m.get(), row.j), 1.0));
    REQUIRE(ref > 0.0);
    int counted = 0;
    for (const auto &row : first_modes) {
        counted += row.m ? 2 : 1;
        if (counted > 20 || row.m == 0)
            continue;
        double level = tools::band_max(mag, bin, theory_hz(m.get(), row.j), 1.0);
        double db = 20.0 * std::log10(level / ref + 1e-300);
        INFO("mode (" << row.m << "," << row.n << ") at " << db << " dB");
        CHECK(db < -80.0);
    }
}

TEST_CASE("A pickup on a nodal line does not hear that mode", "[core][membrane]")
{
    const double fs = 48000.0;
    const size_t n = 1u << 16;
    const double bin = fs / (double)(n * 4);
    auto level_at = [&](double pr, double pt, double sr, double st, double j) {
        membrane_ptr m(linear_membrane(fs));
        membrane_set_modes(m.get(), 8);
        ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_T60, 30.0);
        ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_HF_DAMPING, 0.0);
        membrane_set_pickup(m.get(), 0, pr, pt);
        membrane_strike(m.get(), sr, st, 0.01, 0);
        std::vector<double> mag = tools::spectrum(tools::render(m.get(), n), n * 4);
        return tools::band_max(mag, bin, theory_hz(m.get(), j), 1.0);
    };
    const double j01 = 2.4048255576957729, j02 = 5.5200781102863106, j11 = 3.8317059702075125;
    SECTION("mode (0,2) at r/a = j01/j02")
    {
        double heard = level_at(0.0, 0.0, 0.0, 0.0, j02);
        double nodal = level_at(j01 / j02, 0.0, 0.0, 0.0, j02);
        INFO("(0,2) at its nodal circle: " << 20 * std::log10(nodal / heard) << " dB");
        CHECK(nodal < 1e-4 * heard);
    }
    SECTION("m = 1 cos mode with pickup at 90 degrees")
    {
        // Strike at theta 0 excites only the cos partner of (1,1).
        double heard = level_at(0.5, 0.0, 0.5, 0.0, j11);
        double nodal = level_at(0.5, 90.0, 0.5, 0.0, j11);
        INFO("(1,1) cos at 90 degrees: " << 20 * std::log10(nodal / heard) << " dB");
        CHECK(nodal < 1e-4 * heard);
    }
}

TEST_CASE("Block size does not change the output", "[core][membrane]")
{
    auto run = [](int block) {
        membrane_ptr m(membrane_new(44100.0));
        membrane_set_modes(m.get(), 40);
        contact *c = contact_new();
        membrane_attach_contact(m.get(), c);
        // Every event is scheduled up front with absolute offsets.
        membrane_strike(m.get(), 0.4, 10.0, 0.002, 100);
        membrane_strike(m.get(), 0.7, 200.0, 0.001, 1500);
        contact_hit(c, 3.0, 0.3, 45.0, 300);
        std::vector<float> out, fin((size_t)block), o0((size_t)block), o1((size_t)block);
        float *outs[2] = {o0.data(), o1.data()};
        size_t t = 0;
        while (out.size() < 4096) {
            for (int i = 0; i < block; i++, t++)
                fin[(size_t)i] = (t >= 2000 && t < 2010) ? 5.0f : 0.0f;
            membrane_process(m.get(), fin.data(), outs, block);
            for (int i = 0; i < block; i++) {
                out.push_back(o0[(size_t)i]);
                out.push_back(o1[(size_t)i]);
            }
        }
        out.resize(8192);
        membrane_free(m.release());
        contact_free(c);
        return out;
    };
    std::vector<float> a = run(1), b = run(64), c = run(1024);
    size_t differ_b = 0, differ_c = 0;
    for (size_t i = 0; i < a.size(); i++) {
        differ_b += a[i] != b[i];
        differ_c += a[i] != c[i];
    }
    CHECK(differ_b == 0);
    CHECK(differ_c == 0);
    double energy = 0;
    for (float v : a)
        energy += (double)v * v;
    CHECK(energy > 0.0);
}

TEST_CASE("A strike lands at its sample offset", "[core][membrane]")
{
    for (int offset : {0, 1, 37, 63, 64, 200}) {
        membrane_ptr m(membrane_new(48000.0));
        membrane_set_modes(m.get(), 16);
        membrane_strike(m.get(), 0.3, 0.0, 0.01, offset);
        std::vector<float> x = tools::render(m.get(), 256, 0, 64);
        int first = -1;
        for (int i = 0; i < 256; i++)
            if (x[(size_t)i] != 0.0f) {
                first = i;
                break;
            }
        INFO("offset " << offset);
        CHECK(first == offset);
    }
}

TEST_CASE("Changing the mode count keeps the sounding modes", "[core][membrane]")
{
    membrane_ptr m(membrane_new(48000.0));
    membrane_set_modes(m.get(), 10);
    membrane_strike(m.get(), 0.3, 10.0, 0.01, 0);
    tools::render(m.get(), 1000);
    double w = membrane_displacement_at(m.get(), 0.3, 10.0);
    double e = membrane_energy(m.get());
    membrane_set_modes(m.get(), 300); // grows (allocates): state of the 10 kept
    CHECK(membrane_displacement_at(m.get(), 0.3, 10.0) == Approx(w).epsilon(1e-6));
    CHECK(membrane_energy(m.get()) == Approx(e).epsilon(1e-6));
}

TEST_CASE("Tension change keeps physical velocity continuous", "[core][membrane]")
{
    membrane_ptr m(membrane_new(48000.0));
    membrane_set_modes(m.get(), 30);
    membrane_strike(m.get(), 0.3, 10.0, 0.01, 0);
    tools::render(m.get(), 777);
    double v = membrane_velocity_at(m.get(), 0.45, 70.0);
    double w = membrane_displacement_at(m.get(), 0.45, 70.0);
    ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_TENSION, 5000.0);
    ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_RADIUS, 0.2);
    ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_DENSITY, 0.3);
    CHECK(membrane_velocity_at(m.get(), 0.45, 70.0) == Approx(v).epsilon(1e-5));
    CHECK(membrane_displacement_at(m.get(), 0.45, 70.0) == Approx(w).epsilon(1e-5));
}

TEST_CASE("Setters while sounding do not click", "[core][membrane]")
{
    // A click is a step: the largest sample-to-sample difference right after a
    // change must stay within the range of the differences while ringing before.
    const char *names[] = {"tension",      "radius",      "density",    "t60",
                           "hf_damping",   "pickup",      "modes",      "gain",
                           "strike_point", "sample_rate", "fewer modes"};
    for (int which = 0; which < 11; which++) {
        membrane_ptr m(membrane_new(48000.0));
        membrane_set_modes(m.get(), 40);
        ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_T60, 3.0);
        membrane_strike(m.get(), 0.3, 10.0, 0.01, 0);
        std::vector<float> before = tools::render(m.get(), 4800);
        double max_step = 0.0;
        for (size_t i = 2400; i + 1 < before.size(); i++)
            max_step = std::max(max_step, (double)std::fabs(before[i + 1] - before[i]));
        switch (which) {
        case 0:
            ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_TENSION, 4000.0);
            break;
        case 1:
            ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_RADIUS, 0.16);
            break;
        case 2:
            ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_DENSITY, 0.3);
            break;
        case 3:
            ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_T60, 0.2);
            break;
        case 4:
            ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_HF_DAMPING, 20.0);
            break;
        case 5:
            membrane_set_pickup(m.get(), 0, 0.8, 200.0);
            break;
        case 6:
            membrane_set_modes(m.get(), 200);
            break;
        case 7:
            ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_GAIN, 0.5);
            break;
        case 8:
            membrane_set_strike_point(m.get(), 0.9, 90.0);
            break;
        case 9:
            membrane_set_sample_rate(m.get(), 44100.0);
            break;
        case 10:
            membrane_set_modes(m.get(), 3);
            break;
        }
        std::vector<float> after = tools::render(m.get(), 4800);
        double jump = std::fabs(after[0] - before.back());
        double after_step = jump;
        for (size_t i = 0; i + 1 < after.size(); i++)
            after_step = std::max(after_step, (double)std::fabs(after[i + 1] - after[i]));
        INFO(names[which] << ": step at the change " << jump << ", largest step after "
                          << after_step << ", largest before " << max_step);
        // The gain ramps from the default 0.16 to 0.5: later steps may grow by that ratio.
        const double allowed = which == 7 ? 1.5 * 0.5 / 0.16 : 1.5;
        CHECK(jump <= 1.5 * max_step);
        CHECK(after_step <= allowed * max_step);
    }
}

TEST_CASE("Modes above 0.95 Nyquist are silent", "[core][membrane]")
{
    // At 1 kHz only (0,1) at 230 Hz and (1,1) at 367 Hz lie below 475 Hz; (2,1) at
    // 491 Hz and (0,2) at 528 Hz (alias at 472 Hz) must not sound.
    const double fs = 1000.0;
    membrane_ptr m(linear_membrane(fs));
    membrane_set_modes(m.get(), 10);
    ictus_param_set(&membrane_params, m.get(), MEMBRANE_PARAM_T60, 20.0);
    membrane_set_pickup(m.get(), 0, 0.4, 20.0);
    membrane_strike(m.get(), 0.37, 23.0, 0.01, 0);
    const size_t n = 1u << 14;
    std::vector<double> mag = tools::spectrum(tools::render(m.get(), n), n * 4, true);
    const double bin = fs / (double)(n * 4);
    double ref = tools::band_max(mag, bin, theory_hz(m.get(), 2.4048255576957729), 1.0);
    CHECK(tools::band_max(mag, bin, theory_hz(m.get(), 3.8317059702075125), 1.0) > 1e-3 * ref);
    double f21 = theory_hz(m.get(), 5.1356223018406828),
           f02 = theory_hz(m.get(), 5.5200781102863106);
    CHECK(tools::band_max(mag, bin, f21, 1.0) < 1e-4 * ref);
    CHECK(tools::band_max(mag, bin, fs - f02, 1.0) < 1e-4 * ref);
}

extern "C" void membrane_use_kernel_(membrane *m, int level); // membrane_internal.h

TEST_CASE("Generic and run-time selected kernels agree", "[core][membrane]")
{
    // The tests above ran the kernel chosen at run time (AVX-512 or AVX2+FMA); every
    // copy this CPU runs must give the portable one's sound up to float rounding (FMA contraction
    // and the sums' order differ): 100 modes summed per sample in float, ~100 *
    // FLT_EPSILON ~ 1e-5 of the peak, and the contact feeds that back; a wrong
    // coefficient or a lane left out would be off by far more.
    auto run = [](int level) {
        membrane_ptr m(membrane_new(48000.0));
        membrane_use_kernel_(m.get(), level);
        membrane_set_modes(m.get(), 100);
        contact *c = contact_new();
        membrane_attach_contact(m.get(), c);
        membrane_strike(m.get(), 0.4, 10.0, 0.002, 5);
        contact_hit(c, 3.0, 0.3, 45.0, 100);
        std::vector<float> x = tools::render(m.get(), 4096);
        membrane_free(m.release());
        contact_free(c);
        return x;
    };
    const std::vector<float> b = run(ICTUS_SIMD_GENERIC);
    for (int level : {ICTUS_SIMD_AVX2, ICTUS_SIMD_AVX512}) {
        if (ictus_simd_cpu() < level) {
            WARN("no " << ictus_simd_name((ictus_simd)level) << " on this CPU: not compared");
            continue;
        }
        INFO("kernel " << ictus_simd_name((ictus_simd)level));
        const std::vector<float> a = run(level);
        double peak = 0.0, diff = 0.0;
        for (size_t i = 0; i < a.size(); i++) {
            peak = std::max(peak, (double)std::fabs(a[i]));
            diff = std::max(diff, (double)std::fabs(a[i] - b[i]));
        }
        INFO("largest difference " << diff << " of peak " << peak);
        REQUIRE(peak > 0.0);
        CHECK(diff <= 1e-4 * peak);
    }
}

TEST_CASE("ICTUS_MEMBRANE_KERNEL chooses the kernel of the membranes made after it",
          "[core][membrane]")
{
    // generic: the portable kernel anywhere; avx2: at most AVX2+FMA; avx512: the widest
    // the CPU has; unset: the widest, except AVX2 on AMD family 19h (Zen 4 splits
    // 512-bit operations in two), where AVX2 is the faster.
    auto made_with = [](const char *value) {
        if (value)
            REQUIRE(setenv("ICTUS_MEMBRANE_KERNEL", value, 1) == 0);
        else
            unsetenv("ICTUS_MEMBRANE_KERNEL");
        membrane_ptr m(membrane_new(48000.0));
        unsetenv("ICTUS_MEMBRANE_KERNEL");
        return std::string(membrane_kernel_name(m.get()));
    };
    const ictus_simd cpu = ictus_simd_cpu();
    const std::string widest = ictus_simd_name(cpu);
    const std::string at_most_avx2 = ictus_simd_name(cpu < ICTUS_SIMD_AVX2 ? cpu : ICTUS_SIMD_AVX2);
    INFO("this CPU runs up to " << widest);
    CHECK(made_with("generic") == "generic");
    CHECK(made_with("avx2") == at_most_avx2);
    CHECK(made_with("avx512") == widest);
    CHECK(made_with("no-such-kernel") == made_with(nullptr));
#if (defined(__x86_64__) || defined(__i386__)) && defined(__GNUC__)
    __builtin_cpu_init();
    const bool zen4_like = __builtin_cpu_is("amdfam19h");
#else
    const bool zen4_like = false;
#endif
    CHECK(made_with(nullptr) == (zen4_like ? at_most_avx2 : widest));
}

TEST_CASE("Without the second output the first pickup is the same, bit for bit", "[core][membrane]")
{
    // membrane_process() skips pickup 2 when out[1] is NULL (membrane~ with its
    // second outlet unconnected): pickup 1, the state and the contact must not
    // change at all, through strikes, a pressed stick, a moved pickup and new hits
    // at a point hit before (its shapes then come from the cache).
    auto run = [](bool second) {
        membrane_ptr m(membrane_new(48000.0));
        membrane_set_modes(m.get(), 300);
        contact *c = contact_new();
        ictus_param_set(&contact_params, c, CONTACT_PARAM_MASS, 2.0);
        membrane_attach_contact(m.get(), c);
        membrane_strike(m.get(), 0.4, 10.0, 0.002, 5);
        std::vector<float> o0(64), o1(64), out, force;
        float *outs[2] = {o0.data(), second ? o1.data() : nullptr};
        for (int b = 0; b < 300; b++) {
            if (b % 60 == 3)
                contact_hit(c, 1.5, 0.3, 20.0, b % 64);
            if (b == 100)
                membrane_set_pickup(m.get(), 0, 0.7, 10.0);
            if (b == 150)
                membrane_set_pickup(m.get(), 1, 0.2, 200.0);
            membrane_process(m.get(), nullptr, outs, 64);
            out.insert(out.end(), o0.begin(), o0.end());
            force.push_back((float)contact_last_force(c));
        }
        membrane_free(m.release());
        contact_free(c);
        out.insert(out.end(), force.begin(), force.end());
        return out;
    };
    std::vector<float> both = run(true), first = run(false);
    REQUIRE(both.size() == first.size());
    double peak = 0.0;
    size_t differ = 0;
    for (size_t i = 0; i < both.size(); i++) {
        peak = std::max(peak, (double)std::fabs(both[i]));
        differ += std::memcmp(&both[i], &first[i], sizeof(float)) != 0;
    }
    REQUIRE(peak > 0.0);
    CHECK(differ == 0);
}
