// Building the ODE scene: the world, the character's bodies and joints, the
// sticks and the drum, and the parameters changed on a live scene (drum,
// grip). Stepping is in scene_step.cpp, the state read back in scene_state.cpp.
#include "ictus/sim/scene.hpp"
#include "scene_ode.hpp"
#include "stick_tip.h"

#include <ode/ode.h>

#include <cmath>
#include <sstream>

namespace ictus
{

namespace
{

using ode::to_ode;

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
        throw SimError(s.str());
    }
}

} // namespace

double DrumParams::stiffness_n_per_m(double tip_radius_m) const
{
    // A plate: a centrally loaded clamped disc's point stiffness, 16 pi D / R^2
    // (S. Timoshenko, S. Woinowsky-Krieger, Theory of Plates and Shells, 1959, sec. 19).
    if (plate_bending_n_m > 0.0)
        return 16.0 * M_PI * plate_bending_n_m / (radius_m * radius_m);
    return 2.0 * M_PI * tension_n_per_m / std::log(radius_m / tip_radius_m);
}

double DrumParams::stretch_n_per_m3() const
{
    if (plate_bending_n_m > 0.0)
        return 0.0; // a plate bends; it does not stretch as a film does
    return stick_tip_head_k3(head_young_pa, head_poisson, head_thickness_m, radius_m);
}

bool is_stick_tip(const std::string &name)
{
    return stick_tip_find(name.c_str()) != nullptr;
}

namespace
{
void validate_drum(const DrumParams &d, const std::string &which)
{
    check_finite_positive((which + " radius (m)").c_str(), d.radius_m, 5.0);
    check_finite_positive((which + " shell depth (m)").c_str(), d.shell_depth_m, 5.0);
    if (d.plate_bending_n_m > 0.0)
        check_finite_positive((which + " bending stiffness (N m)").c_str(), d.plate_bending_n_m,
                              1e4);
    else
        check_finite_positive((which + " tension (N/m)").c_str(), d.tension_n_per_m, 1e7);
    if (!(std::isfinite(d.contact_damping_n_s_per_m) && d.contact_damping_n_s_per_m >= 0.0))
        throw SimError(which + " contact damping: expected a finite value >= 0");
    if (!(std::isfinite(d.friction) && d.friction >= 0.0))
        throw SimError(which + " friction: expected a finite value >= 0");
    if (!d.center_m.allFinite())
        throw SimError(which + " position: expected finite coordinates");
}
} // namespace

void validate(const SceneOptions &o)
{
    check_finite_positive("physics step (s)", o.step_s, 0.05);
    if (o.quickstep_iterations < 1 || o.quickstep_iterations > 1000)
        throw SimError("QuickStep iterations: expected 1..1000, got " +
                       std::to_string(o.quickstep_iterations));
    if (!(o.quickstep_w > 0.0 && o.quickstep_w < 2.0))
        throw SimError("QuickStep over-relaxation: expected a value in (0, 2), got " +
                       std::to_string(o.quickstep_w));
    if (!(std::isfinite(o.gravity_mps2) && o.gravity_mps2 >= 0.0))
        throw SimError("gravity: expected a finite value >= 0");
    validate_drum(o.drum, "drum");
    if (o.extra_drums.size() + 1 > static_cast<size_t>(kMaxDrums))
        throw SimError("kit: at most " + std::to_string(kMaxDrums) + " drums, got " +
                       std::to_string(o.extra_drums.size() + 1));
    for (size_t i = 0; i < o.extra_drums.size(); ++i)
        validate_drum(o.extra_drums[i], "drum " + std::to_string(i + 1));
    if (!o.drum.stick_tip.empty() && !stick_tip_find(o.drum.stick_tip.c_str()))
        throw SimError("stick tip: expected wood, nylon or felt, got '" + o.drum.stick_tip + "'");
    check_finite_positive("divergence speed bound (m/s)", o.max_linear_speed_mps);
    check_finite_positive("divergence angular speed bound (rad/s)", o.max_angular_speed_rad_s);
    check_finite_positive("divergence joint separation bound (m)", o.max_joint_separation_m);
    if (!(std::isfinite(o.stop_margin_rad) && o.stop_margin_rad >= 0.0))
        throw SimError("limit stop margin: expected a finite value >= 0");
    if (!(o.stop_erp > 0.0 && o.stop_erp <= 1.0))
        throw SimError("limit stop ERP: expected a value in (0, 1]");
    if (!(std::isfinite(o.grip_damping_ratio) && o.grip_damping_ratio >= 0.0 &&
          o.grip_damping_ratio <= 10.0))
        throw SimError("grip damping ratio: expected 0..10");
    for (const GripSpring &g : o.grip) {
        check_finite_positive("grip stiffness (N m/rad)", g.stiffness_nm_per_rad, 1e6);
        if (!(std::isfinite(g.damping_nm_s_per_rad) && g.damping_nm_s_per_rad >= 0.0 &&
              g.damping_nm_s_per_rad <= 1e4))
            throw SimError("grip damping (N m s/rad): expected a finite value in [0, 1e4]");
    }
}

