// Stepping the ODE scene: the joint targets in, the motors' rows (eq. 1) and
// the limit stops, collision with the drum, the step, the divergence check
// and the reset. Building is in scene_build.cpp, the state read back in
// scene_state.cpp.
#include "ictus/base/rotation.hpp"
#include "ictus/sim/scene.hpp"
#include "scene_ode.hpp"
#include "stick_tip.h"

#include <ode/ode.h>

#include <chrono>
#include <cmath>
#include <utility>

namespace ictus
{

namespace
{

using ode::to_eigen;
using ode::to_eigen3;
using ode::to_ode;

// A stick part's first contact with the drum is on the head when the contact
// normal's upward component exceeds this (the head's own normal: 1; the rim's
// edge met from above: > 0; the shell's side: 0, its bottom: -1).
constexpr double kHeadNormalMin = 0.2;

} // namespace

// The bead's contact with the head: the tip's law (stick_tip.h, the law contact~
// plays: F = k x^alpha) in series with the head's point stiffness with its
// stretching, F = k_h y + k3 y^3 (massless). Returns the pair's secant stiffness
// F / d (N/m) at the depth d: ODE's soft contact is a linear spring-damper per
// step, and with the secant of the depth it has now, the contact's force at that
// depth is the law's. The law's Hunt-Crossley term is left out: the head's damper
// c is the contact's loss (docs/character.md, "Drum").
double series_contact_stiffness(double k_head, double k3, double k_tip, double alpha, double depth)
{
    if (!(depth > 0.0))
        return k_head;
    return stick_tip_series_force(k_tip, alpha, k_head, k3, depth, nullptr) / depth;
}

void Scene::set_joint_targets(const std::vector<Eigen::Quaterniond> &local,
                              const std::vector<Eigen::Vector3d> &rate_parent)
{
    const size_t n = CharacterModel::kJoints;
    if (local.size() != n || rate_parent.size() != n)
        throw SimError("joint targets: expected 19 rotations and 19 rates");
    for (size_t j = 0; j < n; ++j) {
        Eigen::Quaterniond q = local[j];
        if (!q.coeffs().allFinite() || q.norm() < 1e-9 || !rate_parent[j].allFinite())
            throw SimError("joint targets: non-finite target for joint '" +
                           model_.joint_name(static_cast<int>(j)) + "'");
        q.normalize();
        if (!limits_.empty() && limits_[j].active())
            q = limits_[j].clamp(q).normalized();
        target_[j] = q;
        target_rate_[j] = rate_parent[j];
    }
}

void Scene::near_callback(void *data, dGeomID a, dGeomID b)
{
    Scene *self = static_cast<Scene *>(data);
    // Only sticks meet drums (category bits). The stick's geom goes first,
    // so that its body is the contact joint's body 1 and the joint feedback's
    // f1 is the force on the stick (the normal then points into the stick).
    int drum = -1;
    for (int i = 0; i < self->drum_count(); ++i) {
        if (a == self->drum_geom_[i]) {
            std::swap(a, b);
            drum = i;
        } else if (b == self->drum_geom_[i]) {
            drum = i;
        }
    }
    if (drum < 0)
        return;
    int side = -1;
    bool bead = false;
    for (int s = 0; s < 2; ++s) {
        if (a == self->stick_tip_[s]) {
            side = s;
            bead = true;
        } else if (a == self->stick_shaft_[s]) {
            side = s;
        }
    }
    constexpr int kMax = 4;
    dContactGeom geoms[kMax];
    const int n = dCollide(a, b, kMax, geoms, sizeof(dContactGeom));
    if (n <= 0 || side < 0)
        return;
    // The stick meets the head from above; a part that first touches the
    // drum anywhere else (the shell's side or bottom: a clip's arm rising
    // under a drum placed for its strokes) passes through the drum until it
    // is clear of it. Blocked there, the hand would drive the stick against
    // the shell with the arm's whole strength and wrench it round its fulcrum.
    const int part = 4 * drum + 2 * side + (bead ? 1 : 0);
    self->part_touching_now_[static_cast<size_t>(part)] = true;
    if (!self->part_touching_[static_cast<size_t>(part)]) {
        int deepest = 0;
        for (int i = 1; i < n; ++i)
            if (geoms[i].depth > geoms[deepest].depth)
                deepest = i;
        // The normal points into the stick: up (the drum's axis, +y) on the
        // head, outward and up on the rim's edge, level on the shell's side.
        bool from_above = geoms[deepest].normal[1] > kHeadNormalMin;
        // A plate is soft in its contact (its bending) and 1 cm thick: an ff
        // bead sinks deeper than the disc, the shaft behind it follows, and
        // the capsule-cylinder collision (libccd) gives a nearly flat capsule
        // deeper than the disc a sideways normal; a bead skidding off a loud
        // crash's edge comes back at its side. A plate lets a part through
        // only from below: a normal pointing down, or a touch in the disc's
        // lower half while the part rises. Anything else meets it.
        if (!from_above && self->drum(drum).plate_bending_n_m > 0.0) {
            const DrumParams &piece = self->drum(drum);
            dVector3 v;
            dBodyGetPointVel(self->stick_body_[side], geoms[deepest].pos[0], geoms[deepest].pos[1],
                             geoms[deepest].pos[2], v);
            const bool lower_half =
                geoms[deepest].pos[1] < piece.center_m.y() - 0.5 * piece.shell_depth_m;
            from_above =
                !(geoms[deepest].normal[1] < -kHeadNormalMin || (lower_half && v[1] > 0.0));
        }
        self->part_through_[static_cast<size_t>(part)] = !from_above;
        // A shaft arriving at a plate's edge from the side: its first touch
        // level and shallower than the disc is thick, its bead not on that
        // plate (below). A shaft first found deeper than that came in some
        // other way (a strike near the edge, its bead sunk into the soft
        // contact), and its normal there says nothing of where it came from.
        self->part_edge_on_[static_cast<size_t>(part)] =
            from_above && !bead && self->drum(drum).plate_bending_n_m > 0.0 &&
            std::abs(geoms[deepest].normal[1]) <= kHeadNormalMin &&
            geoms[deepest].depth < self->drum(drum).shell_depth_m &&
            !self->part_touching_[static_cast<size_t>(part + 1)] &&
            !self->part_touching_now_[static_cast<size_t>(part + 1)];
        if (!from_above) {
            ++self->shell_passes_;
            ++self->drum_shell_passes_[static_cast<size_t>(drum)];
        }
    }
    // A shaft that arrived at a plate's edge from the side (above) and is
    // driven into it deeper than the disc is thick passes through it from then
    // on: a real cymbal tilts away on its felt. Held there by the plate's
    // bending stiffness (a stiffness across the plate, 20 kN/m for the
    // hi-hat), an arm lagging a fast move across the kit drove a shaft 3-11 cm
    // into the hi-hat's edge at 600-2300 N, the collision's normal turning as
    // it sank, and the spring threw the stick off at 50 m/s and more
    // (docs/character.md, "Drum").
    const DrumParams &piece = self->drum(drum);
    if (self->part_edge_on_[static_cast<size_t>(part)] &&
        !self->part_through_[static_cast<size_t>(part)]) {
        for (int i = 0; i < n; ++i)
            if (std::abs(geoms[i].normal[1]) <= kHeadNormalMin &&
                geoms[i].depth > piece.shell_depth_m) {
                self->part_through_[static_cast<size_t>(part)] = true;
                ++self->shell_passes_;
                ++self->drum_shell_passes_[static_cast<size_t>(drum)];
                break;
            }
    }
    if (self->part_through_[static_cast<size_t>(part)])
        return;
    for (int i = 0; i < n; ++i) {
        dContact contact;
        contact.geom = geoms[i];
        contact.surface.mode = dContactSoftERP | dContactSoftCFM | dContactApprox1;
        contact.surface.mu = self->drum(drum).friction;
        // A shaft pressed on a plate's edge from the side slides on it: a real
        // cymbal tilts on its felt away from the stick (the disc here is
        // static). With friction there, a hand crossing to the hi-hat wedged
        // its stick on the edge and could neither lift nor reach it for a bar.
        if (!bead && self->drum(drum).plate_bending_n_m > 0.0 &&
            geoms[i].normal[1] <= kHeadNormalMin)
            contact.surface.mu = 0.0;
        contact.surface.soft_erp = self->contact_erp_[static_cast<size_t>(drum)];
        contact.surface.soft_cfm = self->contact_cfm_[static_cast<size_t>(drum)];
        const double k3 = self->head_k3_[static_cast<size_t>(drum)];
        if (bead && (self->tip_stiffness_ > 0.0 || k3 > 0.0)) {
            const double k_head = self->drum_contact_stiffness_n_per_m(drum);
            const SoftContact sc =
                soft_contact(self->options_.step_s,
                             series_contact_stiffness(k_head, k3, self->tip_stiffness_,
                                                      self->tip_alpha_, geoms[i].depth),
                             self->drum(drum).contact_damping_n_s_per_m,
                             self->options_.contact_numerical_damping_compensated);
            contact.surface.soft_erp = sc.erp;
            contact.surface.soft_cfm = sc.cfm;
        }
        dJointID joint = dJointCreateContact(self->world_, self->contacts_, &contact);
        dJointAttach(joint, dGeomGetBody(a), dGeomGetBody(b));
        if (self->contact_slots_used_ < static_cast<int>(self->contact_slot_.size())) {
            ContactSlot &slot = self->contact_slot_[self->contact_slots_used_++];
            slot.feedback = Feedback{};
            slot.side = side;
            slot.bead = bead;
            dJointSetFeedback(joint, reinterpret_cast<dJointFeedback *>(&slot.feedback));
        }
    }
    self->contacts_last_step_ += n;
}

void Scene::gather_contact_forces()
{
    drum_contact_ = {};
    for (int i = 0; i < contact_slots_used_; ++i) {
        const ContactSlot &slot = contact_slot_[i];
        StickDrumContact &c = drum_contact_[slot.side];
        const Eigen::Vector3d f = to_eigen3(slot.feedback.f1);
        if (slot.bead) {
            c.bead_force_n += f;
            ++c.bead_points;
        } else {
            c.shaft_force_n += f;
            ++c.shaft_points;
        }
    }
}

void Scene::apply_control()
{
    stops_active_ = 0;
    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        const int child = j + 1;
        if (kinematic_body_[child])
            continue; // placed, not driven
        const int parent = model_.bodies()[child].parent;
        const Eigen::Quaterniond qp = to_eigen(dBodyGetQuaternion(body_[parent]));
        const Eigen::Quaterniond qc = to_eigen(dBodyGetQuaternion(body_[child]));
        const MotorCommand cmd = pd_motor_command(qp, qc, target_[j], target_rate_[j], gains_[j],
                                                  options_.rate_feedforward);
        drive_motor(j, cmd, limit_stop(j, qp, qc, cmd));
        if (motor_noise_ > 0.0) {
            // Signal-dependent noise (Harris & Wolpert 1998): its SD grows
            // with the commanded torque, here the PD's stiffness part.
            const double command_nm =
                std::min(gains_[j].kp_nm_per_rad * cmd.error_parent.norm(), cmd.fmax);
            const double sd = motor_noise_ * kTorqueNoiseCv * command_nm;
            const Eigen::Vector3d n(sd * motor_noise_stream_.normal(),
                                    sd * motor_noise_stream_.normal(),
                                    sd * motor_noise_stream_.normal());
            dBodyAddTorque(body_[child], n.x(), n.y(), n.z());
            dBodyAddTorque(body_[parent], -n.x(), -n.y(), -n.z());
        }
    }
}

