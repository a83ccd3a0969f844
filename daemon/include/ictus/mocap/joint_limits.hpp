// joint_limits.hpp -- joint limits learned from captured rotations, the paper's
// two formulations ("Virtual Character Modeling"): per-axis Euler statistics,
// and Algorithm 1 (ellipsoid in the tangent space of the mean quaternion).
// Works on any per-joint series of local rotations. See docs/mocap.md.
#pragma once

#include "ictus/base/rotation.hpp"
#include "ictus/mocap/rotation_stats.hpp"
#include "ictus/mocap/mocap_error.hpp"
#include "ictus/mocap/motion.hpp"

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <iosfwd>
#include <string>
#include <vector>

namespace ictus
{

// ---- formulation 1: Euler angles -------------------------------------------

struct EulerLimitOptions {
    EulerOrder order = EulerOrder::ZYX;
    enum class Method { mean_std, percentile };
    Method method = Method::mean_std;
    double k = 2.5;          // mean_std: limits = mean -/+ k * std per axis
    double percentile = 1.0; // percentile: limits = [p, 100 - p] percentiles (%)
};

// lower/upper per angle of `order`, rad. Angles a0 and a2 are unwrapped around
// the samples' circular mean, so lower/upper may lie outside (-pi, pi].
struct EulerLimit {
    EulerOrder order = EulerOrder::ZYX;
    Eigen::Vector3d lower_rad = Eigen::Vector3d::Zero();
    Eigen::Vector3d upper_rad = Eigen::Vector3d::Zero();
    Eigen::Vector3d angles(const Eigen::Quaterniond &q) const; // unwrapped into the range
    bool contains(const Eigen::Quaterniond &q, double tolerance_rad = 1e-9) const;
    // Decomposes, clamps each angle to [lower, upper], recomposes.
    Eigen::Quaterniond clamp(const Eigen::Quaterniond &q) const;
};

EulerLimit learn_euler_limit(const std::vector<Eigen::Quaterniond> &series,
                             const EulerLimitOptions &options = {});

// ---- formulation 2: quaternions, Algorithm 1 --------------------------------

struct QuaternionLimitOptions {
    double k = 3.0; // ellipsoid half-axes = k * sigma
    // Spreads below this are raised to it, so a joint that never moved about
    // an axis keeps a tiny, non-degenerate range and nothing divides by zero.
    double sigma_floor_rad = 1e-3;
};

// Algorithm 1: mean rotation, tangent vectors v_i = log_map(mean^-1 * q_i),
// principal axes (columns of `axes`, orthonormal, right-handed, sorted by
// decreasing sigma) and standard deviations sigma along them (rad). The limit
// is the ellipsoid sum_j (v . e_j / (k sigma_j))^2 <= 1.
struct QuaternionLimit {
    Eigen::Quaterniond mean = Eigen::Quaterniond::Identity();
    Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
    Eigen::Vector3d sigma_rad = Eigen::Vector3d::Constant(1e-3);
    double k = 3.0;
    Eigen::Vector3d tangent(const Eigen::Quaterniond &q) const; // log_map(mean^-1 q)
    // Ellipsoid "radius": <= 1 inside. (Mahalanobis distance / k.)
    double normalized_distance(const Eigen::Quaterniond &q) const;
    bool contains(const Eigen::Quaterniond &q, double tolerance = 1e-9) const;
    // Inside: q unchanged. Outside: the tangent vector is scaled along the ray
    // from the mean onto the ellipsoid surface and mapped back.
    Eigen::Quaterniond clamp(const Eigen::Quaterniond &q) const;
};

QuaternionLimit learn_quaternion_limit(const std::vector<Eigen::Quaterniond> &series,
                                       const QuaternionLimitOptions &options = {});

// ---- both, per joint, and reporting ----------------------------------------

struct LimitOptions {
    EulerLimitOptions euler;
    QuaternionLimitOptions quaternion;
};

struct JointLimit {
    std::string name;
    int samples = 0;
    EulerLimit euler;
    QuaternionLimit quaternion;
};

// The series of local rotations of one joint over all frames of a motion.
std::vector<Eigen::Quaterniond> joint_series(const Motion &motion, int joint);

// Learns both limits for every joint of a skeleton that is not an end site,
// from that joint's local rotations over all frames of `motion`.
std::vector<JointLimit> learn_limits(const Skeleton &skeleton, const Motion &motion,
                                     const LimitOptions &options = {});

// Learns both limits for every named series (names.size() == series.size();
// each series non-empty, else MocapError).
std::vector<JointLimit> learn_limits(const std::vector<std::string> &names,
                                     const std::vector<std::vector<Eigen::Quaterniond>> &series,
                                     const LimitOptions &options = {});

nlohmann::json to_json(const EulerLimit &limit);
nlohmann::json to_json(const QuaternionLimit &limit);
nlohmann::json to_json(const JointLimit &limit);
EulerLimit euler_limit_from_json(const nlohmann::json &j);           // throws MocapError
QuaternionLimit quaternion_limit_from_json(const nlohmann::json &j); // throws MocapError

// {"options": {...}, "joints": [ {name, samples, euler: {...}, quaternion: {...}}, ... ]}
// (what `ictusd limits FILE` prints).
nlohmann::json limits_report(const std::vector<std::string> &names,
                             const std::vector<std::vector<Eigen::Quaterniond>> &series,
                             const LimitOptions &options = {});
nlohmann::json limits_report(const std::vector<JointLimit> &limits, const LimitOptions &options);

// Human-readable table: per joint, Euler lower/upper (deg) and k*sigma (deg).
void print_limits(std::ostream &out, const std::vector<JointLimit> &limits);

} // namespace ictus
