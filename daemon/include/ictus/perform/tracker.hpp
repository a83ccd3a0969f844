// tracker.hpp -- the per-step controller of the character: owns the Scene and,
// every physics step, turns the targets of that step into PD targets (eq. 1)
// and steps the world. Joint mode: eq. 1 toward a reference pose. Cartesian
// mode: Algorithm 2, the arms' targets from IK (eq. 2) toward stick-tip targets
// X^T, V^T, the rest of the body held on the reference pose. `ictusd track`
// (track.cpp) and the score performance (performance.cpp) both drive it; see
// docs/ik.md and docs/perform.md.
#pragma once

#include "ictus/control/chain_ik_solver_pos_dls.hpp"
#include "ictus/character/character.hpp"
#include "ictus/control/joint_controller.hpp"
#include "ictus/control/kinematic_chain.hpp"
#include "ictus/perform/perform_error.hpp"
#include "ictus/sim/scene.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <vector>

namespace ictus
{

enum class TrackMode {
    joint,    // eq. 1 on every joint (ID mode)
    cartesian // Algorithm 2: the arms' targets from IK (eq. 2) toward the stick tips
};
const char *to_string(TrackMode mode);
TrackMode track_mode_from_string(const std::string &text); // throws PerformError

// The Cartesian (hybrid) mode's IK settings.
struct CartesianOptions {
    // The gain of eq. 2: the IK target is X^S + gain (X^T - X^S) (+ the terms
    // below), so the PD springs pull the tip toward X^T with `gain` times the
    // stiffness they have in joint space. 1 is the plain IK of X^T. Default 10:
    // on CMU 80_13 the tip RMS falls with the gain up to ~10 and is flat above
    // (docs/ik.md, "Cartesian mode").
    double gain = 10.0;
    // Velocity term c (V^T - V^S), s, V^T the reference tip velocity: the
    // damping that goes with the raised stiffness. < 0: automatic,
    // (sqrt(gain) - 1) 2 zeta / omega_n (restores eq. 1's damping ratio); the
    // default 0.1 s was the best measured on CMU 80_13.
    double velocity_gain_s = 0.1;
    // Acceleration feedforward, s^2: k_a A^T is added to the IK target, A^T the
    // reference tip's acceleration (central difference over one reference
    // frame). Off by default: measured no gain on CMU 80_13.
    double acceleration_feedforward_s2 = 0.0;
    // Integral of the tip error (1/s) added to the IK target. 0: off (measured
    // no gain on CMU 80_13).
    double integral_per_s = 0.0;
    double integral_limit_m = 0.05; // cap on the integral's offset
    // Cap on the correction (gain - 1)(X^T - X^S) + c (V^T - V^S) + k_a A^T, m:
    // a large error (a target a joint limit keeps out of reach) must not throw
    // the IK target far off the path, where the loop gain makes it a runaway
    // (measured: 0.3 m excursions at gain 3 without a cap).
    double correction_limit_m = 0.1;
    // Weight (0..1) of the hands' rotation task (TipTargets::stick_direction).
    double rotation_weight = 1.0;
    // Cap on how fast the kinematic IK's solution may turn any arm joint,
    // rad/s (0: none). The DLS solve can change branch within one step where
    // the rotation task and the limits compete (measured up to 1.2 rad in
    // 1 ms); the PD then slams the joint through its stop. A capped solution
    // continues from where it got to and reaches the target a few steps
    // later. Score mode: 35 rad/s (99 % of the strokes' own joint rates stay
    // under it, docs/perform.md).
    double max_joint_speed_rad_s = 0.0;
    // Where the feedback IK starts. simulated: Theta^S, eq. 2 literally (the
    // arm's redundant directions then drift with the body: measured 30-40 deg
    // RMS at the shoulder on CMU 80_13). kinematic: the kinematic IK's solution
    // (the capture's arm pose when it has one), so the PD also holds the arm's
    // null space where the capture has it, and the Cartesian error term of
    // eq. 2 still corrects the tip. (`ictusd track`'s default is simulated, with the
    // posture task below: track_cartesian_defaults(), docs/ik.md.)
    bool start_from_simulated = false;
    // The redundant arm's secondary task (docs/ik.md, "Posture task"): both IK solves
    // (feedback and kinematic) turn every arm joint by this fraction of its way toward the
    // posture (Tracker::set_posture; default the initial pose) within the tip task's null
    // space, once per step. From the simulated state the PD then pulls the arm's null space
    // toward the posture with this fraction of its stiffness. 0: off (the score performance).
    double posture_weight = 0.0;
    // Iterations of the feedback IK per step (eq. 2 is one; 0: the solver's budget,
    // IkParams::max_iterations, i.e. solved to convergence).
    int feedback_iterations = 0;
    // Likewise for the kinematic IK (it only gives the arms' target rates).
    int kinematic_iterations = 0;
    // The reference's arm rotations are meaningful (a full-body capture): the
    // kinematic IK starts from them every step. Else (stick-only captures) it
    // continues from its own last solution.
    bool reference_has_arms = true;
    IkParams ik;
};

// The targets' ramp at start-up (a step in the targets jolts the trunk,
// docs/character.md): the smoothstep 3x^2 - 2x^3 of t / ramp_s, 1 from ramp_s
// on (and at once when ramp_s is 0).
double ramp_weight(double t_s, double ramp_s);
double smoothstep(double x); // of x clamped to [0, 1]
// `out` = `to` with every local rotation slerped from `from` by w (0: from, 1: to).
void blend_pose(const CharacterPose &from, const CharacterPose &to, double w, CharacterPose &out);

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
    // The sticks' planned directions (butt to tip, world). When given, the IK
    // also turns each hand so that its stick points there with the grip's
    // fulcrum axis horizontal (held_rotation()), as a task below the tip's.
    bool has_direction = false;
    std::array<Eigen::Vector3d, 2> stick_direction = {Eigen::Vector3d::UnitZ(),
                                                      Eigen::Vector3d::UnitZ()};
};

