// The per-step controller: eq. 1 toward a reference pose, Algorithm 2 for the
// arms toward stick-tip targets (tracker.hpp).
#include "ictus/perform/tracker.hpp"
#include "ictus/base/rotation.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>

namespace ictus
{

double smoothstep(double x)
{
    x = std::min(1.0, std::max(0.0, x));
    return x * x * (3.0 - 2.0 * x);
}

double ramp_weight(double t_s, double ramp_s)
{
    return ramp_s > 0.0 ? smoothstep(t_s / ramp_s) : 1.0;
}

void blend_pose(const CharacterPose &from, const CharacterPose &to, double w, CharacterPose &out)
{
    out.pelvis_position_m = to.pelvis_position_m;
    out.pelvis_rotation = to.pelvis_rotation;
    if (w == 1.0) {
        // Past the ramp (every step but its first ramp_s): Eigen's slerp at t = 1
        // has scale0 = sin(0)/sin(theta) = +0 and scale1 = sin(theta)/sin(theta) = 1
        // (or 1 - t and t on its linear branch), negated for a negative dot. The
        // same expression with those scales, without its acos and three sines:
        // the same bits.
        for (size_t j = 0; j < out.local.size(); ++j) {
            const double d = from.local[j].dot(to.local[j]);
            if (!std::isfinite(d)) {
                out.local[j] = from.local[j].slerp(w, to.local[j]);
                continue;
            }
            const double scale0 = 0.0, scale1 = d < 0.0 ? -1.0 : 1.0;
            out.local[j] =
                Eigen::Quaterniond(scale0 * from.local[j].coeffs() + scale1 * to.local[j].coeffs());
        }
        return;
    }
    for (size_t j = 0; j < out.local.size(); ++j)
        out.local[j] = from.local[j].slerp(w, to.local[j]);
}

const char *to_string(TrackMode mode)
{
    return mode == TrackMode::cartesian ? "cartesian" : "joint";
}

TrackMode track_mode_from_string(const std::string &text)
{
    if (text == "joint")
        return TrackMode::joint;
    if (text == "cartesian")
        return TrackMode::cartesian;
    throw PerformError("mode: expected joint or cartesian, got '" + text + "'");
}

// One arm of Algorithm 2: the chain thorax -> clavicle -> shoulder -> elbow ->
// wrist -> stick tip (docs/ik.md), twice: `feedback` is solved every step from
// the simulated state (eq. 2), `kinematic` follows the targets alone (warm-started
// from its own last solution) and gives the target rates for the feedforward.
struct Tracker::Arm {
    int joint[4] = {-1, -1, -1, -1};
    int base_body = -1;
    KinematicChain feedback, kinematic;
    Eigen::Vector3d integral_m = Eigen::Vector3d::Zero();
    Eigen::Quaterniond theta_target[4], kinematic_target[4], previous_kinematic[4];
    Eigen::Quaterniond posture[4];
    int stuck_steps = 0; // kinematic solves in a row stuck away from the target
};

namespace
{
// A kinematic solve stuck this far from its target (m) for this many solves in a row
// is tried again from the arm's posture; kept when nearer by kIkReseedGain_m.
constexpr double kIkReseedAbove_m = 0.02;
constexpr int kIkReseedSteps = 10;
constexpr double kIkReseedGain_m = 0.005;

void build_arm(const CharacterModel &model, int side, const CharacterPose &initial,
               const std::vector<JointLimitRef> &limits, int joint[4], int &base_body,
               KinematicChain *chains[2])
{
    for (int k = 0; k < 4; ++k) {
        joint[k] = model.joint_index(Tracker::kArmJoints[side][k]);
        if (joint[k] < 0)
            throw PerformError(std::string("cartesian mode: the character has no joint '") +
                               Tracker::kArmJoints[side][k] + "'");
    }
    base_body = model.joint_body(joint[0]).parent;
    for (int c = 0; c < 2; ++c) {
        KinematicChain *chain = chains[c];
        if (!chain)
            continue;
        for (int k = 0; k < 4; ++k) {
            const int j = joint[k];
            chain->add_joint(model.joint_body(j).offset_m, initial.local[j],
                             limits.empty() ? JointLimitRef() : limits[j]);
        }
        const Side s = static_cast<Side>(side);
        chain->set_tip(model.stick(s).tip_m, model.stick(s).axis);
    }
}
} // namespace

Tracker::Tracker(const CharacterModel &model, const SceneOptions &scene_options,
                 const CharacterPose &initial, const std::vector<JointGains> &gains,
                 const std::vector<JointLimitRef> &limits, TrackMode mode,
                 const CartesianOptions &cartesian, const GainOptions &gain_options,
                 const std::vector<JointLimitRef> *ik_limits)
    : mode_(mode), cartesian_(cartesian)
{
    const int nj = CharacterModel::kJoints;
    if (static_cast<int>(initial.local.size()) != nj)
        throw PerformError("tracker: the initial pose needs one rotation per joint");
    ChainIkSolverPos_dls probe(4);
    if (!probe.set_params(cartesian.ik))
        throw PerformError("ik parameters: expected finite positive values");
    velocity_gain_s_ = cartesian.velocity_gain_s >= 0.0
                           ? cartesian.velocity_gain_s
                           : (std::sqrt(cartesian.gain) - 1.0) * 2.0 * gain_options.damping_ratio /
                                 (2.0 * M_PI * gain_options.natural_frequency_hz);
    scene_ = std::make_unique<Scene>(model, scene_options, initial, gains);
    scene_->set_joint_limits(limits);
    // The arms are built in both modes: joint mode uses their kinematic IK
    // when a step brings tip targets, and the mode may change while running.
    for (int s = 0; s < 2; ++s) {
        arms_[s] = std::make_unique<Arm>();
        Arm &arm = *arms_[s];
        KinematicChain *chains[2] = {&arm.feedback, &arm.kinematic};
        build_arm(scene_->model(), s, initial, ik_limits ? *ik_limits : limits, arm.joint,
                  arm.base_body, chains);
        for (int k = 0; k < 4; ++k)
            arm.theta_target[k] = arm.kinematic_target[k] = arm.previous_kinematic[k] =
                arm.posture[k] = initial.local[arm.joint[k]];
    }
    solver_ = std::make_unique<ChainIkSolverPos_dls>(4, cartesian.ik);
    IkParams feedback_ik = cartesian.ik;
    if (cartesian.feedback_iterations > 0)
        feedback_ik.max_iterations = cartesian.feedback_iterations;
    feedback_solver_ = std::make_unique<ChainIkSolverPos_dls>(4, feedback_ik);
    // The kinematic IK's own cap (it only gives the target rates).
    if (cartesian.kinematic_iterations > 0) {
        IkParams kinematic_ik = cartesian.ik;
        kinematic_ik.max_iterations = cartesian.kinematic_iterations;
        solver_ = std::make_unique<ChainIkSolverPos_dls>(4, kinematic_ik);
    }
    previous_reference_ = initial.local;
    target_ = initial.local;
    sim_local_ = initial.local;
    rate_.assign(nj, Eigen::Vector3d::Zero());
    target_pose_ = initial;
    model.forward(initial, sim_frames_);
    target_frames_ = sim_frames_;
}

Tracker::~Tracker() = default;

void Tracker::set_posture(int side, const Eigen::Quaterniond posture[4])
{
    for (int k = 0; k < 4; ++k)
        arms_[side & 1]->posture[k] = posture[k].normalized();
}

const Eigen::Quaterniond &Tracker::kinematic_target(int side, int k) const
{
    return arms_[side & 1]->kinematic_target[k & 3];
}

StepResult Tracker::step(const CharacterPose &reference, const TipTargets *tips, bool integrate)
{
    follow_reference(reference, tips != nullptr);
    const bool cartesian = mode_ == TrackMode::cartesian;
    if (cartesian && !tips)
        throw PerformError("cartesian mode: a step needs tip targets");
    if (tips)
        drive_arms(reference, *tips, integrate);
    scene_->set_joint_targets(target_, rate_);
    ++steps_;
    return scene_->step();
}

void Tracker::follow_reference(const CharacterPose &reference, bool tips_drive_arms)
{
    const int nj = CharacterModel::kJoints;
    const double h = scene_->options().step_s;
    // The reference's rates, where something reads them: not an arm's when tips
    // drive the arms (the kinematic IK gives its rate), nor a joint whose
    // body the scene places instead of driving it (SceneOptions::legs_kinematic).
    std::array<bool, CharacterModel::kJoints> rate_read;
    for (int j = 0; j < nj; ++j)
        rate_read[j] = !scene_->body_kinematic(j + 1);
    if (tips_drive_arms)
        for (int s = 0; s < 2; ++s)
            for (int k = 0; k < 4; ++k)
                rate_read[arms_[s]->joint[k]] = false;
    for (int j = 0; j < nj; ++j) {
        target_[j] = reference.local[j];
        if (rate_read[j])
            rate_[j] = log_map(target_[j] * previous_reference_[j].conjugate()) / h;
    }
    previous_reference_ = reference.local; // same size: no allocation
}

// Algorithm 2 (Cartesian), or the kinematic IK alone (joint mode with tips).
void Tracker::drive_arms(const CharacterPose &reference, const TipTargets &tips, bool integrate)
{
    const CharacterModel &model = scene_->model();
    const bool cartesian = mode_ == TrackMode::cartesian;
    const auto ik_start = std::chrono::steady_clock::now();
    target_pose_.pelvis_position_m = reference.pelvis_position_m;
    target_pose_.pelvis_rotation = reference.pelvis_rotation;
    target_pose_.local = target_;
    model.forward(target_pose_, target_frames_);
    if (cartesian) {
        scene_->body_frames(sim_frames_);
        scene_->local_rotations(sim_local_);
    }
    for (int s = 0; s < 2; ++s) {
        Arm &arm = *arms_[s];
        const Side side = static_cast<Side>(s);
        const int hb = model.hand_body(side);
        const Eigen::Vector3d tip_target =
            tips.has_position ? tips.position_m[s]
                              : model.tip_position(side, target_frames_.origin_m[hb],
                                                   target_frames_.rotation[hb]);
        solve_kinematic(arm, side, tip_target, tips);
        if (cartesian) {
            solve_feedback(arm, side, tip_target, tips, integrate);
        } else {
            for (int k = 0; k < 4; ++k)
                arm.theta_target[k] = arm.kinematic_target[k];
        }
        set_arm_targets(arm);
    }
    ik_stats_.wall_s +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - ik_start).count();
}

