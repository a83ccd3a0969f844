// The ODE scene: one owner for the world, space, contact group and bodies.
#include "ictus/sim/scene.hpp"
#include "ictus/base/rotation.hpp"

#include <ode/ode.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <utility>

namespace ictus
{

namespace
{

// dInitODE2 once per process, dCloseODE at exit (a function-local static is
// initialised once, thread-safely, and destroyed after main returns).
struct OdeLibrary {
    OdeLibrary() { dInitODE2(0); }
    ~OdeLibrary() { dCloseODE(); }
};
void ensure_ode()
{
    static OdeLibrary library;
    // Collision needs per-thread data; idempotent for a thread that has it.
    dAllocateODEDataForThread(dAllocateMaskAll);
}

constexpr unsigned long kDrumCategory = 1u;
constexpr unsigned long kStickCategory = 2u;
// A stick part's first contact with the drum is on the head when the contact
// normal's upward component exceeds this (the head's own normal: 1; the rim's
// edge met from above: > 0; the shell's side: 0, its bottom: -1).
constexpr double kHeadNormalMin = 0.2;

Eigen::Quaterniond to_eigen(const dReal *q)
{
    return Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
}
void to_ode(const Eigen::Quaterniond &q, dQuaternion out)
{
    out[0] = q.w();
    out[1] = q.x();
    out[2] = q.y();
    out[3] = q.z();
}
Eigen::Vector3d to_eigen3(const dReal *v)
{
    return Eigen::Vector3d(v[0], v[1], v[2]);
}

// A rotation taking ODE's local z axis (capsules, cylinders) onto `axis`.
Eigen::Quaterniond z_onto(const Eigen::Vector3d &axis)
{
    return Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), axis.normalized());
}

void set_rotation(dGeomID geom, const Eigen::Quaterniond &q, bool offset)
{
    const Eigen::Matrix3d r = q.toRotationMatrix();
    dMatrix3 m;
    for (int i = 0; i < 3; ++i) {
        for (int k = 0; k < 3; ++k)
            m[i * 4 + k] = r(i, k);
        m[i * 4 + 3] = 0.0;
    }
    if (offset)
        dGeomSetOffsetRotation(geom, m);
    else
        dGeomSetRotation(geom, m);
}

void check_finite_positive(const char *what, double v, double max = 1e300)
{
    if (!(std::isfinite(v) && v > 0.0 && v <= max)) {
        std::ostringstream s;
        s << what << ": expected a finite value in (0, " << max << "], got " << v;
        throw CharacterError(s.str());
    }
}

} // namespace

double DrumParams::stiffness_n_per_m(double tip_radius_m) const
{
    return 2.0 * M_PI * tension_n_per_m / std::log(radius_m / tip_radius_m);
}

void validate(const SceneOptions &o)
{
    check_finite_positive("physics step (s)", o.step_s, 0.05);
    if (o.quickstep_iterations < 1 || o.quickstep_iterations > 1000)
        throw CharacterError("QuickStep iterations: expected 1..1000, got " +
                             std::to_string(o.quickstep_iterations));
    if (!(o.quickstep_w > 0.0 && o.quickstep_w < 2.0))
        throw CharacterError("QuickStep over-relaxation: expected a value in (0, 2), got " +
                             std::to_string(o.quickstep_w));
    if (!(std::isfinite(o.gravity_mps2) && o.gravity_mps2 >= 0.0))
        throw CharacterError("gravity: expected a finite value >= 0");
    check_finite_positive("drum radius (m)", o.drum.radius_m, 5.0);
    check_finite_positive("drum shell depth (m)", o.drum.shell_depth_m, 5.0);
    check_finite_positive("drum tension (N/m)", o.drum.tension_n_per_m, 1e7);
    if (!(std::isfinite(o.drum.contact_damping_n_s_per_m) &&
          o.drum.contact_damping_n_s_per_m >= 0.0))
        throw CharacterError("drum contact damping: expected a finite value >= 0");
    if (!(std::isfinite(o.drum.friction) && o.drum.friction >= 0.0))
        throw CharacterError("drum friction: expected a finite value >= 0");
    if (!o.drum.center_m.allFinite())
        throw CharacterError("drum position: expected finite coordinates");
    check_finite_positive("divergence speed bound (m/s)", o.max_linear_speed_mps);
    check_finite_positive("divergence angular speed bound (rad/s)", o.max_angular_speed_rad_s);
    check_finite_positive("divergence joint separation bound (m)", o.max_joint_separation_m);
    if (!(std::isfinite(o.stop_margin_rad) && o.stop_margin_rad >= 0.0))
        throw CharacterError("limit stop margin: expected a finite value >= 0");
    if (!(o.stop_erp > 0.0 && o.stop_erp <= 1.0))
        throw CharacterError("limit stop ERP: expected a value in (0, 1]");
    if (!(std::isfinite(o.grip_damping_ratio) && o.grip_damping_ratio >= 0.0 &&
          o.grip_damping_ratio <= 10.0))
        throw CharacterError("grip damping ratio: expected 0..10");
    for (const GripSpring &g : o.grip) {
        check_finite_positive("grip stiffness (N m/rad)", g.stiffness_nm_per_rad, 1e6);
        if (!(std::isfinite(g.damping_nm_s_per_rad) && g.damping_nm_s_per_rad >= 0.0 &&
              g.damping_nm_s_per_rad <= 1e4))
            throw CharacterError("grip damping (N m s/rad): expected a finite value in [0, 1e4]");
    }
}

