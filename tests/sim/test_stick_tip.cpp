// The stick tip in the physics (DrumParams::stick_tip): the series law of the tip
// and the head (series_contact_stiffness) against its two parts, and a bead thrown
// at the head through ODE's soft contact with the scene's per-step secant, against
// the continuous model integrated here. The tips' constants are the published ones
// (docs/sound.md, "Stick tips"), written out here, not read from the table.
#include "ictus/sim/scene.hpp"

#include <catch2/catch.hpp>
#include <ode/ode.h>

#include <cmath>
#include <vector>

using namespace ictus;

namespace
{

struct OdeInit {
    OdeInit() { dInitODE2(0); }
    ~OdeInit() { dCloseODE(); }
};

struct Tip {
    const char *name;
    double k, alpha;
};
// Hertz, a 7 mm hickory bead on Mylar (4/3 E* sqrt(r)); felt: Chaigne & Askenfelt 1994.
const Tip kWood{"wood", 4.733e8, 1.5};
const Tip kFelt{"felt", 4.5e9, 2.5};
const double kHead = 5825.0; // the default head's spring, 2 pi T / ln(R / r_tip)
const double kDamp = 3.0;    // its damper, N s/m
const std::vector<double> kSpeeds = {0.5, 1.0, 2.0, 5.0, 10.0};

// The series force at depth d by bisection on the tip's compression x:
// k x^alpha = k_head (d - x) (independent of the Newton solve under test).
double series_force(const Tip &tip, double d)
{
    if (d <= 0.0)
        return 0.0;
    double lo = 0.0, hi = d;
    for (int i = 0; i < 200; ++i) {
        double x = 0.5 * (lo + hi);
        (tip.k * std::pow(x, tip.alpha) > kHead * (d - x) ? hi : lo) = x;
    }
    return kHead * (d - 0.5 * (lo + hi));
}

// Onset to return to the plane of a bead of mass m landing at v on the continuous
// series law with the head's damper, F = max(0, F_s(d) + c d'), by RK4 (dt 1 us).
double continuous_duration_ms(const Tip &tip, double m, double v)
{
    auto acc = [&](double d, double dd) {
        double f = series_force(tip, d) + kDamp * dd;
        return d > 0.0 && f > 0.0 ? -f / m : 0.0;
    };
    const double dt = 1e-6;
    double d = 0.0, dd = v, t = 0.0;
    for (int i = 0; i < 200000; ++i) {
        double a1 = acc(d, dd), a2 = acc(d + 0.5 * dt * dd, dd + 0.5 * dt * a1);
        double a3 = acc(d + 0.5 * dt * (dd + 0.5 * dt * a1), dd + 0.5 * dt * a2);
        double a4 = acc(d + dt * (dd + 0.5 * dt * a2), dd + dt * a3);
        double d1 = d + dt * dd + dt * dt / 6.0 * (a1 + a2 + a3);
        double dd1 = dd + dt / 6.0 * (a1 + 2 * a2 + 2 * a3 + a4);
        if (i > 0 && d1 < 0.0)
            return (t + dt * d / (d - d1)) * 1e3;
        d = d1;
        dd = dd1;
        t += dt;
    }
    return -1.0;
}

// The same bead through ODE: a sphere (5 mm) at the plane y = 0, steps of 1 ms, no
// gravity, each step's soft contact from the series secant at the present depth
// with the head's damper (as Scene::near_callback does). Onset and return to the
// plane interpolated between steps, as the strike detector does.
double ode_duration_ms(const Tip &tip, double m, double v)
{
    const double h = 0.001, r = 0.005;
    dWorldID world = dWorldCreate();
    dSpaceID space = dSimpleSpaceCreate(nullptr);
    dJointGroupID contacts = dJointGroupCreate(0);
    dGeomID plane = dCreatePlane(space, 0, 1, 0, 0);
    dBodyID ball = dBodyCreate(world);
    dMass mass;
    dMassSetSphereTotal(&mass, m, r);
    dBodySetMass(ball, &mass);
    dGeomID geom = dCreateSphere(space, r);
    dGeomSetBody(geom, ball);
    dBodySetPosition(ball, 0, r + v * h * 0.5, 0); // touches within the first step
    dBodySetLinearVel(ball, 0, -v, 0);
    double onset = -1.0, release = -1.0, prev = r + v * h * 0.5 - r;
    for (int step = 0; step < 1000 && release < 0.0; ++step) {
        dContact c;
        if (dCollide(geom, plane, 1, &c.geom, sizeof(dContactGeom)) > 0) {
            const SoftContact sc = soft_contact(
                h, series_contact_stiffness(kHead, tip.k, tip.alpha, c.geom.depth), kDamp, true);
            c.surface.mode = dContactSoftERP | dContactSoftCFM;
            c.surface.mu = 0.0;
            c.surface.soft_erp = sc.erp;
            c.surface.soft_cfm = sc.cfm;
            dJointAttach(dJointCreateContact(world, contacts, &c), ball, nullptr);
        }
        dWorldStep(world, h);
        dJointGroupEmpty(contacts);
        const double gap = dBodyGetPosition(ball)[1] - r; // < 0: in the head
        if (onset < 0.0 && gap <= 0.0)
            onset = (step + prev / (prev - gap)) * h;
        else if (onset >= 0.0 && gap > 0.0)
            release = (step + prev / (prev - gap)) * h;
        prev = gap;
    }
    dJointGroupDestroy(contacts);
    dSpaceDestroy(space);
    dWorldDestroy(world);
    return release < 0.0 ? -1.0 : (release - onset) * 1e3;
}

double loglog_slope(const std::vector<double> &x, const std::vector<double> &y)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0, n = static_cast<double>(x.size());
    for (size_t i = 0; i < x.size(); ++i) {
        sx += std::log(x[i]);
        sy += std::log(y[i]);
        sxx += std::log(x[i]) * std::log(x[i]);
        sxy += std::log(x[i]) * std::log(y[i]);
    }
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

} // namespace