void Tracker::count_solve(const IkResult &r)
{
    ik_stats_.iterations += r.iterations;
    ik_stats_.max_iterations = std::max(ik_stats_.max_iterations, r.iterations);
    ik_stats_.not_converged += r.status != IkStatus::converged;
    ++ik_stats_.solves;
}

// Kinematic IK: the arm's target trajectory without the body, for the target
// rates (feedforward of eq. 1), capped at CartesianOptions::max_joint_speed_rad_s.
void Tracker::solve_kinematic(Arm &arm, Side side, const Eigen::Vector3d &tip_target,
                              const TipTargets &tips)
{
    const CartesianOptions &co = cartesian_;
    const int s = static_cast<int>(side);
    arm.kinematic.set_base(target_frames_.origin_m[arm.base_body],
                           target_frames_.rotation[arm.base_body]);
    if (co.reference_has_arms)
        for (int k = 0; k < 4; ++k)
            arm.kinematic_target[k] = target_[arm.joint[k]];
    arm.kinematic.set_rotations(arm.kinematic_target);
    Eigen::Quaterniond hand_target;
    double plane = 0.0;
    const bool orient =
        tips.has_direction && co.rotation_weight > 0.0 &&
        held_rotation(scene_->model(), side, tips.stick_direction[s], hand_target, &plane);
    auto solve = [&](Eigen::Quaterniond *out) {
        return orient ? solver_->solve(arm.kinematic, tip_target, hand_target,
                                       co.rotation_weight * plane, out)
               : co.posture_weight > 0.0
                   ? solver_->solve_with_posture(arm.kinematic, tip_target, arm.posture,
                                                 co.posture_weight, out)
                   : solver_->solve(arm.kinematic, tip_target, out);
    };
    const IkResult r = solve(arm.kinematic_target);
    count_solve(r);
    // Warm-started from its own last solution, the solve can stay in a local minimum
    // at a joint's limit: a right arm folded across the chest (elbow at 45 degrees)
    // after crossing from the floor tom to the hi-hat in 0.3 s, 16-18 cm short of
    // every hi-hat note for 6 s. Stuck for kIkReseedSteps solves, it is solved again
    // from the arm's posture, and that solution kept when it is nearer the target by
    // kIkReseedGain_m (the rate cap below still limits the step toward it).
    if (r.status == IkStatus::converged || !(r.position_error_m > kIkReseedAbove_m)) {
        arm.stuck_steps = 0;
    } else if (++arm.stuck_steps >= kIkReseedSteps) {
        arm.stuck_steps = 0;
        Eigen::Quaterniond seeded[4];
        arm.kinematic.set_rotations(arm.posture);
        const IkResult again = solve(seeded);
        count_solve(again);
        if (again.position_error_m < r.position_error_m - kIkReseedGain_m) {
            for (int k = 0; k < 4; ++k)
                arm.kinematic_target[k] = seeded[k];
            ++ik_stats_.reseeded;
        }
    }
    if (!(co.max_joint_speed_rad_s > 0.0 && steps_ > 0))
        return;
    const double cap = co.max_joint_speed_rad_s * scene_->options().step_s;
    for (int k = 0; k < 4; ++k) {
        const double a = rotation_angle_between(arm.previous_kinematic[k], arm.kinematic_target[k]);
        if (a > cap) {
            arm.kinematic_target[k] =
                arm.previous_kinematic[k].slerp(cap / a, arm.kinematic_target[k]);
            ++ik_stats_.rate_capped;
        }
    }
}