GripSpring grip_spring(double firmness, double stick_inertia_kg_m2, double damping_ratio)
{
    if (!(std::isfinite(damping_ratio) && damping_ratio >= 0.0 && damping_ratio <= 10.0))
        throw CharacterError("grip damping ratio: expected 0..10, got " +
                             std::to_string(damping_ratio));
    if (!(std::isfinite(firmness) && firmness >= 0.0 && firmness <= 1.0))
        throw CharacterError("grip firmness: expected 0..1, got " + std::to_string(firmness));
    if (!(std::isfinite(stick_inertia_kg_m2) && stick_inertia_kg_m2 > 0.0))
        throw CharacterError("grip firmness: the stick's inertia must be > 0");
    GripSpring g;
    g.stiffness_nm_per_rad = 2.0 * std::exp2(7.0 * firmness);
    g.damping_nm_s_per_rad =
        2.0 * damping_ratio * std::sqrt(g.stiffness_nm_per_rad * stick_inertia_kg_m2);
    return g;
}

Scene::Scene(const CharacterModel &model, const SceneOptions &options, const CharacterPose &initial,
             const std::vector<JointGains> &gains)
    : model_(model), options_(options)
{
    validate(options_);
    if (initial.local.size() != static_cast<size_t>(CharacterModel::kJoints))
        throw CharacterError("scene: initial pose must have 19 joint rotations");
    if (options_.drum.radius_m <= model_.options().stick.tip_radius_m)
        throw CharacterError("drum radius: must exceed the stick tip radius");
    set_gains(gains);
    ensure_ode();
    target_ = initial.local;
    target_rate_.assign(CharacterModel::kJoints, Eigen::Vector3d::Zero());
    motor_axes_world_.fill(false);
    build(initial);
}

Scene::~Scene()
{
    // Joints and bodies belong to the world, geoms to the space.
    if (contacts_)
        dJointGroupDestroy(contacts_);
    if (space_)
        dSpaceDestroy(space_);
    if (world_)
        dWorldDestroy(world_);
}

void Scene::set_gains(const std::vector<JointGains> &gains)
{
    if (gains.size() != static_cast<size_t>(CharacterModel::kJoints))
        throw CharacterError("gains: expected 19 joints, got " + std::to_string(gains.size()));
    for (size_t j = 0; j < gains.size(); ++j) {
        const std::string name = "gains of joint '" + model_.joint_name(static_cast<int>(j)) + "'";
        check_finite_positive((name + ": k_s").c_str(), gains[j].kp_nm_per_rad);
        check_finite_positive((name + ": k_d").c_str(), gains[j].kd_nm_s_per_rad);
        check_finite_positive((name + ": torque limit").c_str(), gains[j].torque_limit_nm);
    }
    gains_ = gains;
}

void Scene::set_joint_limits(const std::vector<JointLimitRef> &limits)
{
    if (!limits.empty() && limits.size() != static_cast<size_t>(CharacterModel::kJoints))
        throw CharacterError("joint limits: expected 19 joints, got " +
                             std::to_string(limits.size()));
    limits_ = limits;
}

void Scene::set_joint_targets(const std::vector<Eigen::Quaterniond> &local,
                              const std::vector<Eigen::Vector3d> &rate_parent)
{
    const size_t n = CharacterModel::kJoints;
    if (local.size() != n || rate_parent.size() != n)
        throw CharacterError("joint targets: expected 19 rotations and 19 rates");
    for (size_t j = 0; j < n; ++j) {
        Eigen::Quaterniond q = local[j];
        if (!q.coeffs().allFinite() || q.norm() < 1e-9 || !rate_parent[j].allFinite())
            throw CharacterError("joint targets: non-finite target for joint '" +
                                 model_.joint_name(static_cast<int>(j)) + "'");
        q.normalize();
        if (!limits_.empty() && limits_[j].active())
            q = limits_[j].clamp(q).normalized();
        target_[j] = q;
        target_rate_[j] = rate_parent[j];
    }
}

