// The hi-hat (membrane_presets.c "hihat", docs/plates.md "The hi-hat"): the top plate
// struck by a stick through contact.h, its pedal (openness) setting the loss the bottom
// plate puts on its edge. The decay is measured from the rendered signal (Schroeder's
// backward integration, a line fitted to the energy decay), against the acceptance's
// bounds: closed T60 < 0.3 s, open > 1 s, half between them.
#include <catch2/catch.hpp>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

extern "C" {
#include "contact.h"
#include "membrane_internal.h"
#include "membrane_presets.h"
}

namespace
{
const double fs = 48000.0;

membrane *hihat(double openness)
{
    membrane *m = membrane_new(fs);
    REQUIRE(m);
    REQUIRE(membrane_apply_preset(m, membrane_preset_find("hihat")) == ICTUS_OK);
    REQUIRE(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_OPENNESS, openness) == ICTUS_OK);
    return m;
}

// T60 (s) of y from its energy decay curve (M. R. Schroeder, "New method of measuring
// reverberation time", JASA 37, 1965): EDC(t) = sum of y^2 from t on, in dB; a line
// fitted by least squares from -5 dB to -25 dB, extrapolated to -60 dB (T20 x 3). The
// signal is rendered well past the -25 dB point, so the truncation of the sum matters
// little there. 0 when the curve does not reach -25 dB.
double schroeder_t60(const std::vector<float> &y, double rate)
{
    std::vector<double> edc(y.size() + 1, 0.0);
    for (size_t i = y.size(); i-- > 0;)
        edc[i] = edc[i + 1] + (double)y[i] * y[i];
    if (!(edc[0] > 0.0))
        return 0.0;
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    long n = 0;
    bool reached = false;
    for (size_t i = 0; i < y.size(); i++) {
        const double db = 10.0 * std::log10(edc[i] / edc[0] + 1e-300);
        if (db < -25.0) {
            reached = true;
            break;
        }
        if (db > -5.0)
            continue;
        const double t = (double)i / rate;
        sx += t, sy += db, sxx += t * t, sxy += t * db;
        n++;
    }
    if (!reached || n < 2)
        return 0.0;
    const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx); // dB/s
    return slope < 0.0 ? -60.0 / slope : 0.0;
}

// One stroke of a 13.8 g stick, wood tip, at 2 m/s on the bow (the preset's strike
// point, r/a 0.7), then the plate ringing: pickup 1 over `seconds`.
std::vector<float> stroke(membrane *m, double seconds, double speed = 2.0)
{
    contact *c = contact_new();
    REQUIRE(c);
    REQUIRE(membrane_attach_contact(m, c) == ICTUS_OK);
    contact_set_tip(c, "wood");
    REQUIRE(contact_hit_mass(c, speed, 0.7, 0.0, 0, 0.0138) == ICTUS_OK);
    const int block = 64, blocks = (int)(seconds * fs) / block;
    std::vector<float> y((size_t)blocks * block), o1(block);
    for (int b = 0; b < blocks; b++) {
        float *out[2] = {y.data() + (size_t)b * block, o1.data()};
        membrane_process(m, nullptr, out, block);
    }
    membrane_detach_contact(m, c);
    contact_free(c);
    return y;
}

double t60_at(double openness, double seconds)
{
    membrane *m = hihat(openness);
    const double t = schroeder_t60(stroke(m, seconds), fs);
    membrane_free(m);
    return t;
}
} // namespace

TEST_CASE("hihat: a plate preset, refused as a drum, its pedal not part of it", "[core][hihat]")
{
    const membrane_preset *p = membrane_preset_find("hihat");
    REQUIRE(p);
    CHECK(p->plate == 1);
    CHECK(p->edge_damp_n_s_per_m2 > 0.0);
    CHECK(std::string(membrane_preset_names()).find("hihat") != std::string::npos);
    CHECK(std::string(membrane_preset_drum_names()).find("hihat") == std::string::npos);
    // the top plate: 1.1 mm of bronze, D = E h^3 / (12 (1 - nu^2)), rho h = 8600 h
    CHECK(p->bending_n_m ==
          Approx(100e9 * std::pow(1.1e-3, 3) / (12.0 * (1 - 0.33 * 0.33))).epsilon(1e-3));
    CHECK(p->density_kg_per_m2 == Approx(8600.0 * 1.1e-3).epsilon(1e-6));
    // every other preset has no second plate
    for (int i = 0; i < membrane_preset_count(); i++)
        if (membrane_preset_at(i) != p)
            CHECK(membrane_preset_at(i)->edge_damp_n_s_per_m2 == 0.0);
    // the preset leaves the foot where it was
    membrane *m = membrane_new(fs);
    REQUIRE(m);
    REQUIRE(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_OPENNESS, 0.25) == ICTUS_OK);
    REQUIRE(membrane_apply_preset(m, p) == ICTUS_OK);
    CHECK(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_OPENNESS) == 0.25);
    REQUIRE(membrane_apply_preset(m, membrane_preset_find("crash")) == ICTUS_OK);
    CHECK(ictus_param_get(&membrane_params, m, MEMBRANE_PARAM_EDGE_DAMP) == 0.0);
    membrane_free(m);
}

