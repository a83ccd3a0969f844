// chain_ik_solver_pos_dls.cpp -- damped-least-squares IK (paper eq. 2, Wampler 1986).
#include "ictus/control/chain_ik_solver_pos_dls.hpp"
#include "ictus/base/enum_names.hpp"
#include "ictus/base/rotation.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace ictus
{

namespace
{
const EnumNames<6> kIkStatusNames = {"converged",     "max_iterations", "unreachable",
                                     "joint_limited", "singular",       "invalid_input"};
} // namespace

const char *to_string(IkStatus status)
{
    return enum_name(kIkStatusNames, status, "unknown");
}

// The secondary task's weight is cut to no less than this before the damping grows.
static constexpr double kMinSecondaryWeight = 1.0 / 64.0;

static bool params_valid(const IkParams &p)
{
    const auto positive = [](double x) { return std::isfinite(x) && x > 0.0; };
    return positive(p.damping_m) && positive(p.max_error_step_m) &&
           positive(p.max_joint_step_rad) && positive(p.tolerance_m) &&
           positive(p.direction_tolerance_rad) && positive(p.direction_damping) &&
           p.max_iterations >= 1 && p.max_iterations <= 10000;
}

ChainIkSolverPos_dls::ChainIkSolverPos_dls(int joints, const IkParams &params)
    : joints_(joints >= 1 && joints <= KinematicChain::kMaxJoints ? joints : 0),
      params_(params_valid(params) ? params : IkParams())
{
    // Size every temporary once; their storage is inline (fixed maximum size), so neither
    // this nor solve() touches the heap.
    jacobian_.setZero(3, 3 * joints_);
    step_.setZero(3 * joints_);
    posture_step_.setZero(3 * joints_);
    jacobian_solved_.setZero(3, 3 * joints_);
    direction_jacobian_.setZero(3, 3 * joints_);
    jjt_.setZero();
    jjt_undamped_.setZero();
    for (auto &rotations : rotation_)
        for (auto &q : rotations)
            q.setIdentity();
}

bool ChainIkSolverPos_dls::set_params(const IkParams &params)
{
    if (!params_valid(params))
        return false;
    params_ = params;
    return true;
}

IkResult ChainIkSolverPos_dls::solve(const KinematicChain &chain,
                                     const Eigen::Vector3d &target_tip_m,
                                     Eigen::Quaterniond *rotations_out)
{
    return solve(chain, target_tip_m, Eigen::Vector3d::UnitX(), 0.0, rotations_out);
}

IkResult ChainIkSolverPos_dls::solve(const KinematicChain &chain,
                                     const Eigen::Vector3d &target_tip_m,
                                     const Eigen::Quaterniond &target_rotation,
                                     double rotation_weight, Eigen::Quaterniond *rotations_out)
{
    const double norm = target_rotation.norm();
    if (!(target_rotation.coeffs().allFinite() && norm > 1e-12))
        return solve(chain, target_tip_m, Eigen::Vector3d::Constant(std::nan("")), 1.0,
                     rotations_out); // refused as invalid input
    full_rotation_ = true;
    target_rotation_ = Eigen::Quaterniond(target_rotation.coeffs() / norm);
    const IkResult r =
        solve(chain, target_tip_m, Eigen::Vector3d::UnitX(), rotation_weight, rotations_out);
    full_rotation_ = false;
    return r;
}

IkResult ChainIkSolverPos_dls::solve_with_posture(const KinematicChain &chain,
                                                  const Eigen::Vector3d &target_tip_m,
                                                  const Eigen::Quaterniond *posture,
                                                  double posture_weight,
                                                  Eigen::Quaterniond *rotations_out)
{
    bool valid = posture != nullptr && std::isfinite(posture_weight) && posture_weight >= 0.0 &&
                 posture_weight <= 1.0;
    for (int j = 0; valid && j < joints_; ++j)
        valid = posture[j].coeffs().allFinite() && posture[j].norm() > 1e-12;
    if (!valid)
        return solve(chain, target_tip_m, Eigen::Vector3d::Constant(std::nan("")), 1.0,
                     rotations_out); // refused as invalid input
    posture_ = posture_weight > 0.0 ? posture : nullptr;
    posture_weight_ = posture_weight;
    const IkResult r = solve(chain, target_tip_m, Eigen::Vector3d::UnitX(), 0.0, rotations_out);
    posture_ = nullptr;
    return r;
}

double ChainIkSolverPos_dls::direction_error(const ChainFrames &frames,
                                             const Eigen::Vector3d &target_direction,
                                             Eigen::Vector3d *rotation_vector) const
{
    if (full_rotation_) {
        // The world rotation vector turning the last frame onto the target rotation.
        *rotation_vector =
            log_map(target_rotation_ * frames.joint_rotation[joints_ - 1].conjugate());
        return rotation_vector->norm();
    }
    // The world rotation vector turning the stick onto the target direction (shortest arc).
    const Eigen::Vector3d &d = frames.stick_direction;
    const Eigen::Vector3d axis = d.cross(target_direction);
    const double sin_angle = axis.norm();
    const double angle = std::atan2(sin_angle, d.dot(target_direction));
    if (sin_angle > 1e-12)
        *rotation_vector = axis * (angle / sin_angle);
    else if (angle < 1.0)
        rotation_vector->setZero();
    else // opposite: any axis across the stick will do
        *rotation_vector = d.unitOrthogonal() * angle;
    return angle;
}

bool ChainIkSolverPos_dls::inputs_valid(const KinematicChain &chain,
                                        const Eigen::Vector3d &target_tip_m,
                                        const Eigen::Vector3d &target_direction,
                                        double direction_weight,
                                        const Eigen::Quaterniond *rotations_out) const
{
    const int n = joints_;
    const bool use_direction = direction_weight > 0.0;
    return n > 0 && chain.joints() == n && rotations_out != nullptr && target_tip_m.allFinite() &&
           chain.base_position().allFinite() && chain.base_rotation().coeffs().allFinite() &&
           chain.tip_offset().allFinite() && std::isfinite(direction_weight) &&
           direction_weight >= 0.0 && direction_weight <= 1.0 &&
           (!use_direction ||
            (target_direction.allFinite() && target_direction.squaredNorm() > 1e-24));
}

bool ChainIkSolverPos_dls::load_warm_start(const KinematicChain &chain, bool valid,
                                           Eigen::Quaterniond *rotations_out)
{
    const int n = joints_;
    // Warm start Theta^S. A rotation that is not a usable quaternion makes the input invalid
    // and is replaced by the identity, so the outputs never hold NaN.
    for (int j = 0; j < n && j < chain.joints(); ++j) {
        const Eigen::Quaterniond &q = chain.rotation(j);
        const double norm = q.norm();
        if (q.coeffs().allFinite() && norm > 1e-12) {
            rotation_[0][j] = Eigen::Quaterniond(q.coeffs() / norm);
        } else {
            rotation_[0][j].setIdentity();
            valid = false;
        }
        if (!chain.offset(j).allFinite())
            valid = false;
    }
    if (!valid && rotations_out != nullptr)
        // The warm start as given (not even renormalised), except where it is unusable.
        for (int j = 0; j < n && j < chain.joints(); ++j)
            rotations_out[j] = rotation_[0][j].isApprox(chain.rotation(j), 1e-12)
                                   ? chain.rotation(j)
                                   : rotation_[0][j];
    return valid;
}

void ChainIkSolverPos_dls::tip_step(const ChainFrames &frames, const Eigen::Vector3d &error,
                                    double error_m, double damping_m)
{
    // Eq. 2 with Wampler's damped (singularity-robust) pseudo-inverse:
    // dtheta = J^T (J J^T + lambda^2 I)^-1 e. J J^T is only 3x3, so the solve is cheap.
    KinematicChain::tip_jacobian(frames, joints_, jacobian_);
    // J J^T once per iteration (the damped solve and the projectors' share it).
    jjt_undamped_.noalias() = jacobian_ * jacobian_.transpose();
    jjt_ = jjt_undamped_;
    jjt_.diagonal().array() += damping_m * damping_m;
    llt_.compute(jjt_);
    const Eigen::Vector3d clamped_error =
        error_m > params_.max_error_step_m
            ? Eigen::Vector3d(error * (params_.max_error_step_m / error_m))
            : error;
    step_.noalias() = jacobian_.transpose() * llt_.solve(clamped_error);
}

void ChainIkSolverPos_dls::factor_projector()
{
    jjt_ = jjt_undamped_;
    jjt_.diagonal().array() += 1e-12;
    projector_llt_.compute(jjt_);
}

void ChainIkSolverPos_dls::add_direction_step(double secondary_weight,
                                              const Eigen::Vector3d &direction_step)
{
    const int n = joints_;
    // Secondary task, strictly below the tip (task priority, Nakamura et al. 1987):
    // dtheta += (J_d N)^+ (w e_d - J_d dtheta_tip), N = I - J^+ J the null-space
    // projector of the tip task. The stick turns with every joint alike, J_d = [I..I].
    // N uses the undamped pseudo-inverse (a 1e-6 m regulariser only): a damped one
    // leaks the secondary step into the tip by lambda^2 / sigma^2 and the two tasks
    // then fight. N stays a bounded projector even at singularities.
    // J_d N = J_d - (J_d J^T) (J J^T)^-1 J, J_d J^T the sum of J's 3x3 blocks
    // transposed: a 3x3 by 3xn product instead of N's (3n)x(3n) one.
    factor_projector();
    projector_llt_.solve(jacobian_, jacobian_solved_);
    Eigen::Matrix3d jd_jt = Eigen::Matrix3d::Zero();
    Eigen::Vector3d stick_turn_from_tip_step = Eigen::Vector3d::Zero();
    for (int j = 0; j < n; ++j) {
        jd_jt += jacobian_.middleCols<3>(3 * j).transpose();
        stick_turn_from_tip_step += step_.segment<3>(3 * j);
    }
    direction_jacobian_.noalias() = -jd_jt * jacobian_solved_;
    for (int j = 0; j < n; ++j)
        direction_jacobian_.middleCols<3>(3 * j).diagonal().array() += 1.0;
    const Eigen::Vector3d residual = secondary_weight * direction_step - stick_turn_from_tip_step;
    direction_jjt_.noalias() = direction_jacobian_ * direction_jacobian_.transpose();
    direction_jjt_.diagonal().array() += params_.direction_damping * params_.direction_damping;
    direction_llt_.compute(direction_jjt_);
    step_.noalias() += direction_jacobian_.transpose() * direction_llt_.solve(residual);
}

double ChainIkSolverPos_dls::add_posture_step(const KinematicChain &chain,
                                              const ChainFrames &frames, int current,
                                              bool projector_ready)
{
    const int n = joints_;
    // Posture task in the tip task's null space: dtheta += N w p, p_j the world rotation
    // vector turning joint j onto posture_[j] (local q_j <- exp(R_parent^T p_j) q_j), N
    // with the undamped pseudo-inverse (as the direction task's, so that it does not
    // leak into the tip). N p = p - J^T (J J^T)^-1 J p: a 3x3 solve, no 12x12 projector.
    for (int j = 0; j < n; ++j) {
        const Eigen::Quaterniond &parent =
            j == 0 ? chain.base_rotation() : frames.joint_rotation[j - 1];
        posture_step_.segment<3>(3 * j) =
            posture_weight_ * (parent * log_map(posture_[j] * rotation_[current][j].conjugate()));
    }
    if (!projector_ready)
        factor_projector();
    const Eigen::Vector3d tip_part = projector_llt_.solve(jacobian_ * posture_step_);
    posture_step_.noalias() -= jacobian_.transpose() * tip_part;
    step_.noalias() += posture_step_;
    // A null-space step moves the tip by second-order terms only: at most
    // |dtheta|^2 / 2 times the chain's reach.
    return 0.5 * posture_step_.squaredNorm() * chain.reach_m();
}

bool ChainIkSolverPos_dls::bound_step()
{
    // Scale the whole step (keeping its direction) so no joint turns more than the bound.
    double largest_rad = 0.0;
    for (int j = 0; j < joints_; ++j)
        largest_rad = std::max(largest_rad, step_.segment<3>(3 * j).norm());
    if (!(largest_rad > 1e-14))
        return false;
    if (largest_rad > params_.max_joint_step_rad)
        step_ *= params_.max_joint_step_rad / largest_rad;
    return true;
}

bool ChainIkSolverPos_dls::apply_step(const KinematicChain &chain, const ChainFrames &frames,
                                      int current, int candidate)
{
    // A world-frame increment w_j of joint j is the local rotation exp(R_parent^T w_j):
    // q_j <- R_parent^-1 exp(w_j) R_parent q_j, with R_parent from the current FK. Then
    // the chain's joint limits.
    bool candidate_limited = false;
    for (int j = 0; j < joints_; ++j) {
        const Eigen::Quaterniond &parent =
            j == 0 ? chain.base_rotation() : frames.joint_rotation[j - 1];
        const Eigen::Vector3d local_step = parent.conjugate() * step_.segment<3>(3 * j);
        Eigen::Quaterniond q = exp_map(local_step) * rotation_[current][j];
        q.normalize();
        const JointLimitRef &limit = chain.limit(j);
        if (limit.active()) {
            Eigen::Quaterniond clamped = limit.clamp(q);
            const double norm = clamped.norm();
            if (clamped.coeffs().allFinite() && norm > 1e-12) {
                clamped.coeffs() /= norm;
                // |q.clamped| < 1 unless they are the same rotation (up to sign).
                if (std::abs(clamped.dot(q)) < 1.0 - 1e-12)
                    candidate_limited = true;
                q = clamped;
            }
        }
        rotation_[candidate][j] = q;
    }
    return candidate_limited;
}

IkStatus ChainIkSolverPos_dls::failure_status(const KinematicChain &chain,
                                              const Eigen::Vector3d &target_tip_m, int current,
                                              IkResult &result)
{
    // Not there: say why. sigma_min of the final Jacobian, from the 3x3 J J^T in closed form.
    KinematicChain::tip_jacobian(frames_[current], joints_, jacobian_);
    jjt_.noalias() = jacobian_ * jacobian_.transpose();
    eigen_.computeDirect(jjt_, Eigen::EigenvaluesOnly);
    result.min_singular_value_m = std::sqrt(std::max(0.0, eigen_.eigenvalues()(0)));
    const double target_distance_m = (target_tip_m - frames_[current].joint_position_m[0]).norm();
    if (target_distance_m > chain.reach_m() - params_.tolerance_m)
        return IkStatus::unreachable;
    if (result.limits_active)
        return IkStatus::joint_limited;
    if (result.min_singular_value_m < params_.damping_m)
        return IkStatus::singular;
    return IkStatus::max_iterations;
}

void ChainIkSolverPos_dls::measure(const ChainFrames &frames, const Eigen::Vector3d &target_tip_m,
                                   const Eigen::Vector3d *direction_target, TaskError &at) const
{
    at.tip_m = target_tip_m - frames.tip_position_m;
    at.tip_norm_m = at.tip_m.norm();
    at.direction_step.setZero();
    at.direction_rad =
        direction_target ? direction_error(frames, *direction_target, &at.direction_step) : 0.0;
}

bool ChainIkSolverPos_dls::iterate(const KinematicChain &chain, const Eigen::Vector3d &target_tip_m,
                                   const Eigen::Vector3d *direction_target, double direction_weight,
                                   bool with_posture, Iterate &it)
{
    const ChainFrames &frames = frames_[it.current];
    tip_step(frames, it.error.tip_m, it.error.tip_norm_m, it.damping_m);
    // projector_llt_ holds this iteration's J J^T once the direction step made it.
    const bool projector_ready = direction_target && it.secondary_weight > 0.0;
    if (projector_ready)
        add_direction_step(it.secondary_weight, it.error.direction_step);
    const double posture_leak_m =
        with_posture ? add_posture_step(chain, frames, it.current, projector_ready) : 0.0;
    if (!bound_step())
        return false;
    const int candidate = 1 - it.current;
    it.limits_active = apply_step(chain, frames, it.current, candidate);
    chain.forward(rotation_[candidate].data(), &frames_[candidate]);
    TaskError next;
    measure(frames_[candidate], target_tip_m, direction_target, next);
    // Accept what brings the tip closer, or -- with the tip within tolerance -- turns the
    // stick closer to its target: the tip is never traded for the direction.
    // A posture step may move the tip by its second-order terms: accepted if the tip
    // ends no farther than before plus that bound (the next iterations, or the next
    // call, take it back).
    const double tolerance_m = params_.tolerance_m;
    const bool accept =
        next.tip_norm_m < it.error.tip_norm_m ||
        (direction_target && next.tip_norm_m <= tolerance_m &&
         next.direction_rad < it.error.direction_rad) ||
        (with_posture &&
         next.tip_norm_m <= it.error.tip_norm_m + std::max(tolerance_m, posture_leak_m));
    if (accept) {
        it.current = candidate;
        it.error = next;
        it.damping_m = std::max(params_.damping_m, 0.5 * it.damping_m);
        it.secondary_weight = std::min(direction_weight, 2.0 * it.secondary_weight);
    } else if (direction_target && it.secondary_weight > kMinSecondaryWeight) {
        // The secondary task's share is what most often spoils a step: it turns joints
        // into their limits, and the clamp moves the tip. Retry with less of it before
        // more damping (an accepted step gives it back). Doubling the damping on every
        // refusal stalled the solve 15 cm from a reachable target for 0.6 s in score
        // mode, the arm then driven into its elbow stop by the feedback IK.
        it.secondary_weight = std::max(kMinSecondaryWeight, 0.25 * it.secondary_weight);
    } else {
        it.damping_m *= 2.0;
    }
    return true;
}

IkResult ChainIkSolverPos_dls::solve(const KinematicChain &chain,
                                     const Eigen::Vector3d &target_tip_m,
                                     const Eigen::Vector3d &target_direction,
                                     double direction_weight, Eigen::Quaterniond *rotations_out)
{
    IkResult result;
    const bool use_direction = direction_weight > 0.0;
    if (!load_warm_start(
            chain,
            inputs_valid(chain, target_tip_m, target_direction, direction_weight, rotations_out),
            rotations_out)) {
        result.status = IkStatus::invalid_input;
        result.position_error_m = std::numeric_limits<double>::infinity();
        return result;
    }
    const Eigen::Vector3d direction_target =
        use_direction ? target_direction.normalized() : Eigen::Vector3d::UnitX();
    const Eigen::Vector3d *direction = use_direction ? &direction_target : nullptr;
    // Levenberg-Marquardt on top of Wampler's damping: a step that does not reduce the tip
    // error is undone and retried with twice the damping; accepted steps halve it again, never
    // below damping_m. Plain DLS oscillates where the residual stays large (targets out of
    // reach: the neglected curvature term |e| * L of the arm exceeds lambda^2 near the
    // stretch), see docs/ik.md.
    Iterate it;
    it.damping_m = params_.damping_m;
    it.secondary_weight = direction_weight;
    chain.forward(rotation_[0].data(), &frames_[0]);
    measure(frames_[0], target_tip_m, direction, it.error);
    const auto done = [&]() {
        return it.error.tip_norm_m <= params_.tolerance_m &&
               (!use_direction || it.error.direction_rad <= params_.direction_tolerance_rad);
    };
    // The posture task is tried once, with the first iteration (even when the tip is already
    // within tolerance: the step is in the tip task's null space).
    bool posture_pending = posture_ != nullptr;
    while ((!done() || posture_pending) && result.iterations < params_.max_iterations) {
        const bool with_posture = posture_pending;
        posture_pending = false;
        if (!iterate(chain, target_tip_m, direction, direction_weight, with_posture, it))
            break; // stalled: nothing left that the damped step can do
        ++result.iterations;
    }

    for (int j = 0; j < joints_; ++j)
        rotations_out[j] = rotation_[it.current][j];
    result.position_error_m = it.error.tip_norm_m;
    result.direction_error_rad = it.error.direction_rad;
    result.limits_active = it.limits_active;
    result.status = it.error.tip_norm_m <= params_.tolerance_m
                        ? IkStatus::converged
                        : failure_status(chain, target_tip_m, it.current, result);
    return result;
}

} // namespace ictus