void Scene::build(const CharacterPose &initial)
{
    // QuickStep reorders its constraints with ODE's one global random
    // generator: seeded here, a scene steps the same whatever ran before it in
    // the process (a grip rebuild in `run`, the tests of one binary).
    dRandSetSeed(0);
    world_ = dWorldCreate();
    dWorldSetGravity(world_, 0.0, -options_.gravity_mps2, 0.0); // y up, as the mocap
    dWorldSetQuickStepNumIterations(world_, options_.quickstep_iterations);
    dWorldSetQuickStepW(world_, options_.quickstep_w);
    dWorldSetERP(world_, 0.2);
    dWorldSetCFM(world_, 1e-9);
    space_ = dSimpleSpaceCreate(nullptr); // a handful of geoms: brute force is cheapest
    contacts_ = dJointGroupCreate(0);

    BodyFrames frames;
    model_.forward(initial, frames);
    const bool fulcrum = options_.sticks == StickMount::fulcrum;
    for (int b = 0; b < CharacterModel::kBodies; ++b) {
        double m;
        Eigen::Vector3d c;
        Eigen::Matrix3d inertia;
        if (fulcrum) { // the sticks are bodies of their own
            const BodySpec &spec = model_.bodies()[b];
            m = spec.mass_kg;
            c = spec.com_m;
            inertia = spec.inertia_kg_m2;
        } else {
            model_.merged_mass(b, m, c, inertia);
        }
        com_local_[b] = c;
        dBodyID body = dBodyCreate(world_);
        dMass mass;
        // ODE wants the CoM at the body origin: the inertia is about c, in the
        // body (joint) frame, and the body is placed at the world CoM.
        dMassSetParameters(&mass, m, 0, 0, 0, inertia(0, 0), inertia(1, 1), inertia(2, 2),
                           inertia(0, 1), inertia(0, 2), inertia(1, 2));
        dBodySetMass(body, &mass);
        const Eigen::Vector3d p = frames.origin_m[b] + frames.rotation[b] * c;
        dBodySetPosition(body, p.x(), p.y(), p.z());
        dQuaternion q;
        to_ode(frames.rotation[b], q);
        dBodySetQuaternion(body, q);
        body_[b] = body;
    }
    if (options_.pelvis_kinematic) {
        // Infinite mass at rest: nothing moves it, and no rows hold it.
        pelvis_mass_kg_ = model_.bodies()[0].mass_kg;
        dBodySetKinematic(body_[0]);
        kinematic_body_[0] = true;
    } else {
        pelvis_weld_ = dJointCreateFixed(world_, nullptr);
        dJointAttach(pelvis_weld_, body_[0], nullptr);
        dJointSetFixed(pelvis_weld_);
    }

    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        const int child = j + 1;
        const int parent = model_.bodies()[child].parent;
        const Eigen::Vector3d anchor = frames.origin_m[child];
        ball_[j] = dJointCreateBall(world_, nullptr);
        dJointAttach(ball_[j], body_[child], body_[parent]);
        dJointSetBallAnchor(ball_[j], anchor.x(), anchor.y(), anchor.z());
        if (options_.pelvis_kinematic && parent == 0)
            dJointSetFeedback(ball_[j], reinterpret_cast<dJointFeedback *>(&ball_feedback_[j]));
        // Eq. 1 motor: body 1 = child so that the rows act on w_child - w_parent.
        motor_[j] = dJointCreateAMotor(world_, nullptr);
        dJointAttach(motor_[j], body_[child], body_[parent]);
        dJointSetAMotorMode(motor_[j], dAMotorUser);
        dJointSetAMotorNumAxes(motor_[j], 3);
        dJointSetFeedback(motor_[j], reinterpret_cast<dJointFeedback *>(&feedback_[j]));
    }
    if (options_.legs_kinematic) {
        // The pelvis's limbs that hold no stick: every body whose branch off
        // the pelvis carries neither hand. The pelvis is welded, so (up to
        // the weld's softness and the iterative solve's residual) their
        // joints' reactions end in the world: they move nothing that plays.
        // Disabled, with their joints, they drop out of ODE's island and its
        // solve; place_kinematic_bodies() puts them at their targets.
        std::array<int, CharacterModel::kBodies> branch{};
        for (int b = 1; b < CharacterModel::kBodies; ++b) {
            const int parent = model_.bodies()[b].parent;
            branch[b] = parent == 0 ? b : branch[parent]; // parents come first
        }
        std::array<bool, CharacterModel::kBodies> plays{};
        for (int side = 0; side < 2; ++side)
            plays[branch[model_.hand_body(static_cast<Side>(side))]] = true;
        for (int b = 1; b < CharacterModel::kBodies; ++b) {
            kinematic_body_[b] = !plays[branch[b]];
            if (!kinematic_body_[b])
                continue;
            any_kinematic_ = true;
            dJointDisable(ball_[b - 1]);
            dJointDisable(motor_[b - 1]);
            dBodyDisable(body_[b]);
        }
    }

    // Sticks: on a fulcrum, bodies of their own whose frame is the hand's at
    // the rest angle; rigid, geometry on the hand bodies (mass merged).
    const StickParams &sp = model_.options().stick;
    for (int side = 0; side < 2; ++side) {
        const int hb = model_.hand_body(static_cast<Side>(side));
        const StickInHand &st = model_.stick(static_cast<Side>(side));
        if (fulcrum) {
            dBodyID body = dBodyCreate(world_);
            const Eigen::Matrix3d &in = st.inertia_kg_m2;
            dMass mass;
            dMassSetParameters(&mass, sp.mass_kg, 0, 0, 0, in(0, 0), in(1, 1), in(2, 2), in(0, 1),
                               in(0, 2), in(1, 2));
            dBodySetMass(body, &mass);
            const Eigen::Vector3d p = frames.origin_m[hb] + frames.rotation[hb] * st.com_m;
            dBodySetPosition(body, p.x(), p.y(), p.z());
            dQuaternion q;
            to_ode(frames.rotation[hb], q);
            dBodySetQuaternion(body, q);
            stick_body_[side] = body;
            const Eigen::Vector3d anchor = frames.origin_m[hb] + frames.rotation[hb] * st.grip_m;
            const Eigen::Vector3d axis = frames.rotation[hb] * st.fulcrum_axis;
            fulcrum_[side] = dJointCreateHinge(world_, nullptr);
            dJointAttach(fulcrum_[side], body, body_[hb]);
            dJointSetHingeAnchor(fulcrum_[side], anchor.x(), anchor.y(), anchor.z());
            dJointSetHingeAxis(fulcrum_[side], axis.x(), axis.y(), axis.z());
            apply_grip(side);
        }
        const Eigen::Vector3d origin = fulcrum ? st.com_m : com_local_[hb];
        const double tip_r = sp.tip_radius_m;
        const Eigen::Vector3d tip_centre = st.tip_m - tip_r * st.axis;
        const double shaft_len =
            std::max((tip_centre - st.butt_m).norm() - 2.0 * sp.shaft_radius_m, 1e-3);
        stick_shaft_[side] = dCreateCapsule(space_, sp.shaft_radius_m, shaft_len);
        stick_tip_[side] = dCreateSphere(space_, tip_r);
        for (dGeomID g : {stick_shaft_[side], stick_tip_[side]}) {
            dGeomSetBody(g, fulcrum ? stick_body_[side] : body_[hb]);
            dGeomSetCategoryBits(g, kStickCategory);
            dGeomSetCollideBits(g, kDrumCategory);
        }
        const Eigen::Vector3d shaft_mid = 0.5 * (st.butt_m + tip_centre) - origin;
        dGeomSetOffsetPosition(stick_shaft_[side], shaft_mid.x(), shaft_mid.y(), shaft_mid.z());
        set_rotation(stick_shaft_[side], z_onto(st.axis), true);
        const Eigen::Vector3d tip_off = tip_centre - origin;
        dGeomSetOffsetPosition(stick_tip_[side], tip_off.x(), tip_off.y(), tip_off.z());
    }

    // Drum: a static cylinder whose top face is the membrane.
    drum_ = dCreateCylinder(space_, options_.drum.radius_m, options_.drum.shell_depth_m);
    dGeomSetCategoryBits(drum_, kDrumCategory);
    dGeomSetCollideBits(drum_, kStickCategory);
    place_drum();

    static_assert(sizeof(Feedback) == sizeof(dJointFeedback), "feedback layout");
    if (pelvis_weld_)
        dJointSetFeedback(pelvis_weld_, reinterpret_cast<dJointFeedback *>(&weld_feedback_));
}