// Eq. 2 with its gain: the IK target is X^S + gain (X^T - X^S) (+ the
// velocity, acceleration and integral terms, capped), X^S from the
// simulated thorax and Theta^S. The solve starts from Theta^S (eq. 2
// literally) or from the kinematic solution, which holds the arm's
// null space (CartesianOptions::start_from_simulated, docs/ik.md).
void Tracker::solve_feedback(Arm &arm, Side side, const Eigen::Vector3d &tip_target,
                             const TipTargets &tips, bool integrate)
{
    const CartesianOptions &co = cartesian_;
    const int s = static_cast<int>(side);
    const double h = scene_->options().step_s;
    arm.feedback.set_base(sim_frames_.origin_m[arm.base_body], sim_frames_.rotation[arm.base_body]);
    for (int k = 0; k < 4; ++k)
        arm.feedback.set_rotation(k, sim_local_[arm.joint[k]]);
    const Eigen::Vector3d sim_tip_chain = arm.feedback.tip_position();
    if (!co.start_from_simulated)
        arm.feedback.set_rotations(arm.kinematic_target);
    // X^S where the hand holds the stick: on a fulcrum the stick's
    // own swing (its rebound) is physics, not an error for the arm.
    const Eigen::Vector3d error = tip_target - scene_->held_tip_position(side);
    const Eigen::Vector3d velocity_error = tips.velocity_mps[s] - scene_->held_tip_velocity(side);
    if (co.integral_per_s > 0.0 && integrate) {
        arm.integral_m += co.integral_per_s * h * error;
        const double norm = arm.integral_m.norm();
        if (norm > co.integral_limit_m)
            arm.integral_m *= co.integral_limit_m / norm;
    }
    Eigen::Vector3d correction = (co.gain - 1.0) * error + velocity_gain_s_ * velocity_error +
                                 co.acceleration_feedforward_s2 * tips.acceleration_mps2[s];
    const double correction_norm = correction.norm();
    if (correction_norm > co.correction_limit_m)
        correction *= co.correction_limit_m / correction_norm;
    const Eigen::Vector3d ik_target = sim_tip_chain + error + correction + arm.integral_m;
    // The hands' rotation task stays in the kinematic IK: from its
    // solution the feedback solve moves the arm only as the tip
    // error asks (with the hand's rotation held, the gain's
    // correction would have to come from the upper arm alone, and
    // the loop chattered: docs/perform.md, "Holding the stick").
    // From Theta^S the posture task holds the arm's null space (docs/ik.md).
    count_solve(co.start_from_simulated && co.posture_weight > 0.0
                    ? feedback_solver_->solve_with_posture(arm.feedback, ik_target, arm.posture,
                                                           co.posture_weight, arm.theta_target)
                    : feedback_solver_->solve(arm.feedback, ik_target, arm.theta_target));
}