void Scene::set_motor_noise(double amount, std::uint64_t seed)
{
    if (!(amount >= 0.0 && std::isfinite(amount)))
        throw SimError("motor noise: the amount must be >= 0, got " + std::to_string(amount));
    motor_noise_ = amount;
    motor_noise_stream_ = MotorNoise(seed, 0); // stream 0: the controller's
}

// The joint's present rate (child relative to parent, world).
Eigen::Vector3d Scene::relative_rate(int joint) const
{
    const int child = joint + 1;
    const int parent = model_.bodies()[child].parent;
    return Eigen::Vector3d(to_eigen3(dBodyGetAngularVel(body_[child])) -
                           to_eigen3(dBodyGetAngularVel(body_[parent])));
}

// Safety net: a joint outside its limit region by more than the margin meets
// a one-sided stop along the direction of the violation.
Scene::LimitStop Scene::limit_stop(int j, const Eigen::Quaterniond &qp,
                                   const Eigen::Quaterniond &qc, const MotorCommand &cmd) const
{
    LimitStop stop;
    stop.stop_at = options_.stop_margin_rad;
    if (!(options_.limit_stops && !limits_.empty() && limits_[j].active()))
        return stop;
    const Eigen::Quaterniond current = qp.conjugate() * qc;
    const Eigen::Quaterniond inside = limits_[j].clamp(current);
    // A joint the clamp leaves where it is (every limit returns
    // q.normalized() inside) has no violation: the rotation between the two
    // would be rounding, and its direction a random stop axis that the
    // look-ahead below engaged on fast joints (1 deg margin, > 17 rad/s: 6 of
    // the default score's 24 stops, measured).
    const bool outside = !(inside.coeffs() == current.normalized().coeffs());
    const Eigen::Vector3d v =
        outside ? log_map(current * inside.conjugate()) : Eigen::Vector3d::Zero();
    const double violation = v.norm();
    stop.violation = violation;
    if (!(violation > 0.0)) {
        if (options_.stop_inelastic)
            look_ahead_stop(j, qp, current, cmd, stop);
        return stop;
    }
    // The stop engages one step early: when the joint would be past the
    // margin after this step at its present rate, so a fast joint does not
    // run past it before the stop row exists. Inelastic
    // (SceneOptions::stop_inelastic): past the margin the row takes the joint
    // back to it (at the stop ERP); short of it, the row holds the joint where
    // it is for this step (the stop set at the present angle). Else the row
    // sees the predicted angle.
    const Eigen::Vector3d axis = (qp * v) / violation;
    const Eigen::Vector3d w_rel = relative_rate(j);
    const double rate = options_.stop_inelastic
                            ? std::max(w_rel.dot(axis), cmd.velocity_world.dot(axis))
                            : w_rel.dot(axis);
    const double predicted = violation + std::max(0.0, rate) * options_.step_s;
    if (predicted > options_.stop_margin_rad) {
        stop.engaged = true;
        stop.axis = axis;
        if (options_.stop_inelastic)
            stop.stop_at = std::min(options_.stop_margin_rad, violation);
        else
            stop.violation = predicted;
    }
    return stop;
}

