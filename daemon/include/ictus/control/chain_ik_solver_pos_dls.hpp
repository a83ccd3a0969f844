// chain_ik_solver_pos_dls.hpp -- position IK of a ball-joint chain by damped least squares
// (paper eq. 2, Wampler's singularity-robust pseudo-inverse), the "InverseKinematics()" step
// of Algorithm 2. Named in the manner of Orocos KDL (ChainIkSolverPos_*, ChainIkSolverVel_wdls).
// See docs/ik.md for the maths, the choice of the damping and how the character uses it.
#pragma once

#include "ictus/base/cholesky3.hpp"
#include "ictus/control/kinematic_chain.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

namespace ictus
{

enum class IkStatus {
    converged,      // tip within tolerance of the target (direction: see direction_error_rad)
    max_iterations, // still approaching the target when the iteration budget ran out
    unreachable,    // target beyond the chain's reach: tip left as close as the solver got
    joint_limited,  // a joint limit stopped the tip short of a reachable target
    singular,       // the Jacobian's smallest singular value is below the damping: the damped
                    // step could not reduce the error along the singular direction
    invalid_input,  // non-finite target/state or wrong chain size: outputs = warm start
};
const char *to_string(IkStatus status);

struct IkResult {
    IkStatus status = IkStatus::invalid_input;
    int iterations = 0;                // steps tried (accepted or not), <= max_iterations
    double position_error_m = 0.0;     // |target - tip| at the returned configuration
    double direction_error_rad = 0.0;  // stick direction error (0 without secondary task)
    double min_singular_value_m = 0.0; // sigma_min(J) at the end when not converged, else 0
    bool limits_active = false;        // a limit clamped a joint in the last iteration
};

struct IkParams {
    // Damping lambda of J^T (J J^T + lambda^2 I)^-1, in metres (J maps rad to m). One
    // iteration moves the joints by at most |e| / (2 lambda) rad (Wampler), and away from
    // singularities (sigma ~ 0.3-1 m for an arm) it biases a step by lambda^2 / sigma^2 < 1 %.
    // This is the floor: where a step fails to reduce the error the solver doubles it for the
    // next try (Levenberg-Marquardt), see docs/ik.md.
    double damping_m = 0.03;
    // Per iteration the task error is clamped to this length (Buss & Kim's error clamping),
    // so a far target is approached in steps over which the linearisation holds.
    double max_error_step_m = 0.2;
    // Per iteration the joint step is scaled down (direction kept) so that no joint turns more
    // than this: with max_iterations it bounds how far one call can move any joint.
    double max_joint_step_rad = 0.5;
    // Tried steps per call (accepted or not). Warm-started tracking at 1 kHz needs 1-2; a cold
    // start across the workspace of the test arm up to 11 (docs/ik.md).
    int max_iterations = 16;
    double tolerance_m = 1e-5;
    // Secondary task (stick direction): the solver keeps iterating until the direction is
    // within this too (the tip staying within tolerance_m).
    double direction_tolerance_rad = 1e-3;
    // Damping (dimensionless: J_d maps rad to rad) of the secondary task's pseudo-inverse.
    double direction_damping = 0.1;
};

// Damped-least-squares position IK, warm-started from the chain's current rotations (the
// simulated state Theta^S): Theta^T = Theta^S + sum of steps
//     dtheta = J^T (J J^T + lambda^2 I)^-1 e  [+ (J_d N)^+ (w e_d - J_d dtheta), N = I - J^+ J]
// with e = clamp(X^T - X^S), J the tip Jacobian with respect to world-frame joint angular
// velocities, and the optional stick-direction task in J's null space. Each step is applied
// as world-frame rotation increments, then the chain's joint limits; a step that does not
// bring the tip closer is undone and retried with twice the damping (Levenberg-Marquardt).
// All temporaries are members of fixed maximum size: construction and solve() never
// allocate. Not thread-safe: one solver per arm (or per thread).
class ChainIkSolverPos_dls
{
  public:
    explicit ChainIkSolverPos_dls(int joints, const IkParams &params = IkParams());

    int joints() const { return joints_; }
    const IkParams &params() const { return params_; }
    // Non-finite or non-positive values are refused (returns false, params unchanged).
    bool set_params(const IkParams &params);

    // Tip to `target_tip_m` (world, m). `rotations_out` gets chain.joints() local rotations.
    IkResult solve(const KinematicChain &chain, const Eigen::Vector3d &target_tip_m,
                   Eigen::Quaterniond *rotations_out);
    // Same, with the stick pointing along `target_direction` (world, any length > 0) as a
    // secondary task of weight `direction_weight` in [0, 1] (0 = off) in the null space of
    // the position task: the position is never traded for the direction.
    IkResult solve(const KinematicChain &chain, const Eigen::Vector3d &target_tip_m,
                   const Eigen::Vector3d &target_direction, double direction_weight,
                   Eigen::Quaterniond *rotations_out);
    // Same, with the last joint's frame (the hand, which holds the stick) turned to
    // `target_rotation` (world) as the secondary task: the stick's direction and its roll
    // about it (where a fulcrum's axis lies), with the direction task's tolerance and damping.
    IkResult solve(const KinematicChain &chain, const Eigen::Vector3d &target_tip_m,
                   const Eigen::Quaterniond &target_rotation, double rotation_weight,
                   Eigen::Quaterniond *rotations_out);
    // Same, with a posture task in the null space of the tip task: the first iteration adds
    // N (w log(posture_j q_j^-1)) (world frame, N = I - J^+ J), i.e. it turns every joint a
    // fraction `posture_weight` in [0, 1] of the way toward `posture[j]` (local rotations,
    // chain.joints() of them) as far as that does not move the tip (to first order). Once per
    // call: called every physics step from the simulated state, the arm's redundant directions
    // relax toward the posture at that rate. The posture iteration is accepted when the tip
    // ends no farther from the target than before plus the step's second-order bound
    // |dtheta|^2 L / 2 (L the chain's reach); later iterations take that back. 0 = the plain
    // solve.
    IkResult solve_with_posture(const KinematicChain &chain, const Eigen::Vector3d &target_tip_m,
                                const Eigen::Quaterniond *posture, double posture_weight,
                                Eigen::Quaterniond *rotations_out);

