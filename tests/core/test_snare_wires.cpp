// Snare wires on a membrane (snare_wires.h): they collide with the head and leave it
// again (a buzz, not a load), the head and the wires together never gain energy after
// a strike (the discrete-gradient collision passes energy exactly; the springs' damper
// only takes it), and detached wires leave the membrane exactly as it is without them.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "signal_tools.hpp"

extern "C" {
#include "membrane_presets.h"
#include "snare_wires.h"
}

namespace
{
std::vector<float> render(membrane *m, int blocks, std::vector<double> *energy = nullptr,
                          snare_wires *w = nullptr)
{
    std::vector<float> out(64 * blocks), second(64);
    for (int b = 0; b < blocks; b++) {
        float *o[2] = {out.data() + 64 * b, second.data()};
        membrane_process(m, nullptr, o, 64);
        if (energy)
            energy->push_back(membrane_energy(m) + (w ? snare_wires_energy(w) : 0.0));
    }
    return out;
}
} // namespace

TEST_CASE("snare wires collide, leave the head, and never add energy", "[core][wires]")
{
    membrane *m = membrane_new(48000.0);
    REQUIRE(membrane_apply_preset(m, membrane_preset_find("snare")) == ICTUS_OK);
    snare_wires *w = snare_wires_new();
    REQUIRE(snare_wires_attach(w, m) == ICTUS_OK);
    CHECK(snare_wires_membrane(w) == m);
    // A mezzo-forte impulse: a 50 g stick at 2.5 m/s stopped dead, 0.125 N s.
    REQUIRE(membrane_strike(m, 0.3, 0.0, 0.125, 0) == ICTUS_OK);
    std::vector<double> e;
    render(m, 1, &e, w);
    const double e0 = e[0];
    render(m, 375, &e, w); // 0.5 s
    for (size_t i = 1; i < e.size(); i++)
        REQUIRE(e[i] <= e[i - 1] * (1.0 + 1e-6) + 1e-15);
    const long touching = snare_wires_contact_samples(w);
    INFO("samples in contact (two masses): " << touching);
    CHECK(touching > 100);
    CHECK(touching < 2 * 64 * 376 * 0.9); // they leave the head, again and again
    CHECK(e.back() < 1e-3 * e0);
    snare_wires_free(w);
    membrane_free(m);
}

TEST_CASE("detached wires leave the membrane as it is without them", "[core][wires]")
{
    membrane *plain = membrane_new(48000.0), *m = membrane_new(48000.0);
    REQUIRE(membrane_apply_preset(plain, membrane_preset_find("snare")) == ICTUS_OK);
    REQUIRE(membrane_apply_preset(m, membrane_preset_find("snare")) == ICTUS_OK);
    snare_wires *w = snare_wires_new();
    REQUIRE(snare_wires_attach(w, m) == ICTUS_OK);
    snare_wires_detach(w);
    CHECK(snare_wires_membrane(w) == nullptr);
    membrane_strike(plain, 0.3, 0.0, 0.05, 0);
    membrane_strike(m, 0.3, 0.0, 0.05, 0);
    CHECK(render(plain, 100) == render(m, 100));
    // Attached again, they change the sound.
    REQUIRE(snare_wires_attach(w, m) == ICTUS_OK);
    membrane_strike(plain, 0.3, 0.0, 0.05, 0);
    membrane_strike(m, 0.3, 0.0, 0.05, 0);
    CHECK(render(plain, 100) != render(m, 100));
    snare_wires_free(w);
    membrane_free(plain);
    membrane_free(m);
}