TEST_CASE("hihat: the edge loss is the dashpot's modal rate, and no membrane feels it",
          "[core][hihat]")
{
    // Per mode: T60 = ln 1000 / (rate open + (1 - o)^2 c edge_k / (2 rho h a)), with
    // edge_k the edge integral of the mode shape squared computed here by a 720-point
    // sum of mode_table's shape (independent of the table's cached value).
    membrane *open = hihat(1.0), *half = hihat(0.5);
    const double c = ictus_param_get(&membrane_params, open, MEMBRANE_PARAM_EDGE_DAMP);
    const double rho_h = ictus_param_get(&membrane_params, open, MEMBRANE_PARAM_DENSITY);
    const double a = ictus_param_get(&membrane_params, open, MEMBRANE_PARAM_RADIUS);
    for (int k : {0, 1, 5, 40, 200}) {
        double f, t_open, t_half;
        int bm, bn, s;
        REQUIRE(membrane_get_mode(open, k, &f, &t_open, &bm, &bn, &s));
        REQUIRE(membrane_get_mode(half, k, &f, &t_half, &bm, &bn, &s));
        // the mass-normalised shape at the edge (r/a 1), times sqrt(rho h a^2)
        double edge = 0.0;
        const int steps = 720;
        for (int i = 0; i < steps; i++) {
            const double w = mode_table_shape(&open->table, k, 1.0, 2.0 * M_PI * i / steps);
            edge += w * w * (2.0 * M_PI / steps);
        }
        const double want =
            std::log(1000.0) / (std::log(1000.0) / t_open + 0.25 * c * edge / (2.0 * rho_h * a));
        INFO("mode " << k << " (" << bm << "," << bn << ") at " << f << " Hz");
        CHECK(t_half == Approx(want).epsilon(1e-9));
        CHECK(t_half < t_open);
    }
    membrane_free(open);
    membrane_free(half);
    // a membrane is fixed at its rim: the same edge loss changes no decay
    membrane *drum = membrane_new(fs), *plain = membrane_new(fs);
    REQUIRE(ictus_param_set(&membrane_params, drum, MEMBRANE_PARAM_EDGE_DAMP, 1000.0) == ICTUS_OK);
    REQUIRE(ictus_param_set(&membrane_params, drum, MEMBRANE_PARAM_OPENNESS, 0.0) == ICTUS_OK);
    for (int k = 0; k < membrane_get_modes(drum); k++) {
        double f, t0, t1;
        membrane_get_mode(drum, k, &f, &t0, nullptr, nullptr, nullptr);
        membrane_get_mode(plain, k, &f, &t1, nullptr, nullptr, nullptr);
        CHECK(t0 == Approx(t1).epsilon(1e-12));
    }
    membrane_free(drum);
    membrane_free(plain);
}

TEST_CASE("hihat: T60 from the rendered signal, closed < 0.3 s, open > 1 s, half between",
          "[core][hihat]")
{
    const double closed = t60_at(0.0, 1.5), half = t60_at(0.5, 3.0), open = t60_at(1.0, 8.0);
    std::printf("hihat T60 (Schroeder, T20 x 3): closed %.3f s, half %.3f s, open %.3f s\n", closed,
                half, open);
    CHECK(closed > 0.0);
    CHECK(closed < 0.3);
    CHECK(open > 1.0);
    CHECK(half > closed);
    CHECK(half < open);
}

TEST_CASE("hihat: seeded strokes at seeded openness never gain energy", "[core][hihat]")
{
    // speed 0.5..10 m/s, r/a 0..0.95, stick 5..60 g, wood or felt, openness 0..1
    std::mt19937 rng(29);
    std::uniform_real_distribution<double> speed(0.5, 10.0), ra(0.0, 0.95), mass(0.005, 0.06),
        pedal(0.0, 1.0);
    for (int i = 0; i < 10; i++) {
        const double v = speed(rng), r = ra(rng), mk = mass(rng), o = pedal(rng);
        const char *tip = i % 2 ? "felt" : "wood";
        INFO("stroke " << i << ": " << v << " m/s at r/a " << r << ", " << mk << " kg, " << tip
                       << ", openness " << o);
        membrane *m = hihat(o);
        contact *c = contact_new();
        REQUIRE(c);
        REQUIRE(membrane_attach_contact(m, c) == ICTUS_OK);
        contact_set_tip(c, tip);
        REQUIRE(contact_hit_mass(c, v, r, 30.0, 0, mk) == ICTUS_OK);
        std::vector<float> o0(64), o1(64);
        float *out[2] = {o0.data(), o1.data()};
        contact_report rep{};
        bool released = false;
        for (int b = 0; b < 48000 / 64 && !released; b++) {
            membrane_process(m, nullptr, out, 64);
            released = contact_take_report(c, &rep);
        }
        REQUIRE(released);
        const double e0 = 0.5 * mk * v * v;
        const double plate = membrane_energy(m);
        const double after = plate + 0.5 * mk * rep.rebound_velocity_mps * rep.rebound_velocity_mps;
        CHECK(std::isfinite(after));
        CHECK(after <= e0 * (1.0 + 1e-9));
        bool decays = true;
        for (int b = 0; b < 200; b++) {
            const double before = membrane_energy(m);
            membrane_process(m, nullptr, out, 64);
            decays = decays && membrane_energy(m) <= before * (1.0 + 1e-9);
        }
        CHECK(decays);
        membrane_detach_contact(m, c);
        contact_free(c);
        membrane_free(m);
    }
}