// Inside its region a joint fast enough to cross the margin within the step
// (rate h > margin) would pass it before a stop row exists: a whipping elbow
// went 2.3 deg past its range in one step (1 ms at 40 rad/s). Its rotation
// after the step at the present rate is tested instead; past the margin, the
// row holds it where it is along the predicted violation for this step (as a
// joint short of the margin). Score mode (SceneOptions::stop_inelastic) only.
void Scene::look_ahead_stop(int j, const Eigen::Quaterniond &qp, const Eigen::Quaterniond &current,
                            const MotorCommand &cmd, LimitStop &stop) const
{
    const Eigen::Vector3d w_now = relative_rate(j);
    const Eigen::Vector3d &w_rel =
        cmd.velocity_world.squaredNorm() > w_now.squaredNorm() ? cmd.velocity_world : w_now;
    const double turn = w_rel.norm() * options_.step_s;
    if (!(turn > options_.stop_margin_rad))
        return;
    const Eigen::Vector3d w_parent = qp.conjugate() * w_rel;
    const Eigen::Quaterniond next =
        Eigen::Quaterniond(Eigen::AngleAxisd(turn, w_parent.normalized())) * current.normalized();
    const Eigen::Quaterniond next_inside = limits_[j].clamp(next);
    if (next_inside.coeffs() == next.normalized().coeffs())
        return;
    const Eigen::Vector3d vn = log_map(next * next_inside.conjugate());
    const double ahead = vn.norm();
    if (ahead > options_.stop_margin_rad) {
        stop.engaged = true;
        stop.axis = (qp * vn) / ahead;
        stop.stop_at = 0.0; // violation is 0: held where it is
    }
}