  private:
    using Jacobian = Eigen::Matrix<double, 3, Eigen::Dynamic, 0, 3, KinematicChain::kMaxDofs>;
    using JointVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, KinematicChain::kMaxDofs, 1>;

    double direction_error(const ChainFrames &frames, const Eigen::Vector3d &target_direction,
                           Eigen::Vector3d *rotation_vector) const;
    // The tip's and the secondary task's errors at one configuration.
    struct TaskError {
        Eigen::Vector3d tip_m = Eigen::Vector3d::Zero(); // target - tip
        double tip_norm_m = 0.0;
        // The world rotation vector turning the stick (or hand) onto its target, and its angle.
        Eigen::Vector3d direction_step = Eigen::Vector3d::Zero();
        double direction_rad = 0.0;
    };
    // Where one solve() stands: the accepted configuration rotation_[current] and its errors,
    // the Levenberg-Marquardt damping and the secondary task's weight for the next step.
    struct Iterate {
        int current = 0;
        TaskError error;
        double damping_m = 0.0, secondary_weight = 0.0;
        bool limits_active = false; // a limit clamped a joint in the last step tried
    };
    // The errors at `frames` (the direction's only with a direction target).
    void measure(const ChainFrames &frames, const Eigen::Vector3d &target_tip_m,
                 const Eigen::Vector3d *direction_target, TaskError &at) const;
    // One step tried from `it`, accepted or refused (Levenberg-Marquardt); false when the
    // step is too small to move (stalled).
    bool iterate(const KinematicChain &chain, const Eigen::Vector3d &target_tip_m,
                 const Eigen::Vector3d *direction_target, double direction_weight,
                 bool with_posture, Iterate &it);
    // The steps of solve(), in its order. The inputs' finiteness and sizes; the warm start
    // into rotation_[0] (false, with rotations_out the warm start, when anything is invalid).
    bool inputs_valid(const KinematicChain &chain, const Eigen::Vector3d &target_tip_m,
                      const Eigen::Vector3d &target_direction, double direction_weight,
                      const Eigen::Quaterniond *rotations_out) const;
    bool load_warm_start(const KinematicChain &chain, bool valid,
                         Eigen::Quaterniond *rotations_out);
    // step_ = the damped tip step (eq. 2) at `frames`; jacobian_, jjt_undamped_ its J, J J^T.
    void tip_step(const ChainFrames &frames, const Eigen::Vector3d &error, double error_m,
                  double damping_m);
    // projector_llt_ = the (barely regularised) J J^T of the null-space projector.
    void factor_projector();
    // step_ += the direction (or rotation) task's step in the tip task's null space.
    void add_direction_step(double secondary_weight, const Eigen::Vector3d &direction_step);
    // step_ += the posture task's step in the tip task's null space; returns the bound on
    // how far it moves the tip (m).
    double add_posture_step(const KinematicChain &chain, const ChainFrames &frames, int current,
                            bool projector_ready);
    // Scales step_ to the joint-step bound; false when it is too small to move (stalled).
    bool bound_step();
    // rotation_[candidate] = rotation_[current] turned by step_, clamped into the chain's
    // limits; true when a limit clamped a joint.
    bool apply_step(const KinematicChain &chain, const ChainFrames &frames, int current,
                    int candidate);
    // Why the solve ended short of the target (sets result.min_singular_value_m).
    IkStatus failure_status(const KinematicChain &chain, const Eigen::Vector3d &target_tip_m,
                            int current, IkResult &result);
    // The secondary task is the last frame's whole rotation (solve with a target rotation).
    bool full_rotation_ = false;
    Eigen::Quaterniond target_rotation_ = Eigen::Quaterniond::Identity();
    // The posture task of solve_with_posture (nullptr: none).
    const Eigen::Quaterniond *posture_ = nullptr;
    double posture_weight_ = 0.0;

    int joints_;
    IkParams params_;
    // Working state and temporaries, sized once here. Two configurations: the current one and
    // the candidate of the step being tried.
    std::array<std::array<Eigen::Quaterniond, KinematicChain::kMaxJoints>, 2> rotation_;
    std::array<ChainFrames, 2> frames_;
    Jacobian jacobian_;
    Eigen::Matrix3d jjt_, jjt_undamped_;
    Cholesky3 llt_;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen_;
    JointVector step_, posture_step_;
    // Secondary (stick direction) task.
    Cholesky3 projector_llt_;
    Jacobian jacobian_solved_;
    Jacobian direction_jacobian_;
    Eigen::Matrix3d direction_jjt_;
    Cholesky3 direction_llt_;
};

} // namespace ictus
