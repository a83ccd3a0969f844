// The bass-drum pedal (docs/pedal.md): the beater's one degree of freedom integrated by
// velocity Verlet at a fixed substep, the footboard's chain and the rest stop as one-sided
// inelastic constraints, the felt on the head by the project's contact law, and the planner
// that finds the foot's stroke for a note by simulating a copy forward.
#include "ictus/sim/kick_pedal.hpp"

#include "ictus/sim/sim_error.hpp"

#include "stick_tip.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

namespace ictus
{

namespace
{

constexpr double kPi = 3.14159265358979323846;

void check(const char *name, double v, double lo, double hi, bool lo_open, bool hi_open,
           const char *unit)
{
    bool ok = std::isfinite(v) && (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
    if (ok)
        return;
    std::ostringstream os;
    os << "kick pedal: " << name << " must be in " << (lo_open ? "(" : "[") << lo << ", " << hi
       << (hi_open ? ")" : "]") << (unit[0] ? " " : "") << unit << ", got " << v;
    throw SimError(os.str());
}

} // namespace

KickPedal::KickPedal(const KickPedalParams &p) : p_(p)
{
    check("beater_length_m", p.beater_length_m, 0.05, 0.5, false, false, "m");
    check("felt_mass_kg", p.felt_mass_kg, 0.0, 5.0, true, false, "kg");
    check("shaft_mass_kg", p.shaft_mass_kg, 0.0, 1.0, false, false, "kg");
    check("felt_radius_m", p.felt_radius_m, 0.0, 0.1, true, false, "m");
    check("axle_inertia_kg_m2", p.axle_inertia_kg_m2, 0.0, 0.1, false, false, "kg m^2");
    check("spring_stiffness_n_m_per_rad", p.spring_stiffness_n_m_per_rad, 0.0, 100.0, false, false,
          "N m/rad");
    check("spring_preload_n_m", p.spring_preload_n_m, 0.0, 100.0, false, false, "N m");
    check("axle_damping_n_m_s", p.axle_damping_n_m_s, 0.0, 10.0, false, false, "N m s");
    check("phi_head_rad", p.phi_head_rad, 0.0, kPi / 2.0, true, false, "rad");
    check("chain_ratio", p.chain_ratio, 0.0, 100.0, true, false, "");
    check("head_radius_m", p.head_radius_m, 0.05, 1.0, false, false, "m");
    check("head_tension_n_per_m", p.head_tension_n_per_m, 0.0, 1.0e5, true, false, "N/m");
    check("head_thickness_m", p.head_thickness_m, 0.0, 0.01, true, false, "m");
    check("head_modulus_pa", p.head_modulus_pa, 0.0, 1.0e12, false, false, "Pa");
    check("head_poisson", p.head_poisson, 0.0, 0.5, false, true, "");
    check("surface_stiffness_n_per_m", p.surface_stiffness_n_per_m, 0.0, 1.0e8, false, false,
          "N/m");
    check("surface_mu_s_per_m", p.surface_mu_s_per_m, 0.0, 10.0, false, false, "s/m");
    check("substep_s", p.substep_s, 0.0, 1.0e-3, true, false, "s");
    check("max_speed_mps", p.max_speed_mps, 0.0, 50.0, true, false, "m/s");
    check("min_speed_mps", p.min_speed_mps, 0.0, p.max_speed_mps, true, true, "m/s");
    check("stroke_max_s", p.stroke_max_s, 0.0, 1.0, true, false, "s");
    check("stroke_min_s", p.stroke_min_s, 0.0, p.stroke_max_s, true, false, "s");
    check("throw_fraction", p.throw_fraction, 0.0, 1.0, true, true, "");
    if (!(p.felt_radius_m < 0.5 * p.head_radius_m))
        check("felt_radius_m", p.felt_radius_m, 0.0, 0.5 * p.head_radius_m, true, true, "m");

    const stick_tip *felt = stick_tip_find("felt");
    if (!felt)
        throw SimError("kick pedal: the stick tip table has no felt");
    tip_k_ = p.felt_tip ? felt->stiffness : 0.0; // 0: the surface alone
    tip_alpha_ = felt->alpha;
    tip_mu_ = p.felt_tip ? felt->mu : p.surface_mu_s_per_m;
    const double l = p.beater_length_m;
    inertia_ = p.felt_mass_kg * l * l + p.shaft_mass_kg * l * l / 3.0 + p.axle_inertia_kg_m2;
    k1_ = 2.0 * kPi * p.head_tension_n_per_m / std::log(p.head_radius_m / p.felt_radius_m);
    k3_ = p.head_modulus_pa > 0.0 ? stick_tip_head_k3(p.head_modulus_pa, p.head_poisson,
                                                      p.head_thickness_m, p.head_radius_m)
                                  : 0.0;
    if (p.surface_stiffness_n_per_m > 0.0) {
        k1_ = p.surface_stiffness_n_per_m; // a plate: linear, no stretching
        k3_ = 0.0;
    }
    if (!p.felt_tip && !(k1_ > 0.0))
        throw SimError("kick pedal: without the felt the surface needs a stiffness");
    pushes_.reserve(64);
}

KickPedalParams hihat_pedal_params(double bending_n_m, double radius_m)
{
    check("hi-hat bending_n_m", bending_n_m, 0.0, 1.0e4, true, false, "N m");
    check("hi-hat radius_m", radius_m, 0.05, 1.0, false, false, "m");
    KickPedalParams p;
    const double lever_m = 0.1;           // L: a plate's travel x = L phi
    const double gap_m = 0.015;           // the plates apart when the pedal is up
    const double mass_kg = 0.94 + 0.25;   // 14-inch top plate, clutch and rod
    const double net_force_n = 20.0;      // spring 31.7 N less the weight 11.7 N, open
    const double spring_n_per_m = 500.0;  // +7.5 N at the gap closed
    const double damping_n_s_per_m = 0.5; // the rod in its tube, viscous
    const double plate_k = 16.0 * kPi * bending_n_m / (radius_m * radius_m);
    p.beater_length_m = lever_m;
    p.felt_mass_kg = mass_kg;
    p.shaft_mass_kg = 0.0;
    p.spring_preload_n_m = net_force_n * lever_m;
    p.spring_stiffness_n_m_per_rad = spring_n_per_m * lever_m * lever_m;
    p.axle_damping_n_m_s = damping_n_s_per_m * lever_m * lever_m;
    p.phi_head_rad = gap_m / lever_m;
    p.chain_ratio = 3.0;        // rod travel per footboard (0.3 m) angle, in L's
    p.head_radius_m = radius_m; // the membrane's fields are unused with a surface stiffness
    p.surface_stiffness_n_per_m = 0.5 * plate_k; // two plates in series
    p.felt_tip = false;
    p.surface_mu_s_per_m = 0.4; // a choice: bronze on bronze, restitution ~0.6-0.8 (tested)
    p.min_speed_mps = 0.2;
    p.max_speed_mps = 1.2;
    p.stroke_min_s = 0.025;
    p.stroke_max_s = 0.120;
    p.throw_fraction = 0.95; // the foot carries the plate to within 0.75 mm
    return p;
}

double KickPedal::contact_force_n(double d, double ddot) const
{
    if (!(d > 0.0))
        return 0.0;
    double f = stick_tip_series_force(tip_k_, tip_alpha_, k1_, k3_, d, nullptr);
    f *= 1.0 + tip_mu_ * ddot;
    return f > 0.0 ? f : 0.0;
}

double KickPedal::energy_j() const
{
    const double k = p_.spring_stiffness_n_m_per_rad, t0 = p_.spring_preload_n_m;
    return 0.5 * inertia_ * s_.omega * s_.omega + t0 * s_.phi + 0.5 * k * s_.phi * s_.phi;
}

void KickPedal::set_beater(double phi, double omega)
{
    check("set_beater phi_rad", phi, 0.0, p_.phi_head_rad, false, false, "rad");
    check("set_beater omega_rad_s", omega, -1.0e4, 1.0e4, false, false, "rad/s");
    s_.phi = phi;
    s_.omega = omega;
    s_.in_contact = false;
    anchor_valid_ = false;
}

namespace
{

// The quintic from (x0, v0, a0) to (x1, v1, 0) over T, at tau in [0, T]: position,
// velocity, acceleration.
void quintic(double x0, double v0, double a0, double x1, double v1, double T, double tau,
             double &pos, double &vel, double &acc)
{
    const double u = tau / T;
    const double b1 = v0 * T, b2 = 0.5 * a0 * T * T;
    const double d = x1 - (x0 + b1 + b2), e = v1 * T - (b1 + 2.0 * b2), g = -2.0 * b2;
    const double c3 = 10.0 * d - 4.0 * e + 0.5 * g, c4 = -15.0 * d + 7.0 * e - g,
                 c5 = 6.0 * d - 3.0 * e + 0.5 * g;
    pos = x0 + u * (b1 + u * (b2 + u * (c3 + u * (c4 + u * c5))));
    vel = (b1 + u * (2.0 * b2 + u * (3.0 * c3 + u * (4.0 * c4 + u * 5.0 * c5)))) / T;
    acc = (2.0 * b2 + u * (6.0 * c3 + u * (12.0 * c4 + u * 20.0 * c5))) / (T * T);
}

} // namespace

// The foot: the last push with t0 <= t sets the footboard angle. A push: up from the foot's
// state at t0 to the angle a with the speed vt over rise_s (the throw: the beater leaves
// the chain where the foot starts to slow), a stop over stop_s to a + vt stop_s / 2, and
// the release back to 0 over rise_s; each a quintic, continuous in angle, speed and
// acceleration.
KickPedal::FootState KickPedal::foot_at(double t, std::size_t upto) const
{
    std::size_t i = std::min(upto, pushes_.size());
    while (i > 0 && pushes_[i - 1].t0 > t)
        --i;
    if (i == 0)
        return {0.0, 0.0, 0.0};
    const Push &q = pushes_[i - 1];
    const double T = q.rise_s, Ts = q.stop_s, tau = t - q.t0;
    const double a_end = q.a + 0.5 * q.vt * Ts;
    FootState f{0.0, 0.0, 0.0};
    if (tau < T)
        quintic(q.p0, q.v0, q.acc0, q.a, q.vt, T, tau, f.pos, f.vel, f.acc);
    else if (tau < T + Ts)
        quintic(q.a, q.vt, 0.0, a_end, 0.0, Ts, tau - T, f.pos, f.vel, f.acc);
    else if (tau < 2.0 * T + Ts)
        quintic(a_end, 0.0, 0.0, 0.0, 0.0, T, tau - T - Ts, f.pos, f.vel, f.acc);
    if (f.pos < 0.0)
        f = {0.0, 0.0, 0.0}; // the footboard at its top: the chain slack
    return f;
}

double KickPedal::footboard_angle_rad() const
{
    return foot_at(t_, pushes_.size()).pos;
}

void KickPedal::record(const PedalStrike &s)
{
    std::size_t slot = (ring_head_ + ring_count_) % kRing;
    if (ring_count_ == kRing) {
        ring_head_ = (ring_head_ + 1) % kRing; // full: the oldest is dropped
        slot = (ring_head_ + kRing - 1) % kRing;
    } else {
        ++ring_count_;
    }
    ring_[slot] = s;
}

double KickPedal::next_onset_s() const
{
    return onset_count_ == 0 ? std::numeric_limits<double>::infinity()
                             : onsets_[onset_head_].time_s;
}

bool KickPedal::take_onset(PedalStrike &out)
{
    if (onset_count_ == 0)
        return false;
    out = onsets_[onset_head_];
    onset_head_ = (onset_head_ + 1) % onsets_.size();
    --onset_count_;
    return true;
}

void KickPedal::cancel_pending(double t_s)
{
    while (!pushes_.empty() && pushes_.back().t0 > t_s)
        pushes_.pop_back();
    anchor_valid_ = false;
}

bool KickPedal::take_strike(PedalStrike &out)
{
    if (ring_count_ == 0)
        return false;
    out = ring_[ring_head_];
    ring_head_ = (ring_head_ + 1) % kRing;
    --ring_count_;
    return true;
}

// One substep: velocity Verlet (kick, drift, kick) with the velocity-dependent terms
// (axle damping, Hunt-Crossley) at the half-step velocity, then the rest stop and the chain
// as inelastic one-sided constraints, then the contact episode's bookkeeping.
void KickPedal::step()
{
    const double h = p_.substep_s, L = p_.beater_length_m, ph = p_.phi_head_rad;
    const double k = p_.spring_stiffness_n_m_per_rad, t0 = p_.spring_preload_n_m,
                 c = p_.axle_damping_n_m_s;
    const double tn = static_cast<double>(s_.n) * h, t1 = static_cast<double>(s_.n + 1) * h;
    const double phi = s_.phi, om = s_.omega;
    const double f0 = contact_force_n(L * (phi - ph), L * om);
    const double a0 = (-t0 - k * phi - c * om - f0 * L) / inertia_;
    const double omh = om + 0.5 * h * a0;
    double phi1 = phi + h * omh;
    const double f1 = contact_force_n(L * (phi1 - ph), L * omh);
    const double a1 = (-t0 - k * phi1 - c * omh - f1 * L) / inertia_;
    double om1 = omh + 0.5 * h * a1;
    const double phi_free = phi1;

    if (phi1 < 0.0) {
        phi1 = 0.0;
        om1 = std::max(om1, 0.0);
    }
    const FootState foot = foot_at(t1, pushes_.size());
    const double r = p_.chain_ratio;
    if (phi1 < r * foot.pos) {
        phi1 = r * foot.pos;
        om1 = std::max(om1, r * foot.vel);
    }

    PedalStrike &cur = s_.cur;
    if (!s_.in_contact && phi_free > ph) {
        const double frac = std::clamp((ph - phi) / (phi_free - phi), 0.0, 1.0);
        cur = PedalStrike();
        cur.time_s = tn + frac * h;
        cur.speed_mps = L * (om + a0 * frac * h);
        cur.peak_force_n = f1;
        cur.impulse_n_s = 0.5 * (1.0 - frac) * h * f1;
        cur.effective_mass_kg = inertia_ / (L * L);
        // The first contact after the latest push's start is that push's; any other, a bounce.
        cur.bounce = true;
        for (std::size_t i = pushes_.size(); i > 0; --i) {
            Push &q = pushes_[i - 1];
            if (q.t0 <= cur.time_s) {
                cur.bounce = q.credited;
                q.credited = true;
                break;
            }
        }
        s_.in_contact = true;
        PedalStrike on = cur;
        on.peak_force_n = on.impulse_n_s = on.duration_ms = 0.0;
        const std::size_t slot = (onset_head_ + onset_count_) % onsets_.size();
        if (onset_count_ == onsets_.size())
            onset_head_ = (onset_head_ + 1) % onsets_.size(); // full: the oldest is dropped
        else
            ++onset_count_;
        onsets_[slot] = on;
    } else if (s_.in_contact) {
        if (phi_free <= ph) {
            const double frac = std::clamp((phi - ph) / (phi - phi_free), 0.0, 1.0);
            cur.impulse_n_s += 0.5 * frac * h * f0;
            cur.duration_ms = 1000.0 * (tn + frac * h - cur.time_s);
            s_.in_contact = false;
            record(cur);
        } else {
            cur.impulse_n_s += 0.5 * h * (f0 + f1);
            cur.peak_force_n = std::max(cur.peak_force_n, f1);
        }
    }
    s_.phi = phi1;
    s_.omega = om1;
    ++s_.n;
}

void KickPedal::advance_to(double t_s)
{
    if (!std::isfinite(t_s))
        throw SimError("kick pedal: advance_to t_s must be finite");
    if (t_s < t_)
        throw SimError("kick pedal: advance_to t_s must be >= time_s() (" + std::to_string(t_) +
                       " s), got " + std::to_string(t_s));
    const double h = p_.substep_s;
    while (static_cast<double>(s_.n + 1) * h <= t_s + 1e-12)
        step();
    t_ = t_s;
}

// Runs this (a planning copy) until the first contact credited to the last push, or the
// horizon. Returns its onset (or -1) and sets speed; *pre gets the state of the substep
// before the onset.
double KickPedal::onset_first_contact(double horizon_s, double &speed, State *pre)
{
    const double h = p_.substep_s;
    speed = 0.0;
    if (pushes_.empty())
        return -1.0;
    // Once the foot has stopped pushing (the throw and the stop are over), a beater at rest
    // or on its way back never reaches the head: the spring only pulls it back, and the
    // release only lowers the chain.
    const Push &q = pushes_.back();
    const double pushed_until = q.t0 + q.rise_s + q.stop_s;
    while (static_cast<double>(s_.n) * h < horizon_s) {
        State before = s_;
        step();
        if (q.credited) {
            if (pre)
                *pre = before;
            speed = s_.cur.speed_mps;
            return s_.cur.time_s;
        }
        if (s_.omega <= 0.0 && !s_.in_contact && static_cast<double>(s_.n) * h > pushed_until)
            return -1.0;
    }
    return -1.0;
}

// The push that starts at t0 with the stroke duration rise and reaches the speed v (when it
// can): one control, x in [-1, 1], by false position (Illinois) on the beater's speed at its
// first contact. x >= 0: the foot throws at a_cap - vt stop / 2 with the speed vt = x vt_max;
// x < 0: it does not throw (vt = 0) and goes only to (1 + x) a_cap.
KickPedal::Plan KickPedal::plan_at(const KickPedal &base, KickPedal &pre, double t0, double t_imp,
                                   double v, double rise) const
{
    const double h = p_.substep_s;
    const double a_cap = p_.throw_fraction * p_.phi_head_rad / p_.chain_ratio;
    const double ts = stop_time(rise);
    const double vt_max = 2.0 * a_cap / ts;
    if (static_cast<double>(pre.s_.n) * h > t0)
        pre = base;
    while (static_cast<double>(pre.s_.n + 1) * h <= t0)
        pre.step();
    const FootState f = pre.foot_at(t0, pre.pushes_.size());
    auto make = [&](double x) {
        Push q;
        q.t0 = t0;
        q.rise_s = rise;
        q.stop_s = ts;
        q.vt = x > 0.0 ? x * vt_max : 0.0;
        q.a = x > 0.0 ? a_cap - 0.5 * q.vt * ts : (1.0 + x) * a_cap;
        q.p0 = f.pos;
        q.v0 = f.vel;
        q.acc0 = f.acc;
        q.impact_time_s = t_imp;
        return q;
    };
    auto eval = [&](double x) {
        KickPedal sim = pre;
        sim.pushes_.push_back(make(x));
        Plan e;
        e.onset = sim.onset_first_contact(t0 + 2.0 * rise + ts + 0.3, e.speed, nullptr);
        e.found = e.onset >= 0.0;
        return e;
    };
    double x_lo = -1.0, x_hi = 1.0, x = 1.0;
    Plan e_hi = eval(x_hi), e = e_hi;
    if (e_hi.speed >= v) {
        Plan e_lo = eval(x_lo);
        if (e_lo.speed >= v) {
            x = x_lo;
            e = e_lo;
        } else {
            double g_lo = e_lo.speed - v, g_hi = e_hi.speed - v;
            int side = 0;
            for (int k = 0; k < 60; ++k) {
                x = (x_lo * g_hi - x_hi * g_lo) / (g_hi - g_lo);
                if (!(x > x_lo && x < x_hi))
                    x = 0.5 * (x_lo + x_hi);
                e = eval(x);
                const double g = e.speed - v;
                if (std::fabs(g) <= 1e-3 * v || x_hi - x_lo <= 1e-12)
                    break;
                if (g > 0.0) {
                    x_hi = x;
                    g_hi = g;
                    if (side == 1)
                        g_lo *= 0.5;
                    side = 1;
                } else {
                    x_lo = x;
                    g_lo = g;
                    if (side == -1)
                        g_hi *= 0.5;
                    side = -1;
                }
            }
        }
    }
    e.push = make(x);
    return e;
}

// The plan for one stroke duration: the push's start by fixed-point iteration on the onset,
// then, if that does not settle, by bisection between a start too early and one too late.
KickPedal::Plan KickPedal::plan_rise(const KickPedal &base, double t_lo, double t_imp, double v,
                                     double rise) const
{
    // A checkpoint of the pedal without the new push, shortly before the push's likely start:
    // the searches below restart from it, not from base (which may lie before the last
    // note's contact, whose substeps cost the most), unless they try an earlier start.
    KickPedal ck = base;
    const double t_ck = std::max(t_lo, t_imp - rise - 0.05);
    while (static_cast<double>(ck.s_.n + 1) * p_.substep_s <= t_ck)
        ck.step();
    auto from = [&](double t0) -> const KickPedal & {
        return static_cast<double>(ck.s_.n) * p_.substep_s <= t0 ? ck : base;
    };
    KickPedal pre = ck;
    Plan best;
    double best_err = 1e300;
    double early = -1.0, late = -1.0; // starts whose onsets were before / after t_imp
    auto keep = [&](const Plan &pl) {
        if (!pl.found)
            return;
        if (pl.onset < t_imp)
            early = std::max(early, pl.push.t0);
        else
            late = late < 0.0 ? pl.push.t0 : std::min(late, pl.push.t0);
        const double err = std::fabs(pl.onset - t_imp) + 1e-3 * std::fabs(pl.speed - v) / v;
        if (err < best_err) {
            best_err = err;
            best = pl;
        }
    };
    double t0 = std::max(t_lo, t_imp - rise - 0.010);
    for (int it = 0; it < 8; ++it) {
        const Plan pl = plan_at(from(t0), pre, t0, t_imp, v, rise);
        keep(pl);
        if (!pl.found)
            break;
        const double err = t_imp - pl.onset;
        if (std::fabs(err) < 5e-6)
            return best;
        if (t0 <= t_lo && err < 0.0)
            return best; // late even from the earliest start
        t0 = std::max(t_lo, t0 + err);
    }
    if (early < 0.0) {
        const Plan pl = plan_at(from(t_lo), pre, t_lo, t_imp, v, rise);
        keep(pl);
        if (!pl.found || pl.onset >= t_imp)
            return best;
    }
    if (late < 0.0)
        return best;
    for (int it = 0; it < 30 && late - early > 1e-7; ++it) {
        const double mid = 0.5 * (early + late);
        const Plan pl = plan_at(from(mid), pre, mid, t_imp, v, rise);
        if (!pl.found)
            break;
        keep(pl);
        if (std::fabs(pl.onset - t_imp) < 5e-6)
            break;
    }
    return best;
}

bool KickPedal::at_rest(double t) const
{
    const FootState f = foot_at(t, pushes_.size());
    return s_.phi == 0.0 && s_.omega == 0.0 && !s_.in_contact && f.pos == 0.0 && f.vel == 0.0 &&
           f.acc == 0.0;
}

bool KickPedal::plan_from_rest(const KickPedal &base, double t_lo, double t_imp, double v,
                               Plan &out)
{
    const RestPlan *c = nullptr;
    for (const RestPlan &r : rest_plans_)
        if (r.valid && r.speed == v)
            c = &r;
    if (!c)
        return false;
    const double h = p_.substep_s;
    double t0 = t_imp - c->lead_s;
    for (int it = 0; it < 2 && t0 >= t_lo; ++it) {
        KickPedal pre = base;
        while (static_cast<double>(pre.s_.n + 1) * h <= t0)
            pre.step();
        if (!pre.at_rest(t0))
            return false;
        Push q = c->push;
        q.t0 = t0;
        q.impact_time_s = t_imp;
        pre.pushes_.push_back(q);
        Plan e;
        e.onset = pre.onset_first_contact(t0 + 2.0 * q.rise_s + q.stop_s + 0.3, e.speed, nullptr);
        if (e.onset < 0.0)
            return false;
        if (std::fabs(e.onset - t_imp) <= 2e-5 && std::fabs(e.speed - v) <= 2e-3 * v) {
            e.found = true;
            e.push = q;
            out = e;
            return true;
        }
        t0 += t_imp - e.onset; // the substep grid's phase: once more, shifted
    }
    return false;
}

double KickPedal::schedule(double t_imp, double v)
{
    if (!std::isfinite(t_imp))
        throw SimError("kick pedal: schedule impact_time_s must be finite");
    if (!std::isfinite(v))
        throw SimError("kick pedal: schedule impact_speed_mps must be finite");
    if (!(t_imp > t_))
        throw SimError("kick pedal: schedule impact_time_s (" + std::to_string(t_imp) +
                       " s) must be after time_s() (" + std::to_string(t_) + " s)");
    const double last = pushes_.empty() ? -1.0 : pushes_.back().impact_time_s;
    if (!pushes_.empty() && !(t_imp > last))
        throw SimError("kick pedal: schedule impact_time_s (" + std::to_string(t_imp) +
                       " s) must be after the pending note at " + std::to_string(last) + " s");
    const double vc = std::clamp(v, p_.min_speed_mps, p_.max_speed_mps);
    // The pushes the foot finished over a second ago go (all but the latest): the list
    // stays short over a long performance, within its reserve.
    std::size_t done = 0;
    while (done + 1 < pushes_.size() &&
           pushes_[done].t0 + 2.0 * pushes_[done].rise_s + pushes_[done].stop_s < t_ - 1.0 &&
           pushes_[done + 1].t0 < t_ - 1.0)
        ++done;
    pushes_.erase(pushes_.begin(), pushes_.begin() + static_cast<long>(done));

    // Where planning starts: the state at the last planned first contact, or now if later.
    KickPedal base = *this;
    if (anchor_valid_ && anchor_.n > s_.n)
        base.s_ = anchor_;
    // A push starts after the last planned first contact (so that contact stays that note's).
    const double t_lo = std::max(t_, last + p_.substep_s);

    // The stroke's nominal duration falls with the speed; others, shorter first, if that one
    // does not land (too little time since the last note, or the wrong speed).
    const double x = (vc - p_.min_speed_mps) / (p_.max_speed_mps - p_.min_speed_mps);
    const double rise_fast = std::max(p_.stroke_min_s, 0.4 * p_.stroke_max_s);
    const double nominal = p_.stroke_max_s + (rise_fast - p_.stroke_max_s) * x;
    std::vector<double> rises{nominal};
    for (double r = 0.85 * nominal; r > p_.stroke_min_s; r *= 0.85)
        rises.push_back(r);
    rises.push_back(p_.stroke_min_s);
    for (double r = nominal / 0.85; r < p_.stroke_max_s; r /= 0.85)
        rises.push_back(r);
    rises.push_back(p_.stroke_max_s);
    Plan best;
    double best_cost = 1e300;
    const bool cached = plan_from_rest(base, t_lo, t_imp, vc, best);
    for (double rise : cached ? std::vector<double>{} : rises) {
        Plan pl = plan_rise(base, t_lo, t_imp, vc, rise);
        if (!pl.found)
            continue;
        const double terr = std::fabs(pl.onset - t_imp), verr = std::fabs(pl.speed - vc) / vc;
        const double cost = (terr > 2e-5 ? 1.0 + terr : 0.0) + verr;
        if (cost < best_cost) {
            best_cost = cost;
            best = pl;
        }
        if (terr <= 2e-5 && verr <= 2e-3)
            break;
    }
    if (!best.found) {
        // No stroke reaches the head (a note too close to now): the fastest stroke from the
        // earliest start, which lands late or not at all.
        KickPedal pre = base;
        best = plan_at(base, pre, t_lo, t_imp, p_.max_speed_mps, p_.stroke_min_s);
    }

    // Commit, and keep the state before the first contact as the next plan's start. A note
    // that lands late counts as pending until its real onset.
    if (best.onset > t_imp)
        best.push.impact_time_s = best.onset;
    KickPedal pre = base;
    while (static_cast<double>(pre.s_.n + 1) * p_.substep_s <= best.push.t0)
        pre.step();
    if (!cached && pre.at_rest(best.push.t0) && std::fabs(best.onset - t_imp) <= 2e-5 &&
        std::fabs(best.speed - vc) <= 2e-3 * vc) {
        RestPlan &r = rest_plans_[rest_next_];
        rest_next_ = (rest_next_ + 1) % rest_plans_.size();
        r.valid = true;
        r.speed = vc;
        r.lead_s = t_imp - best.push.t0;
        r.push = best.push;
    }
    pre.pushes_.push_back(best.push);
    double speed = 0.0;
    State at;
    if (pre.onset_first_contact(best.push.t0 + 2.0 * best.push.rise_s + best.push.stop_s + 0.3,
                                speed, &at) >= 0.0) {
        anchor_ = at;
        anchor_valid_ = true;
    } else {
        anchor_valid_ = false;
    }
    pushes_.push_back(best.push);
    return best.speed;
}

} // namespace ictus