// The motor's rows for this step: the PD command on three axes (the world's,
// or the stop's axis and two orthogonal to it), the stop's row, and, while a
// score mode stop locks the joint, axes 2 and 3 held. Only what changed goes
// to ODE (the CFM and force limits change with the gains and the stops, the
// velocities every step).
void Scene::drive_motor(int j, const MotorCommand &cmd, const LimitStop &limit)
{
    dJointID m = motor_[j];
    const bool stop = limit.engaged;
    // Score mode's stop (inelastic) also holds the joint's other two axes
    // for the step: the range is not convex, so moving across the stop's
    // axis took joints further out (an elbow held on its stop axis went
    // from 0 to 2.4 and 4.4 deg out in two steps, random seed 2080).
    // Held there, a joint whose target lies across its stop (the geodesic to it leaves the
    // range) would stay frozen while the stop engages at every step: a right shoulder
    // after a ride-to-hi-hat move in 107 ms stood 0.8 rad from its target through the
    // hi-hat's bars, the stick 37 cm off (perform_recover). After kStopDeadlockSteps steps,
    // held that far, axes 2 and 3 are let go: the joint slides along the stop toward its target.
    constexpr double kStopDeadlockRad = 0.3;
    constexpr int kStopDeadlockSteps = 50;
    MotorParams &held = motor_params_[j];
    held.held_far = stop && options_.stop_inelastic && cmd.error_parent.norm() > kStopDeadlockRad
                        ? held.held_far + 1
                        : 0;
    const bool lock = stop && options_.stop_inelastic && held.held_far <= kStopDeadlockSteps;
    Eigen::Vector3d axes[3];
    if (stop) {
        axes[0] = limit.axis;
        axes[1] = limit.axis.unitOrthogonal();
        axes[2] = axes[0].cross(axes[1]);
        for (int i = 0; i < 3; ++i)
            dJointSetAMotorAxis(m, i, 0, axes[i].x(), axes[i].y(), axes[i].z());
        motor_axes_world_[j] = false;
        ++stops_active_;
    } else {
        for (int i = 0; i < 3; ++i)
            axes[i] = Eigen::Vector3d::Unit(i);
        if (!motor_axes_world_[j]) {
            for (int i = 0; i < 3; ++i)
                dJointSetAMotorAxis(m, i, 0, axes[i].x(), axes[i].y(), axes[i].z());
            motor_axes_world_[j] = true;
        }
    }
    for (int i = 0; i < 3; ++i)
        motor_axes_[j][i] = axes[i];
    static const int kVel[3] = {dParamVel1, dParamVel2, dParamVel3};
    static const int kFMax[3] = {dParamFMax1, dParamFMax2, dParamFMax3};
    static const int kCfm[3] = {dParamCFM1, dParamCFM2, dParamCFM3};
    MotorParams &last = motor_params_[j];
    const bool new_cfm = !(cmd.cfm == last.cfm);
    last.cfm = cmd.cfm;
    for (int i = 0; i < 3; ++i) {
        dJointSetAMotorParam(m, kVel[i], cmd.velocity_world.dot(axes[i]));
        if (new_cfm)
            dJointSetAMotorParam(m, kCfm[i], cmd.cfm);
        // On a stopped axis only the stop acts: ODE would otherwise push
        // with the full motor force as an explicit torque.
        const double fmax = (stop && (i == 0 || lock)) ? 0.0 : cmd.fmax;
        if (!(fmax == last.fmax[i]))
            dJointSetAMotorParam(m, kFMax[i], fmax);
        last.fmax[i] = fmax;
    }
    if (stop) {
        dJointSetAMotorAngle(m, 0, limit.violation);
        dJointSetAMotorParam(m, dParamLoStop1, -dInfinity);
        dJointSetAMotorParam(m, dParamHiStop1, limit.stop_at);
        dJointSetAMotorParam(m, dParamStopERP, options_.stop_erp);
        last.stops_open = false;
    } else if (!last.stops_open) {
        dJointSetAMotorParam(m, dParamHiStop1, dInfinity);
        dJointSetAMotorParam(m, dParamLoStop1, -dInfinity);
        last.stops_open = true;
    }
    // Axes 2 and 3: held at their present angle (a two-sided stop at 0)
    // while locked, open otherwise; only what changed goes to ODE.
    if (lock) {
        dJointSetAMotorAngle(m, 1, 0.0);
        dJointSetAMotorAngle(m, 2, 0.0);
    }
    if (lock != last.locked) {
        const double lo = lock ? 0.0 : -dInfinity, hi = lock ? 0.0 : dInfinity;
        dJointSetAMotorParam(m, dParamHiStop2, hi);
        dJointSetAMotorParam(m, dParamLoStop2, lo);
        dJointSetAMotorParam(m, dParamHiStop3, hi);
        dJointSetAMotorParam(m, dParamLoStop3, lo);
        last.locked = lock;
    }
}