GripSpring grip_spring(double firmness, double stick_inertia_kg_m2, double damping_ratio)
{
    if (!(std::isfinite(damping_ratio) && damping_ratio >= 0.0 && damping_ratio <= 10.0))
        throw SimError("grip damping ratio: expected 0..10, got " + std::to_string(damping_ratio));
    if (!(std::isfinite(firmness) && firmness >= 0.0 && firmness <= 1.0))
        throw SimError("grip firmness: expected 0..1, got " + std::to_string(firmness));
    if (!(std::isfinite(stick_inertia_kg_m2) && stick_inertia_kg_m2 > 0.0))
        throw SimError("grip firmness: the stick's inertia must be > 0");
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
        throw SimError("scene: initial pose must have 19 joint rotations");
    for (int i = 0; i < drum_count(); ++i)
        if (drum(i).radius_m <= model_.options().stick.tip_radius_m)
            throw SimError("drum " + std::to_string(i) +
                           " radius: must exceed the stick tip radius");
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
        throw SimError("gains: expected 19 joints, got " + std::to_string(gains.size()));
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
        throw SimError("joint limits: expected 19 joints, got " + std::to_string(limits.size()));
    limits_ = limits;
}

// The scene in the order ODE gets it (the order decides QuickStep's, so it
// is part of the results): world, bodies, joints, sticks, drum.
void Scene::build(const CharacterPose &initial)
{
    create_world();
    BodyFrames frames;
    model_.forward(initial, frames);
    create_bodies(frames);
    create_joints(frames);
    if (options_.legs_kinematic)
        make_legs_kinematic();
    for (int side = 0; side < 2; ++side)
        create_stick(side, frames);
    create_drum();
}

void Scene::create_world()
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
}

void Scene::create_bodies(const BodyFrames &frames)
{
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
}

void Scene::create_joints(const BodyFrames &frames)
{
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
}

