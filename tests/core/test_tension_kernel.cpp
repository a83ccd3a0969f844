// The tension update's vector kernels (membrane_kernel.inc): the rebuild of the
// coefficients at a new frequency factor, the points' couplings in the new coefficients
// and the energy of the stored state, checked
// against the midpoint rule's coefficients and the energy computed here in double, and
// the AVX2+FMA and AVX-512 copies against the portable one (bit for bit in float: the
// kernels keep the scalar formulas' order and stop FMA contraction).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "ictus_simd.h"
extern "C" {
#include "membrane_internal.h"
}

namespace
{
const int kCount = 1024, kLive = 1001; // the tail 1001..1023: fading modes, left alone
const float kH = 0.5f / 48000.0f, kEpt = 3.7e-4f, kG = 1.0031f;

// 64-byte aligned float arrays, as the membrane allocates them.
struct arrays {
    std::vector<float *> all;
    float *get()
    {
        all.push_back(membrane_alloc_floats_(kCount));
        return all.back();
    }
    ~arrays()
    {
        for (float *p : all)
            free(p);
    }
};

struct head {
    arrays mem;
    float *wm0 = mem.get(), *sm0 = mem.get(), *wm = mem.get(), *q = mem.get(), *p = mem.get();
    float *c1 = mem.get(), *cd = mem.get(), *c3 = mem.get(), *ep = mem.get(), *sc = mem.get();
    float *ep_k = mem.get(), *pick[2] = {mem.get(), mem.get()}, *pick_k[2] = {mem.get(), mem.get()};
    float *psi[2] = {mem.get(), mem.get()}, *psi_k[2] = {mem.get(), mem.get()};
    membrane_tension_args args() const
    {
        membrane_tension_args a;
        std::memset(&a, 0, sizeof(a));
        a.count = kCount, a.live = kLive, a.g = kG, a.h = kH, a.ept = kEpt;
        a.wm0 = wm0, a.sm0 = sm0, a.wm = wm, a.q = q, a.p = p, a.c1 = c1, a.cd = cd, a.c3 = c3;
        a.ep = ep, a.sc = sc, a.ep_k = ep_k;
        for (int j = 0; j < 2; j++)
            a.psi_pick[j] = pick[j], a.pick_k[j] = pick_k[j];
        a.points = 2;
        for (int c = 0; c < 2; c++)
            a.psi[c] = psi[c], a.psi_k[c] = psi_k[c];
        return a;
    }
};

// A head with partials up to 20 kHz at w' = 0.9998 wm0 (the last update), every 37th
// mode silent (w' = 0), and garbage coefficients in the silent and fading lanes.
void fill(head &h, unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f), pos(0.0f, 1.0f);
    for (int k = 0; k < kCount; k++) {
        h.wm0[k] = 2.0f * (float)M_PI * (60.0f + 20000.0f * pos(rng));
        h.sm0[k] = 1.0f + 400.0f * pos(rng);
        h.wm[k] = (k % 37 == 5) ? 0.0f : 0.9998f * h.wm0[k];
        float d = 1.0f + 2.0f * kH * h.sm0[k] + kH * kH * h.wm[k] * h.wm[k];
        h.sc[k] = std::sqrt(2.0f / d);
        h.q[k] = u(rng), h.p[k] = u(rng);
        h.c1[k] = u(rng), h.cd[k] = u(rng), h.c3[k] = u(rng), h.ep[k] = u(rng), h.ep_k[k] = u(rng);
        for (int j = 0; j < 2; j++)
            h.pick[j][k] = u(rng), h.psi[j][k] = u(rng);
    }
}

// A wide copy of the kernels: its name and its three entry points.
struct wide_kernels {
    ictus_simd level;
    double (*energy)(const float *, const float *, const float *, const float *, float, int);
    void (*tension)(membrane_tension_args *);
    void (*couplings)(membrane_tension_args *);
};
const wide_kernels kWide[] = {
    {ICTUS_SIMD_AVX2, membrane_energy_kernel_avx2, membrane_tension_kernel_avx2,
     membrane_couplings_kernel_avx2},
    {ICTUS_SIMD_AVX512, membrane_energy_kernel_avx512, membrane_tension_kernel_avx512,
     membrane_couplings_kernel_avx512},
};

double mode_energy(float h, float w, float sc, float q, float p)
{
    double qe = (double)h * w * sc * q, pe = (double)sc * p;
    return qe * qe + pe * pe;
}
} // namespace