void Scene::place_drum()
{
    const DrumParams &drum = options_.drum;
    dGeomCylinderSetParams(drum_, drum.radius_m, drum.shell_depth_m);
    const Eigen::Vector3d c = drum.center_m - Eigen::Vector3d(0, 0.5 * drum.shell_depth_m, 0);
    dGeomSetPosition(drum_, c.x(), c.y(), c.z());
    set_rotation(drum_, z_onto(Eigen::Vector3d::UnitY()), false);

    // Soft contact from the membrane's spring-damper, the implicit step's
    // numerical damping taken back out by default (soft_contact()).
    const SoftContact sc = soft_contact(options_.step_s, drum_contact_stiffness_n_per_m(),
                                        drum.contact_damping_n_s_per_m,
                                        options_.contact_numerical_damping_compensated);
    contact_erp_ = sc.erp;
    contact_cfm_ = sc.cfm;
}

// ERP = h k / (h k + c), CFM = 1 / (h k + c) is the implicit (backward)
// Euler step of the spring-damper, which dissipates by itself: the
// determinant of its step is 1 / (1 + h c / m + h^2 k / m), an extra damping
// of h k (5.8 N s/m on the default head at 1 ms, more than the head's own 3:
// a stick bounced off at a restitution of 0.12-0.26). Compensated, the
// contact gets c - h k, so that the determinant is 1 / (1 + h c / m), the
// physical damper's alone (h k + c - h k = c). An undamped head (c = 0) keeps
// 5 % of the numerical damping so that the CFM stays finite.
SoftContact soft_contact(double h, double k, double c, bool compensated)
{
    const double cd = compensated ? std::max(c - h * k, -0.95 * h * k) : c;
    return {h * k / (h * k + cd), 1.0 / (h * k + cd)};
}

double Scene::drum_contact_stiffness_n_per_m() const
{
    return options_.drum.stiffness_n_per_m(model_.options().stick.tip_radius_m);
}

void Scene::set_drum(const DrumParams &drum)
{
    SceneOptions candidate = options_;
    candidate.drum = drum;
    validate(candidate); // throws naming the value; nothing changed yet
    if (drum.radius_m <= model_.options().stick.tip_radius_m)
        throw CharacterError("drum radius: must exceed the stick tip radius");
    options_.drum = drum;
    place_drum();
}