bool Scene::check() const
{
    for (int b = 0; b < CharacterModel::kBodies + 2; ++b) {
        dBodyID body =
            b < CharacterModel::kBodies ? body_[b] : stick_body_[b - CharacterModel::kBodies];
        if (!body || (b < CharacterModel::kBodies && kinematic_body_[b]))
            continue;
        const Eigen::Vector3d p = to_eigen3(dBodyGetPosition(body));
        const Eigen::Vector3d v = to_eigen3(dBodyGetLinearVel(body));
        const Eigen::Vector3d w = to_eigen3(dBodyGetAngularVel(body));
        const Eigen::Quaterniond q = to_eigen(dBodyGetQuaternion(body));
        if (!p.allFinite() || !v.allFinite() || !w.allFinite() || !q.coeffs().allFinite())
            return false;
        if (v.norm() > options_.max_linear_speed_mps || w.norm() > options_.max_angular_speed_rad_s)
            return false;
    }
    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        if (kinematic_body_[j + 1])
            continue;
        dVector3 a1, a2;
        dJointGetBallAnchor(ball_[j], a1);
        dJointGetBallAnchor2(ball_[j], a2);
        const double d =
            std::sqrt((a1[0] - a2[0]) * (a1[0] - a2[0]) + (a1[1] - a2[1]) * (a1[1] - a2[1]) +
                      (a1[2] - a2[2]) * (a1[2] - a2[2]));
        if (!(d <= options_.max_joint_separation_m))
            return false;
    }
    for (dJointID f : fulcrum_) {
        if (!f)
            continue;
        dVector3 a1, a2;
        dJointGetHingeAnchor(f, a1);
        dJointGetHingeAnchor2(f, a2);
        const Eigen::Vector3d d = to_eigen3(a1) - to_eigen3(a2);
        if (!(d.norm() <= options_.max_joint_separation_m))
            return false;
    }
    return true;
}

