// stroke_model.cpp -- the parametric stroke model behind the built-in gesture
// database (docs/gestures.md, "The stroke model", for the sources of each
// choice). A unit is built in three layers:
//   1. the tip height h(t): a downswing from the preparation apex whose
//      acceleration grows toward the impact (h = H (1 - u^p), the "whip" of
//      Dahl 2004), a velocity reversal at the strike, and a lift back to an
//      apex whose shape is the nuance's (rebound, quick lift, held);
//   2. how that height is made: the stick turns about the wrist (German
//      grip, a wrist stroke in the stick's vertical plane) or about an axis
//      tilted toward the vertical (French grip, thumbs up: forearm rotation
//      plus wrist and finger flexion in the horizontal plane, which swings
//      the tip outward), up to a saturation; the rest is the forearm
//      lifting the wrist;
//   3. the nuance's forward path: the accent draws the arm back (a larger
//      loop), the vertical accent moves the wrist forward to cancel the arc.
// Every quantity is a smooth function of h(t), so the unit is C1 except at
// the strike, where the velocity reverses.
#include "ictus/gesture/gesture.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace ictus
{

namespace
{

constexpr double kPi = 3.14159265358979323846;
constexpr double kNominalPeriod_s = 0.5;    // 120 bpm: the period the shapes are set at
constexpr double kLegatoHeightFff_m = 0.36; // legato preparation height at d = 1
constexpr double kPressTau_s = 0.012;       // buzz: how fast the hand presses in
constexpr double kMaxPress_s = 0.3;         // buzz: the longest press
// The longest lift: at slower tempi the stick waits at the apex. A lift drawn
// out over the whole period leaves a soft stroke's stick on the head (30 bpm,
// pp legato: it fell back 24 ms after the strike and rested 38 ms).
constexpr double kMaxLift_s = 0.4;
constexpr double kReboundPeriod_s = 0.1;    // shorter periods: rebound strokes
constexpr double kReboundGainFrom_s = 0.2;
constexpr double kReboundGainExponent = 0.35;
// The lowest stroke: above the 1 cm a stick must rise between two strokes
// for the second to be a stroke, not a bounce (docs/osc.md).
constexpr double kMinHeight_m = 0.015;
// A floored short stroke's downswing (stroke_model): the lowest exponent (a
// constant acceleration from the apex) and the largest share of its period.
constexpr double kMinExponent = 2.0;
constexpr double kMaxDownswingShare = 0.75;

struct NuanceShape {
    double height_scale;  // preparation height relative to legato
    double prep_fraction; // downswing duration / nominal period
    double exponent;      // p in h = H (1 - u^p)
    double lift_exponent; // q in h = H_l (1 - (1 - w)^q): rebound speed q H_l / L
    double lift_hold;     // weight of a held (zero-speed) departure, tenuto
    double lift_ratio;    // lift apex / preparation apex
    double draw_back;     // extra backward pivot motion per metre of height (accent loop)
    double verticality;   // fraction of the arc's backward motion cancelled
    // Press (buzz): after the strike the tip is held into the head, down to
    // press_depth_m below it, over press_fraction of the lift time; the lift
    // follows.
    double press_depth_m = 0.0;
    double press_fraction = 0.0;
};

// Indexed by Nuance (enum order). See docs/gestures.md, table "Nuance shapes".
const NuanceShape kShapes[kNuances] = {
    // legato: relaxed rebound stroke
    {1.00, 0.35, 3.0, 2.0, 0.0, 1.00, 0.00, 0.0},
    // tenuto: low, stays close to the head after the strike
    {0.55, 0.40, 2.5, 2.0, 0.5, 0.80, 0.00, 0.0},
    // accent: higher preparation, larger loop, rebound controlled lower
    {1.70, 0.40, 3.0, 2.0, 0.0, 0.75, 0.10, 0.0},
    // vertical accent: highest, lifted vertically
    {1.90, 0.40, 3.0, 2.5, 0.0, 0.90, 0.00, 0.85},
    // staccato: lifts away quickly after the hit
    {1.15, 0.30, 3.0, 4.0, 0.0, 1.00, 0.00, 0.0},
    // buzz: a legato-like downswing, then pressed into the head 2 cm over 60 %
    // of the lift time (a loose grip then bounces the stick there), lifted low
    {0.75, 0.35, 3.0, 2.0, 1.0, 0.60, 0.00, 0.0, 0.02, 0.6},
};

// Impact speed per nuance relative to legato at the same dynamics (enum
// order): within 0.85..1.3, narrower than one dynamics level.
const double kSpeedScale[kNuances] = {1.0, 0.85, 1.2, 1.3, 1.1, 0.9};

struct GripShape {
    double pivot_to_tip_m;   // wrist to stick tip
    double rotation_share;   // fraction of the height made by turning the stick
    double axis_tilt_rad;    // rotation axis tilted from horizontal toward the vertical
    double inward_yaw_rad;   // stick direction at the strike, toward the body's midline
    double strike_pitch_rad; // stick direction at the strike, below horizontal
};

const GripShape kGerman = {0.35, 0.85, 0.0, 20.0 * kPi / 180.0, 8.0 * kPi / 180.0};
const GripShape kFrench = {0.33, 0.70, 25.0 * kPi / 180.0, 25.0 * kPi / 180.0, 8.0 * kPi / 180.0};

// Rebound strokes: below kReboundGainFrom_s the height is raised by
// (kReboundGainFrom_s / period)^kReboundGainExponent, so that the short,
// quick strokes of a double land as fast as the first one (the arm tracks
// their larger accelerations with a lag that costs impact speed:
// docs/score.md, "Rebound strokes").
double rebound_gain(double period_s)
{
    return period_s < kReboundGainFrom_s
               ? std::pow(kReboundGainFrom_s / period_s, kReboundGainExponent)
               : 1.0;
}

// Height profile at time t from the strike (s): prep over [-D, 0], lift over [0, L].
double height(const NuanceShape &s, double H, double H_lift, double D, double L, double t)
{
    if (t <= 0.0) {
        const double u = std::clamp((t + D) / D, 0.0, 1.0);
        return H * (1.0 - std::pow(u, s.exponent));
    }
    // The press: the hand keeps going into the head (press_depth_m, time
    // constant kPressTau_s), holds, and lets go over the last 30 % of it.
    const double P = std::min(s.press_fraction * L, kMaxPress_s);
    if (t < P) {
        const double x = std::clamp((t - 0.7 * P) / (0.3 * P), 0.0, 1.0);
        return -s.press_depth_m * (1.0 - std::exp(-t / kPressTau_s)) *
               (1.0 - x * x * (3.0 - 2.0 * x));
    }
    const double lift_end = std::min(L, P + kMaxLift_s);
    const double w = std::clamp((t - P) / (lift_end - P), 0.0, 1.0);
    const double rebound = 1.0 - std::pow(1.0 - w, s.lift_exponent);
    const double held = w * w * (3.0 - 2.0 * w);
    return H_lift * (s.lift_hold * held + (1.0 - s.lift_hold) * rebound);
}

} // namespace

double dynamics_height_level(double dynamics)
{
    return std::max(dynamics_height_factor(dynamics), kMinHeight_m / kLegatoHeightFff_m);
}

GestureUnit stroke_model(Grip g, Nuance n, Side h, double dynamics, double period_s)
{
    return stroke_model(g, n, h, dynamics, period_s, period_s);
}

GestureUnit stroke_model(Grip g, Nuance n, Side h, double dynamics, double prep_period_s,
                         double lift_period_s)
{
    const NuanceShape &s = kShapes[static_cast<int>(n)];
    const GripShape &gs = g == Grip::german ? kGerman : kFrench;
    const double d = std::isfinite(dynamics) ? std::clamp(dynamics, 0.0, 1.0) : 0.6;
    const auto clamp_period = [](double p) {
        return std::isfinite(p) ? std::clamp(p, 0.03, 4.0) : 0.5;
    };
    const double prep_period = clamp_period(prep_period_s);
    const double period = clamp_period(lift_period_s);
    // Rebound strokes (a period under kReboundPeriod_s) are sampled finer:
    // their downswing lasts a few 4 ms samples only.
    const double rate = std::min(prep_period, period) < kReboundPeriod_s ? 1000.0 : 250.0;

    // Timing: the downswing lasts prep_fraction of the period up to the
    // nominal period; at slower tempi the extra time is spent in the lift.
    // Heights shrink in proportion above the nominal tempo, so the impact
    // speed p H / D depends on the dynamics and the nuance, not the tempo.
    // The downswing is made for the time since the previous strike, the lift
    // for the time to the next one, each with the next (previous) stroke's
    // share: the lift of one stroke then reaches the height the next one
    // starts from, and the first stroke after a rest is a whole one even when
    // the next follows at once.
    // Heights: the nuance's, brought to the dynamics' impact speed (p H / D)
    // by kSpeedScale, in proportion to the period below the nominal one,
    // raised for rebound strokes; never under kMinHeight_m.
    const NuanceShape &leg = kShapes[0];
    const double speed_norm = kSpeedScale[static_cast<int>(n)] *
                              (leg.exponent / leg.prep_fraction) /
                              (s.height_scale * s.exponent / s.prep_fraction);
    const double level =
        kLegatoHeightFff_m * s.height_scale * speed_norm * dynamics_height_factor(d);
    const auto raw_height = [&](double p) {
        return level * std::min(1.0, p / kNominalPeriod_s) * rebound_gain(p);
    };
    // The downswing of a stroke made for period p: prep_fraction of it (up to
    // the nominal period) with the nuance's exponent, so that it hits at the
    // speed it has at the nominal period (times the rebound raise). Where the
    // floor raises a short stroke's height above its share (a soft rebound
    // stroke: a drag's second grace, 40 ms after the first), the same fall in
    // the same time would hit harder (p H / D): the exponent is lowered in
    // proportion instead, down to kMinExponent (a constant acceleration), and
    // below that the downswing lengthens, up to kMaxDownswingShare of the
    // period, so the speed stays that one while it can.
    struct Downswing {
        int samples;
        double exponent;
    };
    const auto downswing = [&](double p) {
        const double base = s.prep_fraction * std::min(p, kNominalPeriod_s);
        const double H_p = std::max(kMinHeight_m, raw_height(p));
        const double speed = s.exponent * std::max(kMinHeight_m, level) * rebound_gain(p) /
                             (s.prep_fraction * kNominalPeriod_s);
        Downswing ds{std::max(2, static_cast<int>(std::lround(base * rate))), s.exponent};
        if (s.exponent * H_p / base <= speed * (1.0 + 1e-9))
            return ds;
        ds.exponent = std::max(kMinExponent, speed * base / H_p);
        const double wanted = ds.exponent * H_p / speed;
        const double longest = std::max(base, kMaxDownswingShare * p);
        ds.samples =
            std::max(ds.samples, static_cast<int>(std::lround(std::min(wanted, longest) * rate)));
        return ds;
    };
    const Downswing prep = downswing(prep_period);
    const int strike_index = prep.samples;
    const int lift_samples =
        std::max(2, static_cast<int>(std::lround(period * rate)) - downswing(period).samples);
    const double D = strike_index / rate, L = lift_samples / rate;
    NuanceShape shape = s;
    shape.exponent = prep.exponent;
    const double H = std::max(kMinHeight_m, raw_height(prep_period));
    const double H_lift = std::max(kMinHeight_m, s.lift_ratio * raw_height(period));

    // Stick at the strike (right hand): forward, yawed inward (-x), pitched down.
    const Eigen::Vector3d dir0(-std::sin(gs.inward_yaw_rad) * std::cos(gs.strike_pitch_rad),
                               -std::sin(gs.strike_pitch_rad),
                               std::cos(gs.inward_yaw_rad) * std::cos(gs.strike_pitch_rad));
    const Eigen::Vector3d horiz = Eigen::Vector3d(dir0.x(), 0.0, dir0.z()).normalized();
    // Wrist axis: horizontal, across the stick; turning about it raises the
    // tip in the stick's vertical plane (German: wrist flexion, palms down).
    Eigen::Vector3d across = Eigen::Vector3d::UnitY().cross(horiz).normalized();
    if ((Eigen::AngleAxisd(0.1, across) * dir0).y() < dir0.y())
        across = -across; // the sign that raises the tip
    // French (thumbs up): wrist flexion turns the stick in the horizontal
    // plane, so the axis tilts toward the vertical and the tip swings
    // outward (+x for the right hand: Y x dir0 has x = dir0.z > 0).
    const Eigen::Vector3d axis = (std::cos(gs.axis_tilt_rad) * across +
                                  std::sin(gs.axis_tilt_rad) * Eigen::Vector3d::UnitY())
                                     .normalized();
    // Turning dir0 by phi about the axis: dir_y = c0 + (v_y - c0) cos phi + w sin phi
    // (Rodrigues), c0 = a_y (a . dir0), w = (a x dir0)_y. Inverted in closed
    // form for the rise the rotation must make.
    const double R = gs.pivot_to_tip_m;
    const double vy = dir0.y(), c0 = axis.y() * axis.dot(dir0), wy = axis.cross(dir0).y();
    const double A = std::hypot(vy - c0, wy), delta = std::atan2(wy, vy - c0);
    // The stick turns up to most of its range; smooth saturation (tanh) keeps C1.
    const double rise_cap = 0.8 * R * (c0 + A - vy);

    const Eigen::Vector3d pivot0 = -R * dir0; // tip at the origin at the strike
    GestureUnit u;
    u.grip = g;
    u.nuance = n;
    u.hand = h;
    u.rate_hz = rate;
    u.strike_index = strike_index;
    u.dynamics = d;
    u.period_s = period;
    u.source = "model";
    const int samples = strike_index + lift_samples + 1;
    u.tip_m.reserve(samples);
    u.stick_dir.reserve(samples);
    // The arc's backward motion is cancelled by moving the wrist forward
    // (vertical accent); computed after the rotation below.
    for (int k = 0; k < samples; ++k) {
        const double t = (k - strike_index) / rate;
        const double hk = height(shape, H, H_lift, D, L, t);
        const double rise_rot = rise_cap * std::tanh(gs.rotation_share * hk / rise_cap);
        const double target = std::clamp((vy + rise_rot / R - c0) / A, -1.0, 1.0);
        const double phi = delta - std::acos(target);
        const Eigen::Vector3d dir = Eigen::AngleAxisd(phi, axis) * dir0;
        Eigen::Vector3d tip = pivot0 + Eigen::Vector3d(0.0, hk - R * (dir.y() - vy), 0.0) + R * dir;
        const double arc_back = tip.z(); // < 0: the arc brings the tip toward the body
        tip.z() += -s.verticality * arc_back - s.draw_back * hk;
        tip.y() = hk; // exact (removes rounding of the decomposition)
        u.tip_m.push_back(tip);
        u.stick_dir.push_back(dir.normalized());
    }
    u.tip_m[strike_index] = Eigen::Vector3d::Zero();
    if (h == Side::left) // mirror image: x is the performer's right
        for (int k = 0; k < samples; ++k) {
            u.tip_m[k].x() = -u.tip_m[k].x();
            u.stick_dir[k].x() = -u.stick_dir[k].x();
        }
    return u;
}

} // namespace ictus