// The pelvis's limbs that hold no stick: every body whose branch off the
// pelvis carries neither hand. The pelvis is welded, so (up to the weld's
// softness and the iterative solve's residual) their joints' reactions end in
// the world: they move nothing that plays. Disabled, with their joints, they
// drop out of ODE's island and its solve; place_kinematic_bodies() puts them
// at their targets.
void Scene::make_legs_kinematic()
{
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

// A stick: on a fulcrum, a body of its own whose frame is the hand's at the
// rest angle; rigid, geometry on the hand body (mass merged).
void Scene::create_stick(int side, const BodyFrames &frames)
{
    const bool fulcrum = options_.sticks == StickMount::fulcrum;
    const StickParams &sp = model_.options().stick;
    const int hb = model_.hand_body(static_cast<Side>(side));
    const StickInHand &st = model_.stick(static_cast<Side>(side));
    if (fulcrum) {
        dBodyID body = dBodyCreate(world_);
        // The stick's roll about its own axis is the hand's (the hinge allows
        // none), but its own inertia there, m r^2 / 2 = 1.3e-6 kg m^2, is 1/380
        // of the hand's (5e-4): QuickStep's iterations do not hold the hinge's row
        // about that axis against a torque on it (the friction at a shaft
        // pressed on a head, 7 mm off the axis), and the stick's roll rate
        // flips sign every step, growing to the divergence bound (400 rad/s).
        // kStickRollInertia_kg_m2 (the fingers closed round the stick, which
        // roll with it) conditions that row (docs/character.md, "The fulcrum").
        Eigen::Matrix3d in = st.inertia_kg_m2;
        in += kStickRollInertia_kg_m2 * st.axis * st.axis.transpose();
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

// Drums: each a static cylinder whose top face is the membrane; drum 0
// first, a kit's others after it.
void Scene::create_drum()
{
    for (int i = 0; i < drum_count(); ++i) {
        const DrumParams &d = drum(i);
        drum_geom_[i] = dCreateCylinder(space_, d.radius_m, d.shell_depth_m);
        dGeomSetCategoryBits(drum_geom_[i], kDrumCategory);
        dGeomSetCollideBits(drum_geom_[i], kStickCategory);
        place_drum(i);
    }

    static_assert(sizeof(Feedback) == sizeof(dJointFeedback), "feedback layout");
    if (pelvis_weld_)
        dJointSetFeedback(pelvis_weld_, reinterpret_cast<dJointFeedback *>(&weld_feedback_));
}

void Scene::place_drum(int index)
{
    const DrumParams &drum = this->drum(index);
    dGeomID geom = drum_geom_[index];
    dGeomCylinderSetParams(geom, drum.radius_m, drum.shell_depth_m);
    const Eigen::Vector3d c = drum.center_m - Eigen::Vector3d(0, 0.5 * drum.shell_depth_m, 0);
    dGeomSetPosition(geom, c.x(), c.y(), c.z());
    set_rotation(geom, z_onto(Eigen::Vector3d::UnitY()), false);

    // Soft contact from the membrane's spring-damper, the implicit step's
    // numerical damping taken back out by default (soft_contact()).
    const SoftContact sc = soft_contact(options_.step_s, drum_contact_stiffness_n_per_m(index),
                                        drum.contact_damping_n_s_per_m,
                                        options_.contact_numerical_damping_compensated);
    contact_erp_[index] = sc.erp;
    contact_cfm_[index] = sc.cfm;
    const stick_tip *tip =
        options_.drum.stick_tip.empty() ? nullptr : stick_tip_find(options_.drum.stick_tip.c_str());
    tip_stiffness_ = tip ? tip->stiffness : 0.0;
    tip_alpha_ = tip ? tip->alpha : 1.0;
    head_k3_[index] = drum.stretch_n_per_m3();
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
    return drum_contact_stiffness_n_per_m(0);
}

double Scene::drum_contact_stiffness_n_per_m(int index) const
{
    return drum(index).stiffness_n_per_m(model_.options().stick.tip_radius_m);
}

const DrumParams &Scene::drum(int index) const
{
    if (index < 0 || index >= drum_count())
        throw SimError("drum " + std::to_string(index) + ": the scene has " +
                       std::to_string(drum_count()) + " drum(s)");
    return index == 0 ? options_.drum : options_.extra_drums[static_cast<size_t>(index - 1)];
}

void Scene::set_drum(const DrumParams &drum)
{
    set_drum(0, drum);
}

void Scene::set_drum(int index, const DrumParams &drum)
{
    this->drum(index); // throws for a bad index
    SceneOptions candidate = options_;
    (index == 0 ? candidate.drum : candidate.extra_drums[static_cast<size_t>(index - 1)]) = drum;
    validate(candidate); // throws naming the value; nothing changed yet
    if (drum.radius_m <= model_.options().stick.tip_radius_m)
        throw SimError("drum radius: must exceed the stick tip radius");
    (index == 0 ? options_.drum : options_.extra_drums[static_cast<size_t>(index - 1)]) = drum;
    place_drum(index);
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

} // namespace ictus