// The hand's world rotation that holds `side`'s stick along `direction` with
// the fulcrum axis horizontal: the stroke plane vertical, as the grip holds
// it (French: thumb up; German: palm down). `weight` (if given) is how far
// the stroke plane is defined, 0..1: 1 for a stick within 60 degrees of the
// horizontal, falling smoothly to 0 at 78 degrees, so that the rotation task
// fades out as the stick turns towards the vertical instead of switching off
// (a switch made the IK's solution jump by up to 1 rad in one step). False
// when the weight is 0.
bool held_rotation(const CharacterModel &model, Side side, const Eigen::Vector3d &direction,
                   Eigen::Quaterniond &out, double *weight = nullptr);

// IK statistics since construction (Cartesian mode, and joint mode with tip targets).
struct TrackerIkStats {
    long iterations = 0;
    long solves = 0;
    long rate_capped = 0; // joint solutions held back by max_joint_speed_rad_s
    long reseeded = 0;    // kinematic solutions taken from a solve started at the posture
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
    // "joint targets through IK", docs/perform.md). mode cartesian: Algorithm 2.
    // `gain_options` only for the automatic velocity gain (cartesian.velocity_gain_s < 0).
    // `limits` as Scene::set_joint_limits (empty: none; they must outlive the tracker);
    // `ik_limits` (nullptr: `limits`) those the arms' IK clamps into.
    // Throws PerformError (a joint missing from the model, bad options).
    Tracker(const CharacterModel &model, const SceneOptions &scene_options,
            const CharacterPose &initial, const std::vector<JointGains> &gains,
            const std::vector<JointLimitRef> &limits, TrackMode mode,
            const CartesianOptions &cartesian = {}, const GainOptions &gain_options = {},
            const std::vector<JointLimitRef> *ik_limits = nullptr);
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
    // The posture of the IK's null-space task [clavicle, shoulder, elbow, wrist] of `side`
    // (CartesianOptions::posture_weight); the initial pose's until set.
    void set_posture(int side, const Eigen::Quaterniond posture[4]);

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
    // With `directions`, the hands also hold their sticks along them
    // (held_rotation()).
    static void solve_arms(const CharacterModel &model, const std::vector<JointLimitRef> &limits,
                           const IkParams &ik, const std::array<Eigen::Vector3d, 2> &tips,
                           CharacterPose &pose,
                           const std::array<Eigen::Vector3d, 2> *directions = nullptr);

  private:
    struct Arm;
    // The steps of step(): the reference's targets and rates, then the arms' IK.
    void follow_reference(const CharacterPose &reference, bool tips_drive_arms);
    void drive_arms(const CharacterPose &reference, const TipTargets &tips, bool integrate);
    void solve_kinematic(Arm &arm, Side side, const Eigen::Vector3d &tip_target,
                         const TipTargets &tips);
    void solve_feedback(Arm &arm, Side side, const Eigen::Vector3d &tip_target,
                        const TipTargets &tips, bool integrate);
    void set_arm_targets(Arm &arm);
    void count_solve(const IkResult &r);
    TrackMode mode_;
    CartesianOptions cartesian_;
    double velocity_gain_s_ = 0.0;
    std::unique_ptr<Scene> scene_;
    std::array<std::unique_ptr<Arm>, 2> arms_;
    std::unique_ptr<ChainIkSolverPos_dls> solver_, feedback_solver_;
    std::vector<Eigen::Quaterniond> previous_reference_, target_, sim_local_;
    std::vector<Eigen::Vector3d> rate_;
    CharacterPose target_pose_;
    BodyFrames sim_frames_, target_frames_;
    TrackerIkStats ik_stats_;
    long steps_ = 0;
};

} // namespace ictus