// The arm's PD targets Theta^T and, for the feedforward, the kinematic IK's rates.
void Tracker::set_arm_targets(Arm &arm)
{
    const double h = scene_->options().step_s;
    for (int k = 0; k < 4; ++k) {
        const int j = arm.joint[k];
        target_[j] = arm.theta_target[k];
        rate_[j] =
            steps_ == 0
                ? Eigen::Vector3d::Zero()
                : Eigen::Vector3d(
                      log_map(arm.kinematic_target[k] * arm.previous_kinematic[k].conjugate()) / h);
        arm.previous_kinematic[k] = arm.kinematic_target[k];
    }
}

bool held_rotation(const CharacterModel &model, Side side, const Eigen::Vector3d &direction,
                   Eigen::Quaterniond &out, double *weight)
{
    const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
    if (!(direction.allFinite() && direction.norm() > 1e-9))
        return false;
    const Eigen::Vector3d d = direction.normalized();
    // French (thumb up): the fulcrum axis is stick x thumb = d x up; German
    // (palm down): stick x palm normal = d x (-up) (character.cpp).
    Eigen::Vector3d f = model.options().grip == Grip::french ? d.cross(up) : up.cross(d);
    // |f| is the cosine of the stick's elevation: 0.5 at 60 degrees, 0.2 at 78.
    const double x = std::clamp((f.norm() - 0.2) / (0.5 - 0.2), 0.0, 1.0);
    if (weight)
        *weight = x * x * (3.0 - 2.0 * x);
    if (x <= 0.0)
        return false;
    f.normalize();
    const StickInHand &st = model.stick(side);
    Eigen::Matrix3d local, world;
    local << st.axis, st.fulcrum_axis, st.axis.cross(st.fulcrum_axis);
    world << d, f, d.cross(f);
    out = Eigen::Quaterniond(Eigen::Matrix3d(world * local.transpose()));
    out.normalize();
    return true;
}

