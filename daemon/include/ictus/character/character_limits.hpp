// character_limits.hpp -- the joint limits the simulation enforces: learned
// from the reference motion of the character's 19 joints with the paper's two
// formulations (joint_limits.hpp: Euler statistics, Algorithm 1), made fit for
// a dynamic body:
//  - a minimum half-width per axis: a joint the capture never turned about an
//    axis would otherwise get a region a fraction of a degree thick, thinner
//    than gravity sag, and every step would sit "outside";
//  - the quaternion clamp is the closest point of the ellipsoid (tangent
//    space) rather than a radial projection, which for thin ellipsoids moves a
//    slightly-off target far towards the mean.
#pragma once

#include "ictus/character/character.hpp"
#include "ictus/mocap/joint_limits.hpp"
#include "ictus/character/joint_limit_ref.hpp"

#include <string>
#include <vector>

namespace ictus
{

enum class LimitKind { none, euler, quaternion };
const char *to_string(LimitKind kind);
LimitKind limit_kind_from_string(const std::string &text); // throws CharacterError

// Algorithm 1's ellipsoid with a closest-point clamp.
struct EllipsoidJointLimit {
    QuaternionLimit limit;
    bool contains(const Eigen::Quaterniond &q) const { return limit.contains(q, 1e-9); }
    // Inside: q. Outside: the ellipsoid point nearest to q's tangent vector.
    Eigen::Quaterniond clamp(const Eigen::Quaterniond &q) const;
};

struct EulerJointLimit {
    EulerLimit limit;
    bool contains(const Eigen::Quaterniond &q) const { return limit.contains(q, 1e-9); }
    Eigen::Quaterniond clamp(const Eigen::Quaterniond &q) const { return limit.clamp(q); }
};

// Fewest reference frames worth learning limits from. Both formulations
// estimate a spread per axis (Algorithm 1: a 3 x 3 covariance, singular below
// 4 samples); a sample standard deviation's relative error is about
// 1 / sqrt(2 (n - 1)): 13 % at 30 frames (limits at k = 3 std within
// +-0.4 std), 50 % at 3. Thirty is also ten samples per rotation axis, the
// usual minimum for a covariance. `ictusd limits` refuses fewer (--force:
// a warning), `ictusd track` warns. CharacterLimits itself learns from any
// number >= 1 (the spreads are floored by min_half_width_rad).
constexpr int kMinLimitFrames = 30;

struct CharacterLimitOptions {
    LimitKind kind = LimitKind::quaternion;
    double k = 3.0;                     // standard deviations (both formulations)
    double min_half_width_rad = 0.1047; // 6 degrees
};

class CharacterLimits
{
  public:
    // Learns both formulations for every joint from all reference frames.
    // Throws CharacterError (bad options) or MocapError (from the learners).
    CharacterLimits(const CharacterModel &model, const ReferenceMotion &reference,
                    const CharacterLimitOptions &options = {});
    const CharacterLimitOptions &options() const { return options_; }
    const std::vector<JointLimit> &learned() const { return learned_; }
    const EllipsoidJointLimit &ellipsoid(int joint) const { return ellipsoid_[joint]; }
    const EulerJointLimit &euler(int joint) const { return euler_[joint]; }
    // For Scene::set_joint_limits: empty for LimitKind::none. Refers to this
    // object, which must outlive the scene.
    std::vector<JointLimitRef> refs() const;
    // The report `ictusd limits` writes: joint_limits.hpp's, plus the widths used.
    nlohmann::json report() const;

  private:
    CharacterLimitOptions options_;
    LimitOptions learn_options_;
    std::vector<JointLimit> learned_;
    std::vector<EllipsoidJointLimit> ellipsoid_;
    std::vector<EulerJointLimit> euler_;
};

} // namespace ictus