TEST_CASE("stick tip: the series law carries one force through the tip and the head",
          "[sim][stick_tip]")
{
    for (const Tip &tip : {kWood, kFelt}) {
        for (double d = 1e-6; d < 0.03; d *= 1.7) {
            const double s = series_contact_stiffness(kHead, tip.k, tip.alpha, d);
            const double f = s * d, x = d - f / kHead; // the tip's compression
            INFO(tip.name << " at depth " << d << " m: secant " << s << " N/m");
            REQUIRE(x >= 0.0);
            CHECK(tip.k * std::pow(x, tip.alpha) == Approx(f).epsilon(1e-8));
            CHECK(f == Approx(series_force(tip, d)).epsilon(1e-8));
            CHECK(s < kHead);
        }
        CHECK(series_contact_stiffness(kHead, tip.k, tip.alpha, 0.0) == kHead);
        CHECK(series_contact_stiffness(kHead, 0.0, tip.alpha, 0.01) == kHead);
    }
}

TEST_CASE("stick tip: a bead on the head through ODE's soft contact lasts as the continuous "
          "series law",
          "[sim][stick_tip]")
{
    OdeInit ode;
    for (const Tip &tip : {kWood, kFelt}) {
        for (double m : {0.0136, 0.05}) {
            std::vector<double> ode_ms, law_ms;
            for (double v : kSpeeds) {
                ode_ms.push_back(ode_duration_ms(tip, m, v));
                law_ms.push_back(continuous_duration_ms(tip, m, v));
                WARN(tip.name << " " << m << " kg at " << v << " m/s: ODE " << ode_ms.back()
                              << " ms, continuous " << law_ms.back() << " ms");
            }
            const double s_ode = loglog_slope(kSpeeds, ode_ms),
                         s_law = loglog_slope(kSpeeds, law_ms);
            WARN(tip.name << " " << m << " kg: slope ODE " << s_ode << ", continuous " << s_law);
        }
    }
}