StepResult Scene::step(StepTiming *timing)
{
    using clock = std::chrono::steady_clock;
    clock::time_point t0, t1, t2, t3, t4;
    if (timing)
        t0 = clock::now();
    apply_control();
    if (timing)
        t1 = clock::now();
    contacts_last_step_ = 0;
    contact_slots_used_ = 0;
    part_touching_now_.fill(false);
    dSpaceCollide(space_, this, &Scene::near_callback);
    part_touching_ = part_touching_now_;
    for (size_t p = 0; p < part_through_.size(); ++p) {
        part_through_[p] = part_through_[p] && part_touching_[p]; // clear of the drum
        part_edge_on_[p] = part_edge_on_[p] && part_touching_[p];
    }
    if (contacts_last_step_ > 0)
        ++contact_steps_;
    if (timing)
        t2 = clock::now();
    if (options_.stepper == Stepper::quick)
        dWorldQuickStep(world_, options_.step_s);
    else
        dWorldStep(world_, options_.step_s);
    // The feedback slots are ours: read after the step, valid after the joints go.
    gather_contact_forces();
    dJointGroupEmpty(contacts_);
    if (timing)
        t3 = clock::now();
    if (any_kinematic_)
        place_kinematic_bodies();
    const bool ok = check();
    if (timing) {
        t4 = clock::now();
        auto s = [](clock::time_point a, clock::time_point b) {
            return std::chrono::duration<double>(b - a).count();
        };
        timing->control_s = s(t0, t1);
        timing->collide_s = s(t1, t2);
        timing->solve_s = s(t2, t3);
        timing->check_s = s(t3, t4);
    }
    time_s_ += options_.step_s;
    ++steps_;
    if (ok)
        return StepResult::ok;
    ++divergences_;
    reset(target_pose());
    return StepResult::diverged;
}

// The kinematic bodies at their joints' targets, from the pelvis as it is
// (forward kinematics, CharacterModel::forward on those bodies only), at rest.
void Scene::place_kinematic_bodies()
{
    std::array<Eigen::Quaterniond, CharacterModel::kBodies> rotation;
    std::array<Eigen::Vector3d, CharacterModel::kBodies> origin;
    rotation[0] = to_eigen(dBodyGetQuaternion(body_[0]));
    origin[0] = to_eigen3(dBodyGetPosition(body_[0])) - rotation[0] * com_local_[0];
    for (int b = 1; b < CharacterModel::kBodies; ++b) {
        if (!kinematic_body_[b])
            continue;
        const BodySpec &spec = model_.bodies()[b];
        const int p = spec.parent; // the pelvis or a kinematic body
        origin[b] = origin[p] + rotation[p] * spec.offset_m;
        rotation[b] = rotation[p] * target_[b - 1];
        const Eigen::Vector3d c = origin[b] + rotation[b] * com_local_[b];
        dBodySetPosition(body_[b], c.x(), c.y(), c.z());
        dQuaternion q;
        to_ode(rotation[b], q);
        dBodySetQuaternion(body_[b], q);
    }
}