void Tracker::solve_arms(const CharacterModel &model, const std::vector<JointLimitRef> &limits,
                         const IkParams &ik, const std::array<Eigen::Vector3d, 2> &tips,
                         CharacterPose &pose, const std::array<Eigen::Vector3d, 2> *directions)
{
    BodyFrames frames;
    model.forward(pose, frames);
    ChainIkSolverPos_dls cold(4, ik);
    for (int s = 0; s < 2; ++s) {
        int joint[4], base_body = -1;
        KinematicChain chain;
        KinematicChain *chains[2] = {&chain, nullptr};
        build_arm(model, s, pose, limits, joint, base_body, chains);
        chain.set_base(frames.origin_m[base_body], frames.rotation[base_body]);
        Eigen::Quaterniond q[4];
        // Repeated calls: the solver's per-call budget is 16 steps.
        for (int call = 0; call < 20; ++call) {
            Eigen::Quaterniond hand;
            double plane = 0.0;
            const bool orient = directions && held_rotation(model, static_cast<Side>(s),
                                                            (*directions)[s], hand, &plane);
            const IkResult r =
                orient ? cold.solve(chain, tips[s], hand, plane, q) : cold.solve(chain, tips[s], q);
            chain.set_rotations(q);
            if (r.status == IkStatus::converged)
                break;
        }
        for (int k = 0; k < 4; ++k)
            pose.local[joint[k]] = chain.rotation(k);
    }
}

} // namespace ictus
