// Joint limits as the simulation enforces them (see character_limits.hpp).
#include "ictus/character/character_limits.hpp"
#include "ictus/base/enum_names.hpp"

#include <algorithm>
#include <cmath>

namespace ictus
{

namespace
{
const EnumNames<3> kLimitKindNames = {"none", "euler", "quaternion"};
} // namespace

const char *to_string(LimitKind kind)
{
    return enum_name(kLimitKindNames, kind, "?");
}

LimitKind limit_kind_from_string(const std::string &text)
{
    LimitKind kind;
    if (enum_from_name(kLimitKindNames, text, kind))
        return kind;
    throw CharacterError("limits: expected none, euler or quaternion, got '" + text + "'");
}

Eigen::Quaterniond EllipsoidJointLimit::clamp(const Eigen::Quaterniond &q) const
{
    const Eigen::Vector3d a = limit.k * limit.sigma_rad; // half-axes
    // A sufficient test for inside without the tangent's atan2 (every joint's
    // target and state, every step): mean^-1 q = (c, s) has the tangent
    // 2 atan(|s| / |c|) s / |s|, shorter than 2 s / |c|; so 4 sum (s.e_i /
    // a_i)^2 <= c^2 puts it inside the ellipsoid (q need not be unit: both
    // sides scale as |q|^2). A relative 1e-9 of slack covers rounding.
    {
        const Eigen::Quaterniond d = limit.mean.conjugate() * q;
        const Eigen::Vector3d s = limit.axes.transpose() * d.vec();
        double sum = 0.0;
        for (int i = 0; i < 3; ++i)
            sum += (s[i] / a[i]) * (s[i] / a[i]);
        if (4.0 * sum <= (1.0 - 1e-9) * d.w() * d.w())
            return q.normalized();
    }
    const Eigen::Vector3d v = limit.tangent(q);
    const Eigen::Vector3d p = limit.axes.transpose() * v; // principal coordinates
    double inside = 0.0;
    for (int i = 0; i < 3; ++i)
        inside += (p[i] / a[i]) * (p[i] / a[i]);
    if (inside <= 1.0)
        return q.normalized();
    // Closest point: x_i = a_i^2 p_i / (a_i^2 + t) with t >= 0 the root of
    // f(t) = sum (a_i p_i / (a_i^2 + t))^2 - 1, decreasing and convex, so
    // Newton from t = 0 converges monotonically.
    double t = 0.0;
    for (int it = 0; it < 60; ++it) {
        double f = -1.0, df = 0.0;
        for (int i = 0; i < 3; ++i) {
            const double d = a[i] * a[i] + t;
            const double r = a[i] * p[i] / d;
            f += r * r;
            df -= 2.0 * r * r / d;
        }
        if (std::fabs(f) < 1e-12 || df == 0.0)
            break;
        t -= f / df;
    }
    Eigen::Vector3d x;
    for (int i = 0; i < 3; ++i)
        x[i] = a[i] * a[i] * p[i] / (a[i] * a[i] + t);
    return (limit.mean * exp_map(limit.axes * x)).normalized();
}

CharacterLimits::CharacterLimits(const CharacterModel &model, const ReferenceMotion &reference,
                                 const CharacterLimitOptions &options)
    : options_(options)
{
    if (!(std::isfinite(options.k) && options.k > 0.0))
        throw CharacterError("limit k: expected a finite value > 0");
    if (!(std::isfinite(options.min_half_width_rad) && options.min_half_width_rad >= 0.0 &&
          options.min_half_width_rad < M_PI))
        throw CharacterError("limit minimum half-width: expected 0 <= rad < pi");
    learn_options_.quaternion.k = options.k;
    learn_options_.euler.k = options.k;
    // Algorithm 1 with the minimum width as its spread floor: k sigma >= w.
    learn_options_.quaternion.sigma_floor_rad =
        std::max(1e-3, options.min_half_width_rad / options.k);
    std::vector<std::string> names;
    std::vector<std::vector<Eigen::Quaterniond>> series(CharacterModel::kJoints);
    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        names.push_back(model.joint_name(j));
        series[j].reserve(reference.frames());
        for (int f = 0; f < reference.frames(); ++f)
            series[j].push_back(reference.frame(f).local[j]);
    }
    learned_ = learn_limits(names, series, learn_options_);
    for (const JointLimit &l : learned_) {
        ellipsoid_.push_back({l.quaternion});
        EulerJointLimit e{l.euler};
        for (int i = 0; i < 3; ++i) {
            const double mid = 0.5 * (e.limit.lower_rad[i] + e.limit.upper_rad[i]);
            const double half = std::max(0.5 * (e.limit.upper_rad[i] - e.limit.lower_rad[i]),
                                         options.min_half_width_rad);
            e.limit.lower_rad[i] = mid - half;
            e.limit.upper_rad[i] = mid + half;
        }
        euler_.push_back(e);
    }
}

std::vector<JointLimitRef> CharacterLimits::refs() const
{
    std::vector<JointLimitRef> refs;
    if (options_.kind == LimitKind::none)
        return refs;
    for (size_t j = 0; j < learned_.size(); ++j)
        refs.push_back(options_.kind == LimitKind::euler ? JointLimitRef::to(euler_[j])
                                                         : JointLimitRef::to(ellipsoid_[j]));
    return refs;
}

nlohmann::json CharacterLimits::report() const
{
    std::vector<JointLimit> enforced = learned_;
    for (size_t j = 0; j < enforced.size(); ++j)
        enforced[j].euler = euler_[j].limit;
    nlohmann::json r = limits_report(enforced, learn_options_);
    r["enforced"] = to_string(options_.kind);
    r["min_half_width_deg"] = options_.min_half_width_rad * 180.0 / M_PI;
    r["note"] = "Euler limits widened and quaternion spreads floored to the minimum "
                "half-width; the quaternion clamp is the closest ellipsoid point "
                "(docs/character.md)";
    return r;
}

} // namespace ictus
