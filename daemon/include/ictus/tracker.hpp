// tracker.hpp -- the per-step controller of the character: owns the Scene and,
// every physics step, turns the targets of that step into PD targets (eq. 1)
// and steps the world. Joint mode: eq. 1 toward a reference pose. Cartesian
// mode: Algorithm 2, the arms' targets from IK (eq. 2) toward stick-tip targets
// X^T, V^T, the rest of the body held on the reference pose. `ictusd track`
// (track.cpp) and the score performance (performance.cpp) both drive it; see
// docs/ik.md and docs/perform.md.
#pragma once

#include "ictus/chain_ik_solver_pos_dls.hpp"
#include "ictus/character.hpp"
#include "ictus/joint_controller.hpp"
#include "ictus/kinematics.hpp"
#include "ictus/scene.hpp"
#include "ictus/track.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <vector>

namespace ictus
{

// The stick-tip targets of one step, world frame [side].
struct TipTargets {
    // X^T. When false, X^T is the stick tip of the step's reference pose
    // (forward kinematics: a full-body capture).
    bool has_position = false;
    std::array<Eigen::Vector3d, 2> position_m = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    std::array<Eigen::Vector3d, 2> velocity_mps = {Eigen::Vector3d::Zero(),
                                                   Eigen::Vector3d::Zero()};
    std::array<Eigen::Vector3d, 2> acceleration_mps2 = {Eigen::Vector3d::Zero(),
                                                        Eigen::Vector3d::Zero()};
};

// IK statistics since construction (Cartesian mode, and joint mode with tip targets).
struct TrackerIkStats {
    long iterations = 0;
    long solves = 0;
    int max_iterations = 0;
    long not_converged = 0; // solves that ended other than `converged`
    double wall_s = 0.0;    // wall time in the IK
};

// One controller, one Scene. Not thread-safe (the Scene is not). All per-step
// scratch is sized in the constructor: step() does not allocate.
class Tracker
{
  public:
    // mode joint: eq. 1 on every joint toward the reference (and, when a step
    // gives tip targets, the arms toward the kinematic IK of those targets:
    // "joint targets through IK", issue 6). mode cartesian: Algorithm 2.
    // `gain_options` only for the automatic velocity gain (cartesian.velocity_gain_s < 0).
    // `limits` as Scene::set_joint_limits (empty: none; they must outlive the tracker).
    // Throws CharacterError (a joint missing from the model, bad options).
    Tracker(const CharacterModel &model, const SceneOptions &scene_options,
            const CharacterPose &initial, const std::vector<JointGains> &gains,
            const std::vector<JointLimitRef> &limits, TrackMode mode,
            const CartesianOptions &cartesian = {}, const GainOptions &gain_options = {});
    ~Tracker();
    Tracker(const Tracker &) = delete;
    Tracker &operator=(const Tracker &) = delete;

    // One physics step toward `reference` (the targets for the end of the
    // step: pelvis and all local rotations). Target rates are the reference's
    // finite differences over the step; the arms' (when IK drives them) the
    // kinematic IK's. `tips` drives the arms (nullptr: joint mode on every
    // joint; required in Cartesian mode, where has_position = false takes the
    // reference's own tips). `integrate`: accumulate the integral term.
    StepResult step(const CharacterPose &reference, const TipTargets *tips, bool integrate = true);

    // The mode can change between steps (the arms' IK state is kept warm in both).
    void set_mode(TrackMode mode) { mode_ = mode; }
    TrackMode mode() const { return mode_; }
    const CartesianOptions &cartesian() const { return cartesian_; }
    double velocity_gain_s() const { return velocity_gain_s_; }

    // The PD targets of the last step before the Scene clamped them into the
    // limits: the reference, with the arms' IK solutions where IK drove them.
    const std::vector<Eigen::Quaterniond> &targets() const { return target_; }
    // The kinematic IK's last arm targets [side][clavicle, shoulder, elbow, wrist].
    const Eigen::Quaterniond &kinematic_target(int side, int k) const;
    const TrackerIkStats &ik_stats() const { return ik_stats_; }

    Scene &scene() { return *scene_; }
    const Scene &scene() const { return *scene_; }
    const CharacterModel &model() const { return scene_->model(); }

    // The arm joints [side][clavicle, shoulder, elbow, wrist] (joint indices).
    static constexpr const char *kArmJoints[2][4] = {
        {"l_clavicle", "l_shoulder", "l_elbow", "l_wrist"},
        {"r_clavicle", "r_shoulder", "r_elbow", "r_wrist"}};

    // Arm rotations that put the stick tips at `tips` [side] from the pose
    // `pose` (a cold IK solve, repeated calls of the solver's budget): writes
    // them into pose.local. For a body whose arms start nowhere near the sticks.
    static void solve_arms(const CharacterModel &model, const std::vector<JointLimitRef> &limits,
                           const IkParams &ik, const std::array<Eigen::Vector3d, 2> &tips,
                           CharacterPose &pose);

  private:
    struct Arm;
    TrackMode mode_;
    CartesianOptions cartesian_;
    double velocity_gain_s_ = 0.0;
    std::unique_ptr<Scene> scene_;
    std::array<std::unique_ptr<Arm>, 2> arms_;
    std::unique_ptr<ChainIkSolverPos_dls> solver_;
    std::vector<Eigen::Quaterniond> previous_reference_, target_, sim_local_;
    std::vector<Eigen::Vector3d> rate_;
    CharacterPose target_pose_;
    BodyFrames sim_frames_, target_frames_;
    TrackerIkStats ik_stats_;
    long steps_ = 0;
};

} // namespace ictus