TEST_CASE("Tension rebuild: the midpoint rule's coefficients at g w0, each mode's energy kept",
          "[core][membrane][tension]")
{
    head before, after;
    fill(before, 11);
    fill(after, 11);
    membrane_tension_args a = after.args();
    membrane_tension_kernel_generic(&a);
    membrane_couplings_kernel_generic(&a);
    double self[2] = {0, 0}, coupling[2][2] = {{0, 0}, {0, 0}};
    for (int k = 0; k < kCount; k++) {
        const bool live = k < kLive && before.wm[k] > 0.0f;
        INFO("mode " << k << (live ? " live" : " left alone"));
        if (!live) {
            // Not rebuilt: every array as it was.
            CHECK(after.c1[k] == before.c1[k]);
            CHECK(after.ep[k] == before.ep[k]);
            CHECK(after.q[k] == before.q[k]);
            CHECK(after.wm[k] == before.wm[k]);
        } else {
            // x+ = (I - hA)^-1 (I + hA) x for x' = A x, A = [[0, w], [-w, -2 s]]:
            // D = 1 + 2 h s + (h w)^2 (docs/membrane.md), in double here.
            double w = (double)kG * before.wm0[k], s = before.sm0[k], hw = (double)kH * w;
            double D = 1.0 + 2.0 * kH * s + hw * hw;
            CHECK(after.wm[k] == Approx(w).epsilon(2e-7));
            CHECK(after.c1[k] == Approx(2.0 * hw * hw / D).epsilon(1e-6));
            CHECK(after.cd[k] == Approx(2.0 / D).epsilon(1e-6));
            CHECK(after.c3[k] == Approx((2.0 * hw * hw + 4.0 * kH * s) / D).epsilon(1e-6));
            CHECK(after.ep[k] == Approx(kEpt / D).epsilon(1e-6));
            CHECK(after.sc[k] == Approx(std::sqrt(2.0 / D)).epsilon(1e-6));
            CHECK(after.ep_k[k] == Approx(kEpt / D / std::sqrt(2.0 / D)).epsilon(1e-6));
            double e0 = mode_energy(kH, before.wm[k], before.sc[k], before.q[k], before.p[k]);
            double e1 = mode_energy(kH, after.wm[k], after.sc[k], after.q[k], after.p[k]);
            CHECK(e1 == Approx(e0).epsilon(1e-6));
        }
        for (int j = 0; j < 2; j++) {
            CHECK(after.pick_k[j][k] ==
                  Approx((double)before.pick[j][k] * after.sc[k]).epsilon(1e-7));
            CHECK(after.psi_k[j][k] ==
                  Approx((double)before.psi[j][k] * after.sc[k]).epsilon(1e-7));
            double psi = before.psi[j][k];
            self[j] += psi * psi * after.ep[k];
            for (int i = 0; i < 2; i++)
                coupling[j][i] += (double)before.pick[i][k] * psi * after.ep[k];
        }
    }
    for (int c = 0; c < 2; c++) {
        CHECK(a.self_sum[c] == Approx(self[c]).epsilon(1e-12));
        for (int j = 0; j < 2; j++)
            CHECK(a.pick_coupling[c][j] == Approx(coupling[c][j]).epsilon(1e-9).margin(1e-12));
    }
}

TEST_CASE("Tension rebuild and energy: the AVX2 and AVX-512 kernels agree with the portable ones",
          "[core][membrane][tension]")
{
    const ictus_simd cpu = ictus_simd_cpu();
    for (const wide_kernels &k : kWide) {
        const char *name = ictus_simd_name(k.level);
        if (cpu < k.level) {
            WARN("no " << name << " on this CPU: that copy is not compared");
            continue;
        }
        INFO("kernels: " << name);
        head x, y;
        fill(x, 23);
        fill(y, 23);
        double ex = membrane_energy_kernel_generic(x.q, x.p, x.wm, x.sc, kH, kLive);
        double ey = k.energy(y.q, y.p, y.wm, y.sc, kH, kLive);
        double e = 0.0; // the live modes only, in double
        for (int m = 0; m < kLive; m++)
            e += 0.5 * mode_energy(kH, x.wm[m], x.sc[m], x.q[m], x.p[m]);
        REQUIRE(e > 0.0);
        CHECK(ex == Approx(e).epsilon(1e-6));
        CHECK(ey == Approx(ex).epsilon(1e-12));
        membrane_tension_args a = x.args(), b = y.args();
        membrane_tension_kernel_generic(&a);
        membrane_couplings_kernel_generic(&a);
        k.tension(&b);
        k.couplings(&b);
        size_t differ = 0;
        for (size_t i = 0; i < x.mem.all.size(); i++)
            differ += std::memcmp(x.mem.all[i], y.mem.all[i], sizeof(float) * kCount) != 0;
        CHECK(differ == 0);
        for (int c = 0; c < 2; c++) {
            CHECK(b.self_sum[c] == Approx(a.self_sum[c]).epsilon(1e-12));
            for (int j = 0; j < 2; j++)
                CHECK(b.pick_coupling[c][j] ==
                      Approx(a.pick_coupling[c][j]).epsilon(1e-9).margin(1e-12));
        }
    }
}