// The grip's spring-damper as the fulcrum's soft stop at 0 rad: with lo ==
// hi ODE makes the stop row two-sided, and its ERP / CFM from k and c (ODE
// manual: ERP = h k / (h k + c), CFM = 1 / (h k + c)) make it the implicit
// spring-damper torque -k theta - c theta', stable at any stiffness.
void Scene::apply_grip(int side)
{
    if (!fulcrum_[side])
        return;
    const GripSpring &g = options_.grip[side];
    const double h = options_.step_s;
    const double hk = h * g.stiffness_nm_per_rad;
    dJointSetHingeParam(fulcrum_[side], dParamLoStop, 0.0);
    dJointSetHingeParam(fulcrum_[side], dParamHiStop, 0.0);
    dJointSetHingeParam(fulcrum_[side], dParamStopERP, hk / (hk + g.damping_nm_s_per_rad));
    dJointSetHingeParam(fulcrum_[side], dParamStopCFM, 1.0 / (hk + g.damping_nm_s_per_rad));
    dJointSetHingeParam(fulcrum_[side], dParamBounce, 0.0);
}

void Scene::set_grip(Side side, const GripSpring &grip)
{
    SceneOptions candidate = options_;
    candidate.grip[static_cast<int>(side)] = grip;
    validate(candidate);
    options_.grip[static_cast<int>(side)] = grip;
    apply_grip(static_cast<int>(side));
}

double Scene::fulcrum_inertia_kg_m2(Side side) const
{
    const StickInHand &st = model_.stick(side);
    const Eigen::Vector3d &a = st.fulcrum_axis;
    const double d = a.cross(st.com_m - st.grip_m).norm();
    return a.dot(st.inertia_kg_m2 * a) + model_.options().stick.mass_kg * d * d;
}

void Scene::set_grip_firmness(Side side, double firmness)
{
    // A looser hold touches the stick with less of the hand: below the
    // default firmness the damping ratio falls in proportion.
    const double ratio =
        options_.grip_damping_ratio * std::min(1.0, std::max(firmness, 0.0) / kDefaultGripFirmness);
    set_grip(side, grip_spring(firmness, fulcrum_inertia_kg_m2(side), ratio));
}