CharacterPose Scene::target_pose() const
{
    CharacterPose pose;
    const Eigen::Quaterniond q = to_eigen(dBodyGetQuaternion(body_[0]));
    const Eigen::Vector3d c = to_eigen3(dBodyGetPosition(body_[0]));
    pose.pelvis_rotation = q;
    pose.pelvis_position_m = c - q * com_local_[0];
    pose.local = target_;
    return pose;
}

void Scene::reset(const CharacterPose &pose_in)
{
    if (pose_in.local.size() != static_cast<size_t>(CharacterModel::kJoints))
        throw SimError("scene reset: pose must have 19 joint rotations");
    CharacterPose pose = pose_in;
    // The pelvis stays where it is welded.
    const Eigen::Quaterniond q0 = to_eigen(dBodyGetQuaternion(body_[0]));
    const Eigen::Vector3d c0 = to_eigen3(dBodyGetPosition(body_[0]));
    pose.pelvis_rotation = q0.coeffs().allFinite() ? q0 : Eigen::Quaterniond::Identity();
    pose.pelvis_position_m =
        c0.allFinite() ? Eigen::Vector3d(c0 - q0 * com_local_[0]) : Eigen::Vector3d::Zero();
    for (auto &q : pose.local)
        q.normalize();
    BodyFrames frames;
    model_.forward(pose, frames);
    for (int b = 0; b < CharacterModel::kBodies; ++b) {
        const Eigen::Vector3d p = frames.origin_m[b] + frames.rotation[b] * com_local_[b];
        dBodySetPosition(body_[b], p.x(), p.y(), p.z());
        dQuaternion q;
        to_ode(frames.rotation[b], q);
        dBodySetQuaternion(body_[b], q);
        dBodySetLinearVel(body_[b], 0, 0, 0);
        dBodySetAngularVel(body_[b], 0, 0, 0);
        dBodySetForce(body_[b], 0, 0, 0);
        dBodySetTorque(body_[b], 0, 0, 0);
    }
    for (int side = 0; side < 2; ++side) {
        dBodyID stick = stick_body_[side];
        if (!stick)
            continue;
        const int hb = model_.hand_body(static_cast<Side>(side));
        const Eigen::Vector3d p =
            frames.origin_m[hb] + frames.rotation[hb] * model_.stick(static_cast<Side>(side)).com_m;
        dBodySetPosition(stick, p.x(), p.y(), p.z());
        dQuaternion q;
        to_ode(frames.rotation[hb], q);
        dBodySetQuaternion(stick, q);
        dBodySetLinearVel(stick, 0, 0, 0);
        dBodySetAngularVel(stick, 0, 0, 0);
        dBodySetForce(stick, 0, 0, 0);
        dBodySetTorque(stick, 0, 0, 0);
    }
    dJointGroupEmpty(contacts_);
    drum_contact_ = {};
    weld_feedback_ = Feedback{};
    ball_feedback_ = {};
    part_touching_.fill(false); // the next contact is judged afresh
    part_through_.fill(false);
    part_edge_on_.fill(false);
}

void Scene::kick(int body, const Eigen::Vector3d &dv, const Eigen::Vector3d &dw)
{
    if (body < 0 || body >= CharacterModel::kBodies)
        throw SimError("kick: no body " + std::to_string(body));
    // ODE aborts (dDebug) on a NaN quaternion inside a step: refuse non-finite input here.
    if (!dv.allFinite() || !dw.allFinite())
        throw SimError("kick: velocity change must be finite");
    if (kinematic_body_[body])
        throw SimError("kick: body " + std::to_string(body) +
                       " is placed, not simulated (kinematic)");
    const Eigen::Vector3d v = to_eigen3(dBodyGetLinearVel(body_[body])) + dv;
    const Eigen::Vector3d w = to_eigen3(dBodyGetAngularVel(body_[body])) + dw;
    dBodySetLinearVel(body_[body], v.x(), v.y(), v.z());
    dBodySetAngularVel(body_[body], w.x(), w.y(), w.z());
}

} // namespace ictus
