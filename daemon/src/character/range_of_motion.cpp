// range_of_motion.cpp -- the normal human range of motion as swing-twist
// limits (range_of_motion.hpp; docs/character.md, "Range of motion").
#include "ictus/character/range_of_motion.hpp"
#include "ictus/base/rotation.hpp"

#include <algorithm>
#include <cmath>

namespace ictus
{

namespace
{

constexpr double kDeg = M_PI / 180.0;

// One row: a joint of the performer's right side (or the midline), its swing
// axes as world axes of the rest pose (0 x: the performer's left, 1 y: up,
// 2 z: forward), and its ranges in degrees. Positive swing about x tips a
// vertical segment forward; about z it turns the right arm or hand down (the
// right leg toward the midline); about y it swings the right arm forward.
// The left side is the mirror image: its y and z ranges are negated.
//
// Sources (normal adult male active ranges): American Academy of Orthopaedic
// Surgeons, "Joint motion: method of measuring and recording" (1965); Soucie
// et al., "Range of motion measurements: reference values and a database for
// comparison studies", Haemophilia 17 (2011) 500-507; Kapandji, "The
// physiology of the joints" (spine, clavicle). Ranges are those of the
// anatomical motions re-expressed about the rest (T-) pose: the shoulder's
// 180 deg of abduction from the arm hanging at the side are -90..+90 deg
// about z from the arm held out; a few degrees of margin on each side.
struct Row {
    const char *joint;
    int u_axis, w_axis;
    double u_lo, u_hi, w_lo, w_hi, twist; // deg; twist is +-
};

const Row kRows[] = {
    // spine: flexion 40 (forward), extension 20, lateral bend 20, rotation 20-25 per region
    {"lumbar", 0, 2, -20, 40, -20, 20, 20},
    {"thorax", 0, 2, -20, 40, -20, 20, 25},
    // neck: flexion 45, extension 45, lateral 35, rotation 50 (half of the cervical range each)
    {"neck", 0, 2, -45, 45, -35, 35, 50},
    {"upper_neck", 0, 2, -40, 40, -30, 30, 30},
    {"head", 0, 2, -30, 30, -20, 20, 30},
    // sternoclavicular: protraction / retraction 25, elevation 35, depression 10 (20 here:
    // the CMU skeleton's clavicle rests some degrees above the anatomical one), rotation 30
    {"r_clavicle", 1, 2, -25, 25, -35, 20, 30},
    // glenohumeral from the arm held out: horizontal flexion 135 (forward), extension 45-60,
    // abduction to 180 (-90 about z), adduction to the side and 20 past (+110), rotation 90-100
    {"r_shoulder", 1, 2, -60, 135, -95, 110, 100},
    // elbow: flexion 150; in the CMU skeleton's frames its axis lies between y and z (a
    // drummer's elbow in CMU 80_13: u 14..120, w -69..-8 deg), so both swing axes carry it;
    // hyperextension 10; half the forearm's pronation / supination as twist
    {"r_elbow", 1, 2, -10, 150, -80, 30, 45},
    // wrist: flexion 80 (down, palm down), extension 70, radial deviation 25, ulnar 35; the
    // CMU skeleton turns the forearm's pronation / supination (80-90 each way) here
    {"r_wrist", 1, 2, -35, 30, -75, 85, 85},
    // hip: flexion 125 (forward: -x), extension 30, abduction 45, adduction 30, rotation 45
    {"r_hip", 0, 2, -125, 30, -45, 30, 45},
    // knee: flexion 145 (+x), extension 5, rotation 30 when flexed
    {"r_knee", 0, 2, -5, 145, -10, 10, 30},
    // ankle: plantarflexion 50 (+x), dorsiflexion 25, ab/adduction 30, inversion / eversion 35
    {"r_ankle", 0, 1, -25, 50, -30, 30, 35},
};

} // namespace

Eigen::Vector3d SwingTwistLimit::coordinates(const Eigen::Quaterniond &q_in) const
{
    Eigen::Quaterniond q = q_in.normalized();
    if (q.w() < 0.0)
        q.coeffs() = -q.coeffs();
    // Twist: the rotation about twist_axis closest to q; swing = q twist^-1.
    // With w >= 0 the twist angle 2 atan2(along, w) lies in [-pi, pi] (no
    // wrapping), and the twist quaternion (cos, sin(twist / 2) axis) is
    // (w, along axis) / r, r = |(w, along)|: no sine or cosine of the angle.
    const double along = q.vec().dot(twist_axis);
    const double twist = 2.0 * std::atan2(along, q.w());
    const double r = std::sqrt(q.w() * q.w() + along * along);
    Eigen::Quaterniond swing = q;
    if (r > 0.0) { // r = 0: a half turn across the axis, no twist
        const Eigen::Vector3d t = (along / r) * twist_axis;
        const double tw = q.w() / r;
        // q * conj(twist_q)
        swing.w() = q.w() * tw + q.vec().dot(t);
        swing.vec() = tw * q.vec() - q.w() * t - q.vec().cross(t);
    }
    const Eigen::Vector3d v = log_map(swing.normalized());
    return Eigen::Vector3d(v.dot(u), v.dot(w), twist);
}

namespace
{
bool inside(const SwingTwistLimit &l, const Eigen::Vector3d &c, double tolerance_rad)
{
    return c[0] >= l.u_lo_rad - tolerance_rad && c[0] <= l.u_hi_rad + tolerance_rad &&
           c[1] >= l.w_lo_rad - tolerance_rad && c[1] <= l.w_hi_rad + tolerance_rad &&
           c[2] >= l.twist_lo_rad - tolerance_rad && c[2] <= l.twist_hi_rad + tolerance_rad;
}

// A sufficient test that q is inside, without trigonometry, square roots or
// divisions (most calls, every step: the IK's iterations, the targets, the
// stops, the excursion): false means "do the exact test". For a range
// holding 0 only the bound on the coordinate's side matters, and each
// coordinate is 2 atan(x) times a known factor, bounded with
// atan(x) <= x (15 + 4 x^2) / (15 + 9 x^2) for x >= 0 (odd in x): atan(x) / x
// = integral over [0, 1] of dt / (1 + x^2 t^2) is a Stieltjes function of
// x^2, whose [1/1] Pade approximant bounds it from above (within 0.8 % at
// x = 1, a 90 degree swing; |atan x| <= |x|, 27 % off there, made the elbows
// of a drummer's strokes take the exact path). Twist: 2 atan(x), x = along /
// w (w > 0). Swing: q twist^-1 = (r, s), r^2 = w^2 + along^2, r s = w (v -
// along a) - along v x a =: n; its rotation vector is g s, g = 2 atan(x) /
// (x r), x = |s| / r, x^2 = |n|^2 / r^4, so its u coordinate is
// 2 (atan(x) / x) n.u / r^2. All of it holds for q unnormalised and for -q
// (each side is homogeneous in q, n and r^2 quadratic). A relative 1e-9 of
// slack covers rounding.
bool certainly_inside(const SwingTwistLimit &l, const Eigen::Quaterniond &q)
{
    constexpr double kShrink = 1.0 - 1e-9;
    auto holds_zero = [](double lo, double hi) { return lo <= 0.0 && hi >= 0.0; };
    if (!(holds_zero(l.twist_lo_rad, l.twist_hi_rad) && holds_zero(l.u_lo_rad, l.u_hi_rad) &&
          holds_zero(l.w_lo_rad, l.w_hi_rad)))
        return false;
    const double sign = q.w() < 0.0 ? -1.0 : 1.0;
    const double w = sign * q.w(), along = sign * q.vec().dot(l.twist_axis);
    if (!(w > 0.0))
        return false;
    const double w2 = w * w, a2 = along * along;
    // 2 atan(along / w) <= 2 along (15 w^2 + 4 along^2) / (w (15 w^2 + 9 along^2)).
    const double t = 2.0 * along * (15.0 * w2 + 4.0 * a2);
    const double t_bound = kShrink * w * (15.0 * w2 + 9.0 * a2);
    if (!(t <= l.twist_hi_rad * t_bound && t >= l.twist_lo_rad * t_bound))
        return false;
    const double r2 = w2 + a2;
    const Eigen::Vector3d &v = q.vec();
    const Eigen::Vector3d n =
        q.w() * (v - q.vec().dot(l.twist_axis) * l.twist_axis) -
        q.vec().dot(l.twist_axis) * v.cross(l.twist_axis); // quadratic: no sign needed
    const double r4 = r2 * r2, n2 = n.squaredNorm();
    const double pade = 15.0 * r4 + 4.0 * n2, bound = kShrink * r2 * (15.0 * r4 + 9.0 * n2);
    const double pu = 2.0 * n.dot(l.u) * pade, pw = 2.0 * n.dot(l.w) * pade;
    return pu <= l.u_hi_rad * bound && pu >= l.u_lo_rad * bound && pw <= l.w_hi_rad * bound &&
           pw >= l.w_lo_rad * bound;
}

// The clamp of q whose coordinates are c (outside the limit).
Eigen::Quaterniond recompose(const SwingTwistLimit &l, const Eigen::Vector3d &c)
{
    const double a = std::clamp(c[0], l.u_lo_rad, l.u_hi_rad);
    const double b = std::clamp(c[1], l.w_lo_rad, l.w_hi_rad);
    const double t = std::clamp(c[2], l.twist_lo_rad, l.twist_hi_rad);
    return (exp_map(a * l.u + b * l.w) * Eigen::Quaterniond(Eigen::AngleAxisd(t, l.twist_axis)))
        .normalized();
}
} // namespace

bool SwingTwistLimit::contains(const Eigen::Quaterniond &q, double tolerance_rad) const
{
    return (tolerance_rad >= 0.0 && certainly_inside(*this, q)) ||
           inside(*this, coordinates(q), tolerance_rad);
}

Eigen::Quaterniond SwingTwistLimit::clamp(const Eigen::Quaterniond &q) const
{
    if (certainly_inside(*this, q))
        return q.normalized();
    const Eigen::Vector3d c = coordinates(q); // once: inside or out
    if (inside(*this, c, 0.0))
        return q.normalized();
    return recompose(*this, c);
}

double SwingTwistLimit::excursion_rad(const Eigen::Quaterniond &q) const
{
    if (certainly_inside(*this, q))
        return 0.0;
    const Eigen::Vector3d c = coordinates(q);
    if (inside(*this, c, 0.0))
        return 0.0; // inside: nothing to recompose (the usual case, every step)
    return rotation_angle_between(q.normalized(), recompose(*this, c));
}

RangeOfMotion::RangeOfMotion(const CharacterModel &model)
{
    limits_.resize(CharacterModel::kJoints);
    std::vector<bool> set(CharacterModel::kJoints, false);
    for (const Row &row : kRows) {
        for (int mirror = 0; mirror < 2; ++mirror) {
            std::string name = row.joint;
            if (mirror) {
                if (name[0] != 'r')
                    continue;
                name[0] = 'l';
            }
            const int j = model.joint_index(name);
            if (j < 0)
                throw CharacterError("range of motion: the body has no joint '" + name + "'");
            const BodySpec &body = model.joint_body(j);
            SwingTwistLimit &l = limits_[j];
            l.twist_axis =
                body.distal_m.norm() > 1e-9 ? body.distal_m.normalized() : Eigen::Vector3d::UnitY();
            auto across = [&](int axis) {
                Eigen::Vector3d e = Eigen::Vector3d::Unit(axis);
                e -= e.dot(l.twist_axis) * l.twist_axis;
                return e.norm() > 1e-6 ? Eigen::Vector3d(e.normalized())
                                       : Eigen::Vector3d(l.twist_axis.unitOrthogonal());
            };
            l.u = across(row.u_axis);
            l.w = across(row.w_axis);
            l.w = (l.w - l.w.dot(l.u) * l.u).normalized();
            // Mirror (x -> -x): rotation vectors keep x and negate y and z.
            auto range = [&](int axis, double lo, double hi, double &out_lo, double &out_hi) {
                if (mirror && axis != 0) {
                    out_lo = -hi * kDeg;
                    out_hi = -lo * kDeg;
                } else {
                    out_lo = lo * kDeg;
                    out_hi = hi * kDeg;
                }
            };
            range(row.u_axis, row.u_lo, row.u_hi, l.u_lo_rad, l.u_hi_rad);
            range(row.w_axis, row.w_lo, row.w_hi, l.w_lo_rad, l.w_hi_rad);
            l.twist_lo_rad = -row.twist * kDeg;
            l.twist_hi_rad = row.twist * kDeg;
            set[j] = true;
        }
    }
    for (int j = 0; j < CharacterModel::kJoints; ++j)
        if (!set[j])
            throw CharacterError("range of motion: no range for joint '" + model.joint_name(j) +
                                 "'");
}

RangeOfMotion::RangeOfMotion(const CharacterModel &model, double inner_margin_rad)
    : RangeOfMotion(model)
{
    if (!(std::isfinite(inner_margin_rad) && inner_margin_rad >= 0.0))
        throw CharacterError("range of motion: the inner margin must be finite and >= 0");
    auto narrow = [inner_margin_rad](double &lo, double &hi) {
        const double m = std::min(inner_margin_rad, 0.5 * (hi - lo));
        lo += m;
        hi -= m;
    };
    for (SwingTwistLimit &l : limits_) {
        narrow(l.u_lo_rad, l.u_hi_rad);
        narrow(l.w_lo_rad, l.w_hi_rad);
        narrow(l.twist_lo_rad, l.twist_hi_rad);
    }
}

std::vector<JointLimitRef> RangeOfMotion::refs() const
{
    std::vector<JointLimitRef> refs;
    refs.reserve(limits_.size());
    for (const SwingTwistLimit &l : limits_)
        refs.push_back(JointLimitRef::to(l));
    return refs;
}

double RangeOfMotion::max_excursion_rad(const std::vector<Eigen::Quaterniond> &local,
                                        int *joint) const
{
    double worst = 0.0;
    int at = -1;
    for (size_t j = 0; j < limits_.size() && j < local.size(); ++j) {
        const double e = limits_[j].excursion_rad(local[j]);
        if (e > worst) {
            worst = e;
            at = static_cast<int>(j);
        }
    }
    if (joint)
        *joint = at;
    return worst;
}

} // namespace ictus