void Scene::near_callback(void *data, dGeomID a, dGeomID b)
{
    Scene *self = static_cast<Scene *>(data);
    // Only sticks meet the drum (category bits). The stick's geom goes first,
    // so that its body is the contact joint's body 1 and the joint feedback's
    // f1 is the force on the stick (the normal then points into the stick).
    if (a == self->drum_)
        std::swap(a, b);
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
    const int part = 2 * side + (bead ? 1 : 0);
    self->part_touching_now_[static_cast<size_t>(part)] = true;
    if (!self->part_touching_[static_cast<size_t>(part)]) {
        int deepest = 0;
        for (int i = 1; i < n; ++i)
            if (geoms[i].depth > geoms[deepest].depth)
                deepest = i;
        // The normal points into the stick: up (the drum's axis, +y) on the
        // head, outward and up on the rim's edge, level on the shell's side.
        const bool from_above = geoms[deepest].normal[1] > kHeadNormalMin;
        self->part_through_[static_cast<size_t>(part)] = !from_above;
        if (!from_above)
            ++self->shell_passes_;
    }
    if (self->part_through_[static_cast<size_t>(part)])
        return;
    for (int i = 0; i < n; ++i) {
        dContact contact;
        contact.geom = geoms[i];
        contact.surface.mode = dContactSoftERP | dContactSoftCFM | dContactApprox1;
        contact.surface.mu = self->options_.drum.friction;
        contact.surface.soft_erp = self->contact_erp_;
        contact.surface.soft_cfm = self->contact_cfm_;
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
        dJointID m = motor_[j];

        // Safety net: a joint outside its limit region by more than the
        // margin meets a one-sided stop along the direction of the violation.
        bool stop = false;
        double violation = 0.0, stop_at = options_.stop_margin_rad;
        Eigen::Vector3d stop_axis = Eigen::Vector3d::UnitX();
        if (options_.limit_stops && !limits_.empty() && limits_[j].active()) {
            const Eigen::Quaterniond current = qp.conjugate() * qc;
            // The joint's present rate (child relative to parent, world).
            auto relative_rate = [&] {
                return Eigen::Vector3d(to_eigen3(dBodyGetAngularVel(body_[child])) -
                                       to_eigen3(dBodyGetAngularVel(body_[parent])));
            };
            const Eigen::Quaterniond inside = limits_[j].clamp(current);
            // A joint the clamp leaves where it is (every limit returns
            // q.normalized() inside) has no violation: the rotation between
            // the two would be rounding, and its direction a random stop axis
            // that the look-ahead below engaged on fast joints (1 deg margin,
            // > 17 rad/s: 6 of the default score's 24 stops, measured).
            const bool outside = !(inside.coeffs() == current.normalized().coeffs());
            const Eigen::Vector3d v =
                outside ? log_map(current * inside.conjugate()) : Eigen::Vector3d::Zero();
            violation = v.norm();
            if (violation > 0.0) {
                // The stop engages one step early: when the joint would be
                // past the margin after this step at its present rate, so a
                // fast joint does not run past it before the stop row
                // exists. Inelastic (SceneOptions::stop_inelastic): past the
                // margin the row takes the joint back to it (at the stop
                // ERP); short of it, the row holds the joint where it is for
                // this step (the stop set at the present angle). Else the
                // row sees the predicted angle.
                const Eigen::Vector3d axis = (qp * v) / violation;
                const Eigen::Vector3d w_rel = relative_rate();
                const double rate = options_.stop_inelastic
                                        ? std::max(w_rel.dot(axis), cmd.velocity_world.dot(axis))
                                        : w_rel.dot(axis);
                const double predicted = violation + std::max(0.0, rate) * options_.step_s;
                if (predicted > options_.stop_margin_rad) {
                    stop = true;
                    stop_axis = axis;
                    if (options_.stop_inelastic)
                        stop_at = std::min(options_.stop_margin_rad, violation);
                    else
                        violation = predicted;
                }
            } else if (options_.stop_inelastic) {
                // Inside its region a joint fast enough to cross the margin
                // within the step (rate h > margin) would pass it before a
                // stop row exists: a whipping elbow went 2.3 deg past its
                // range in one step (1 ms at 40 rad/s). Its rotation after
                // the step at the present rate is tested instead; past the
                // margin, the row holds it where it is along the predicted
                // violation for this step (as a joint short of the margin).
                const Eigen::Vector3d w_now = relative_rate();
                const Eigen::Vector3d &w_rel =
                    cmd.velocity_world.squaredNorm() > w_now.squaredNorm() ? cmd.velocity_world
                                                                           : w_now;
                const double turn = w_rel.norm() * options_.step_s;
                if (turn > options_.stop_margin_rad) {
                    const Eigen::Vector3d w_parent = qp.conjugate() * w_rel;
                    const Eigen::Quaterniond next =
                        Eigen::Quaterniond(Eigen::AngleAxisd(turn, w_parent.normalized())) *
                        current.normalized();
                    const Eigen::Quaterniond next_inside = limits_[j].clamp(next);
                    if (!(next_inside.coeffs() == next.normalized().coeffs())) {
                        const Eigen::Vector3d vn = log_map(next * next_inside.conjugate());
                        const double ahead = vn.norm();
                        if (ahead > options_.stop_margin_rad) {
                            stop = true;
                            stop_axis = (qp * vn) / ahead;
                            stop_at = 0.0; // violation is 0: held where it is
                        }
                    }
                }
            }
        }
        // Score mode's stop (inelastic) also holds the joint's other two axes
        // for the step: the range is not convex, so moving across the stop's
        // axis took joints further out (an elbow held on its stop axis went
        // from 0 to 2.4 and 4.4 deg out in two steps, random seed 2080).
        const bool lock = stop && options_.stop_inelastic;
        Eigen::Vector3d axes[3];
        if (stop) {
            axes[0] = stop_axis;
            axes[1] = stop_axis.unitOrthogonal();
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
        // Only what changed goes to ODE (the CFM and force limits change with
        // the gains and the stops, the velocities every step).
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
            dJointSetAMotorAngle(m, 0, violation);
            dJointSetAMotorParam(m, dParamLoStop1, -dInfinity);
            dJointSetAMotorParam(m, dParamHiStop1, stop_at);
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
    for (size_t p = 0; p < part_through_.size(); ++p)
        part_through_[p] = part_through_[p] && part_touching_[p]; // clear of the drum
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
        throw CharacterError("scene reset: pose must have 19 joint rotations");
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
}

void Scene::body_frames(BodyFrames &frames) const
{
    frames.origin_m.resize(CharacterModel::kBodies);
    frames.rotation.resize(CharacterModel::kBodies);
    for (int b = 0; b < CharacterModel::kBodies; ++b) {
        const Eigen::Quaterniond q = to_eigen(dBodyGetQuaternion(body_[b]));
        frames.rotation[b] = q;
        frames.origin_m[b] = to_eigen3(dBodyGetPosition(body_[b])) - q * com_local_[b];
    }
}

void Scene::local_rotations(std::vector<Eigen::Quaterniond> &local) const
{
    local.resize(CharacterModel::kJoints);
    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        const int child = j + 1;
        const int parent = model_.bodies()[child].parent;
        local[j] = to_eigen(dBodyGetQuaternion(body_[parent])).conjugate() *
                   to_eigen(dBodyGetQuaternion(body_[child]));
    }
}

dBodyID Scene::tip_body(Side side) const
{
    dBodyID stick = stick_body_[static_cast<int>(side)];
    return stick ? stick : body_[model_.hand_body(side)];
}

Eigen::Vector3d Scene::tip_body_com(Side side) const
{
    return stick_body_[static_cast<int>(side)] ? model_.stick(side).com_m
                                               : com_local_[model_.hand_body(side)];
}

namespace
{
// A point fixed in a body, given in the hand frame (`rel`: relative to the
// body's CoM), and its velocity.
Eigen::Vector3d point_of(dBodyID body, const Eigen::Vector3d &rel)
{
    dVector3 out;
    dBodyGetRelPointPos(body, rel.x(), rel.y(), rel.z(), out);
    return to_eigen3(out);
}
Eigen::Vector3d velocity_of(dBodyID body, const Eigen::Vector3d &rel)
{
    dVector3 out;
    dBodyGetRelPointVel(body, rel.x(), rel.y(), rel.z(), out);
    return to_eigen3(out);
}
} // namespace

Eigen::Vector3d Scene::tip_position(Side side) const
{
    return point_of(tip_body(side), model_.stick(side).tip_m - tip_body_com(side));
}

Eigen::Vector3d Scene::tip_velocity(Side side) const
{
    return velocity_of(tip_body(side), model_.stick(side).tip_m - tip_body_com(side));
}

// The bead's centre (the tip minus one bead radius along the stick), relative
// to the tip body's centre of mass, in its frame: what ODE's point queries take.
Eigen::Vector3d Scene::bead_rel_com(Side side) const
{
    const StickInHand &st = model_.stick(side);
    return st.tip_m - model_.options().stick.tip_radius_m * st.axis - tip_body_com(side);
}

Eigen::Vector3d Scene::bead_position(Side side) const
{
    return point_of(tip_body(side), bead_rel_com(side));
}

Eigen::Vector3d Scene::bead_velocity(Side side) const
{
    return velocity_of(tip_body(side), bead_rel_com(side));
}

Eigen::Vector3d Scene::held_tip_position(Side side) const
{
    const int hb = model_.hand_body(side);
    return point_of(body_[hb], model_.stick(side).tip_m - com_local_[hb]);
}

Eigen::Vector3d Scene::held_tip_velocity(Side side) const
{
    const int hb = model_.hand_body(side);
    return velocity_of(body_[hb], model_.stick(side).tip_m - com_local_[hb]);
}

Eigen::Vector3d Scene::held_bead_position(Side side) const
{
    const int hb = model_.hand_body(side);
    const StickInHand &st = model_.stick(side);
    return point_of(body_[hb],
                    st.tip_m - model_.options().stick.tip_radius_m * st.axis - com_local_[hb]);
}

double Scene::fulcrum_angle_rad(Side side) const
{
    dJointID f = fulcrum_[static_cast<int>(side)];
    return f ? dJointGetHingeAngle(f) : 0.0;
}

Eigen::Quaterniond Scene::stick_in_hand(Side side) const
{
    const Eigen::Quaterniond hand = to_eigen(dBodyGetQuaternion(body_[model_.hand_body(side)]));
    return (hand.conjugate() * to_eigen(dBodyGetQuaternion(tip_body(side)))).normalized();
}

Eigen::Vector3d Scene::fulcrum_axis(Side side) const
{
    const Eigen::Quaterniond q = to_eigen(dBodyGetQuaternion(body_[model_.hand_body(side)]));
    return q * model_.stick(side).fulcrum_axis;
}

Eigen::Vector3d Scene::stick_axis(Side side) const
{
    return to_eigen(dBodyGetQuaternion(tip_body(side))) * model_.stick(side).axis;
}

double Scene::fulcrum_rate_rad_s(Side side) const
{
    dJointID f = fulcrum_[static_cast<int>(side)];
    return f ? dJointGetHingeAngleRate(f) : 0.0;
}

namespace
{
// The inverse of the effective mass at a point p along n of a set of rigid
// bodies whose velocities are J u for the generalised velocities u:
// n^T G (J^T M J)^-1 G^T n, G the point's velocity row in u.
// Fixed sizes: it runs on run's physics thread, which does not allocate.
template <int Bodies, int Dofs>
double inverse_effective_mass(const Eigen::Matrix<double, Bodies, Dofs> &J,
                              const Eigen::Matrix<double, Bodies, Bodies> &M,
                              const Eigen::Matrix<double, 1, Dofs> &g)
{
    const Eigen::Matrix<double, Dofs, Dofs> Mu = J.transpose() * M * J;
    return g * Mu.ldlt().solve(g.transpose());
}

Eigen::Matrix3d skew(const Eigen::Vector3d &v)
{
    Eigen::Matrix3d m;
    m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
    return m;
}

// A body's world mass matrix (diag m, world inertia about its CoM).
void body_mass(dBodyID body, Eigen::Matrix<double, 6, 6> &out)
{
    dMass mass;
    dBodyGetMass(body, &mass);
    Eigen::Matrix3d local;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k)
            local(i, k) = mass.I[i * 4 + k];
    const Eigen::Matrix3d r = to_eigen(dBodyGetQuaternion(body)).toRotationMatrix();
    out.setZero();
    out.topLeftCorner<3, 3>() = mass.mass * Eigen::Matrix3d::Identity();
    out.bottomRightCorner<3, 3>() = r * local * r.transpose();
}
} // namespace