TEST_CASE("hihat: the pedal moved while the plate rings: no NaN, no jump, no energy from it",
          "[core][hihat]")
{
    // Open, struck at 6 m/s, ringing for 0.2 s; then the pedal closes and opens again
    // over 0.4 s in steps of 0.02 every 64 samples, with seeded jitter, as a pedal's
    // messages would. A change of openness changes how fast the modes decay, never
    // where the plate is or how fast it moves: the displacement and the velocity at the
    // stick's point and at the pickup are the same just before and just after each set.
    membrane *m = hihat(1.0);
    (void)stroke(m, 0.2, 6.0);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> jitter(-0.005, 0.005);
    std::vector<float> o0(64), o1(64);
    float *out[2] = {o0.data(), o1.data()};
    const double where[2][2] = {{0.7, 0.0}, {0.5, 0.0}};
    double w_scale = 0.0, v_scale = 0.0, w_moved = 0.0, v_moved = 0.0;
    bool finite = true, decays = true;
    double set_gain = 0.0;
    for (int b = 0; b < 100; b++) {
        const double ramp = b < 50 ? 1.0 - 0.02 * (b + 1) : 0.02 * (b - 49);
        const double o = std::min(1.0, std::max(0.0, ramp + jitter(rng)));
        double w0[2], v0[2];
        for (int i = 0; i < 2; i++) {
            w0[i] = membrane_displacement_at(m, where[i][0], where[i][1]);
            v0[i] = membrane_velocity_at(m, where[i][0], where[i][1]);
            w_scale = std::max(w_scale, std::fabs(w0[i]));
            v_scale = std::max(v_scale, std::fabs(v0[i]));
        }
        const double e0 = membrane_energy(m);
        REQUIRE(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_OPENNESS, o) == ICTUS_OK);
        // the discrete energy's stiffness term moves by O((sigma T)^2) with the damping
        // (the midpoint rule's map, largest near Nyquist): 1e-4 at most at a set, taken
        // away many times over by the block's decay
        set_gain = std::max(set_gain, membrane_energy(m) / e0 - 1.0);
        for (int i = 0; i < 2; i++) {
            w_moved = std::max(
                w_moved, std::fabs(membrane_displacement_at(m, where[i][0], where[i][1]) - w0[i]));
            v_moved = std::max(
                v_moved, std::fabs(membrane_velocity_at(m, where[i][0], where[i][1]) - v0[i]));
        }
        membrane_process(m, nullptr, out, 64);
        decays = decays && membrane_energy(m) <= e0;
        for (int i = 0; i < 64; i++)
            finite = finite && std::isfinite(o0[i]) && std::isfinite(o1[i]);
    }
    CHECK(finite);
    CHECK(decays);
    CHECK(set_gain < 1e-3);
    INFO("largest move at a set: displacement " << w_moved << " of " << w_scale << " m, velocity "
                                                << v_moved << " of " << v_scale << " m/s");
    CHECK(w_scale > 0.0);
    CHECK(w_moved <= 1e-4 * w_scale);
    CHECK(v_moved <= 1e-4 * v_scale);
    membrane_free(m);
}

TEST_CASE("hihat: openness and edgedamp out of range are clamped and said so", "[core][hihat]")
{
    membrane *m = hihat(0.5);
    const struct {
        int id;
        double value, want;
    } cases[] = {
        {MEMBRANE_PARAM_OPENNESS, 1.5, 1.0},   {MEMBRANE_PARAM_OPENNESS, -0.2, 0.0},
        {MEMBRANE_PARAM_OPENNESS, NAN, 1.0},   {MEMBRANE_PARAM_OPENNESS, INFINITY, 1.0},
        {MEMBRANE_PARAM_EDGE_DAMP, -1.0, 0.0}, {MEMBRANE_PARAM_EDGE_DAMP, 1e9, 1.0e4},
    };
    for (const auto &t : cases) {
        INFO(membrane_params.def[t.id].name << " " << t.value);
        CHECK(ictus_param_set(&membrane_params, m, t.id, t.value) == ICTUS_CLAMPED);
        CHECK(ictus_param_get(&membrane_params, m, t.id) == t.want);
    }
    CHECK(std::string(membrane_params.def[MEMBRANE_PARAM_OPENNESS].name) == "openness");
    CHECK(std::string(membrane_params.def[MEMBRANE_PARAM_EDGE_DAMP].name) == "edgedamp");
    CHECK(ictus_param_set(&membrane_params, m, MEMBRANE_PARAM_OPENNESS, 0.5) == ICTUS_OK);
    membrane_free(m);
}
