// The stick-head contact's restitution (soft_contact(), scene.hpp) against
// the continuous spring-damper's: a ball of mass m thrown at a plane through
// ODE's soft contact bounces off at e = exp(-zeta pi / sqrt(1 - zeta^2)),
// zeta = c / (2 sqrt(k m)). ODE's plain mapping (the implicit Euler step)
// adds a numerical damping of h k and loses most of the bounce; with the
// compensation the bounce is the damper's.
#include "ictus/sim/scene.hpp"

#include <catch2/catch.hpp>
#include <ode/ode.h>

#include <cmath>
#include <random>

using namespace ictus;

namespace
{

struct OdeInit {
    OdeInit() { dInitODE2(0); }
    ~OdeInit() { dCloseODE(); }
};

// Throws a ball (radius 5 mm, mass m) down at v_in onto the plane y = 0 with
// the given contact, steps of h, no gravity; returns the speed it leaves at
// over v_in (0 if it is still in contact after 1 s).
double restitution(double m, const SoftContact &sc, double h, double v_in)
{
    dWorldID world = dWorldCreate();
    dSpaceID space = dSimpleSpaceCreate(nullptr);
    dJointGroupID contacts = dJointGroupCreate(0);
    dGeomID plane = dCreatePlane(space, 0, 1, 0, 0);
    dBodyID ball = dBodyCreate(world);
    dMass mass;
    dMassSetSphereTotal(&mass, m, 0.005);
    dBodySetMass(ball, &mass);
    dGeomID geom = dCreateSphere(space, 0.005);
    dGeomSetBody(geom, ball);
    dBodySetPosition(ball, 0, 0.005 + v_in * h * 0.5, 0); // touches within the first step
    dBodySetLinearVel(ball, 0, -v_in, 0);
    double v_out = 0.0;
    bool touched = false;
    for (int step = 0; step < static_cast<int>(1.0 / h); ++step) {
        dContact c;
        const int n = dCollide(geom, plane, 1, &c.geom, sizeof(dContactGeom));
        if (n > 0) {
            touched = true;
            c.surface.mode = dContactSoftERP | dContactSoftCFM;
            c.surface.mu = 0.0;
            c.surface.soft_erp = sc.erp;
            c.surface.soft_cfm = sc.cfm;
            dJointAttach(dJointCreateContact(world, contacts, &c), ball, nullptr);
        } else if (touched) {
            v_out = dBodyGetLinearVel(ball)[1];
            break;
        }
        dWorldStep(world, h);
        dJointGroupEmpty(contacts);
    }
    dJointGroupDestroy(contacts);
    dSpaceDestroy(space);
    dWorldDestroy(world);
    return v_out / v_in;
}

double theory(double m, double k, double c)
{
    const double zeta = c / (2.0 * std::sqrt(k * m));
    return std::exp(-zeta * M_PI / std::sqrt(1.0 - zeta * zeta));
}

} // namespace

TEST_CASE("contact: with the implicit step's numerical damping taken out, a ball bounces off "
          "the soft contact as off the continuous spring-damper",
          "[sim][scene][contact]")
{
    OdeInit ode;
    const double h = 0.001;
    // The default head against the stick's 14 g at the bead (docs/perform.md).
    {
        const double m = 0.014, k = 5825.0, c = 3.0;
        const double e_plain = restitution(m, soft_contact(h, k, c, false), h, 3.0);
        const double e_comp = restitution(m, soft_contact(h, k, c, true), h, 3.0);
        const double e_theory = theory(m, k, c);
        INFO("default head: theory " << e_theory << ", compensated " << e_comp << ", plain "
                                     << e_plain);
        CHECK(e_comp == Approx(e_theory).epsilon(0.15));
        CHECK(e_plain < 0.6 * e_theory); // the loss the compensation removes
    }
    // Random heads and sticks (seeded): masses 5-50 g, stiffness 1-20 kN/m,
    // damping ratios 0.02-0.2, within omega h <= 0.7 (the default head has
    // 0.17 and 0.65 with the stick's 14 g). The compensation is first order:
    // beyond that range the bounce comes out higher than the continuous one
    // (measured: 0.38-0.45 where theory gives 0.26-0.34 at zeta 0.3-0.4).
    std::mt19937 rng(20261124u);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int tried = 0;
    while (tried < 40) {
        const double m = 0.005 * std::pow(10.0, u(rng));
        const double k = 1000.0 * std::pow(20.0, u(rng));
        if (std::sqrt(k / m) * h > 0.7)
            continue;
        const double zeta = 0.02 + 0.18 * u(rng);
        const double c = 2.0 * zeta * std::sqrt(k * m);
        const double v = 0.5 + 9.5 * u(rng);
        ++tried;
        const double e = restitution(m, soft_contact(h, k, c, true), h, v);
        INFO("m " << m << " kg, k " << k << " N/m, zeta " << zeta << ", v " << v << " m/s: theory "
                  << theory(m, k, c) << ", compensated " << e);
        CHECK(e == Approx(theory(m, k, c)).epsilon(0.15));
    }
}

TEST_CASE("contact: an undamped head keeps a finite contact that does not gain energy",
          "[sim][scene][contact]")
{
    OdeInit ode;
    const SoftContact sc = soft_contact(0.001, 5825.0, 0.0, true);
    CHECK(std::isfinite(sc.erp));
    CHECK(std::isfinite(sc.cfm));
    CHECK(sc.cfm > 0.0);
    const double e = restitution(0.014, sc, 0.001, 3.0);
    CHECK(e > 0.8);
    CHECK(e <= 1.0);
}