double Scene::effective_mass_kg(Side side, const Eigen::Vector3d &normal_in) const
{
    const Eigen::Vector3d n = normal_in.normalized();
    const int s = static_cast<int>(side);
    dBodyID hand = body_[model_.hand_body(side)];
    const Eigen::Vector3d ch = to_eigen3(dBodyGetPosition(hand));
    const Eigen::Vector3d bead = bead_position(side);
    Eigen::Matrix<double, 6, 6> mh;
    body_mass(hand, mh);
    if (!stick_body_[s]) {
        // One body: 1/m + (r x n)^T I^-1 (r x n).
        // n . (v + w x r) = n . v + w . (r x n).
        Eigen::Matrix<double, 1, 6> g;
        g << n.transpose(), (bead - ch).cross(n).transpose();
        return 1.0 / inverse_effective_mass<6, 6>(Eigen::Matrix<double, 6, 6>::Identity(), mh, g);
    }
    dBodyID stick = stick_body_[s];
    const Eigen::Vector3d cs = to_eigen3(dBodyGetPosition(stick));
    dVector3 anchor, axis;
    dJointGetHingeAnchor(fulcrum_[s], anchor);
    dJointGetHingeAxis(fulcrum_[s], axis);
    const Eigen::Vector3d p = to_eigen3(anchor), a = to_eigen3(axis).normalized();
    Eigen::Matrix<double, 6, 6> ms;
    body_mass(stick, ms);
    Eigen::Matrix<double, 12, 12> M = Eigen::Matrix<double, 12, 12>::Zero();
    M.topLeftCorner<6, 6>() = mh;
    M.bottomRightCorner<6, 6>() = ms;
    // u = (v_h, w_h, theta'): the hand's twist and the fulcrum's rate.
    // Stick: w_s = w_h + a theta'; v_s = v_h + w_h x (c_s - c_h) + theta' a x (c_s - p).
    Eigen::Matrix<double, 12, 7> J = Eigen::Matrix<double, 12, 7>::Zero();
    J.block<3, 3>(0, 0).setIdentity();
    J.block<3, 3>(3, 3).setIdentity();
    J.block<3, 3>(6, 0).setIdentity();
    J.block<3, 3>(6, 3) = -skew(cs - ch);
    J.block<3, 1>(6, 6) = a.cross(cs - p);
    J.block<3, 3>(9, 3).setIdentity();
    J.block<3, 1>(9, 6) = a;
    // The bead moves with the stick: n . (v_s + w_s x (b - c_s)).
    Eigen::Matrix<double, 1, 6> gs;
    gs << n.transpose(), (bead - cs).cross(n).transpose();
    const Eigen::Matrix<double, 1, 7> g = gs * J.bottomRows<6>();
    const double m_pivot = 1.0 / inverse_effective_mass<12, 7>(J, M, g);
    // The stick welded to the hand: theta' = 0.
    const Eigen::Matrix<double, 12, 6> J_rigid = J.leftCols<6>();
    const Eigen::Matrix<double, 1, 6> g_rigid = g.head<6>();
    const double m_rigid = 1.0 / inverse_effective_mass<12, 6>(J_rigid, M, g_rigid);
    const double lever = a.cross(bead - p).norm();
    const double k_grip = options_.grip[s].stiffness_nm_per_rad / std::max(lever * lever, 1e-6);
    const double k_drum = drum_contact_stiffness_n_per_m();
    const double w = k_grip / (k_grip + k_drum);
    return m_pivot + w * (m_rigid - m_pivot);
}

Eigen::Vector3d Scene::support_force_n() const
{
    if (pelvis_weld_)
        return to_eigen3(weld_feedback_.f1);
    // The pelvis at rest: support + weight + its joints' forces on it = 0.
    Eigen::Vector3d f(0.0, options_.gravity_mps2 * pelvis_mass_kg_, 0.0);
    for (int j = 0; j < CharacterModel::kJoints; ++j)
        if (model_.bodies()[j + 1].parent == 0 && !kinematic_body_[j + 1])
            f -= to_eigen3(ball_feedback_[j].f2);
    return f;
}

Eigen::Vector3d Scene::motor_torque(int joint) const
{
    return to_eigen3(feedback_.at(joint).t1);
}

bool Scene::motor_saturated(int joint) const
{
    const Eigen::Vector3d t = motor_torque(joint);
    const double limit = gains_[joint].torque_limit_nm;
    for (int i = 0; i < 3; ++i)
        if (std::fabs(t.dot(motor_axes_[joint][i])) >= 0.999 * limit)
            return true;
    return false;
}

// One square root for the largest: sqrt is monotone and correctly rounded, so
// sqrt(max |v|^2) is max sqrt(|v|^2) = max |v| (Eigen's norm()) bit for bit.
double Scene::max_linear_speed_mps() const
{
    double m2 = 0.0;
    for (dBodyID b : body_)
        m2 = std::max(m2, to_eigen3(dBodyGetLinearVel(b)).squaredNorm());
    return std::sqrt(m2);
}

double Scene::max_angular_speed_rad_s() const
{
    double m2 = 0.0;
    for (dBodyID b : body_)
        m2 = std::max(m2, to_eigen3(dBodyGetAngularVel(b)).squaredNorm());
    return std::sqrt(m2);
}

void Scene::kick(int body, const Eigen::Vector3d &dv, const Eigen::Vector3d &dw)
{
    if (body < 0 || body >= CharacterModel::kBodies)
        throw CharacterError("kick: no body " + std::to_string(body));
    // ODE aborts (dDebug) on a NaN quaternion inside a step: refuse non-finite input here.
    if (!dv.allFinite() || !dw.allFinite())
        throw CharacterError("kick: velocity change must be finite");
    if (kinematic_body_[body])
        throw CharacterError("kick: body " + std::to_string(body) +
                             " is placed, not simulated (kinematic)");
    const Eigen::Vector3d v = to_eigen3(dBodyGetLinearVel(body_[body])) + dv;
    const Eigen::Vector3d w = to_eigen3(dBodyGetAngularVel(body_[body])) + dw;
    dBodySetLinearVel(body_[body], v.x(), v.y(), v.z());
    dBodySetAngularVel(body_[body], w.x(), w.y(), w.z());
}

} // namespace ictus
