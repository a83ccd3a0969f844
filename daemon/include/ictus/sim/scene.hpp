// scene.hpp -- the one owner of ODE state: world, collision space, contact
// group, the physical character (20 bodies, 19 ball joints + angular motors,
// pelvis welded to the world), the sticks merged into the hands, and the drum.
// Fixed step: control (eq. 1 motor rows), collide, step, clear contacts, check.
// See docs/character.md.
#pragma once

#include "ictus/base/motor_noise.hpp"
#include "ictus/character/character.hpp"
#include "ictus/control/joint_controller.hpp"
#include "ictus/character/joint_limit_ref.hpp"
#include "ictus/sim/sim_error.hpp"
#include "ictus/sim/strike_event.hpp" // kMaxDrums

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <limits>
#include <string>
#include <vector>

// ODE's opaque handles, so that users of the scene need not include ode.h.
struct dxWorld;
struct dxSpace;
struct dxJointGroup;
struct dxBody;
struct dxJoint;
struct dxGeom;

namespace ictus
{

// The drum: a membrane disk (the top face of a short cylinder). Contact with
// the sticks is a spring-damper normal to the membrane: the stiffness of a
// circular membrane of tension T pressed by a tip of radius r is
// k = 2 pi T / ln(R / r) (static point-load deflection of a membrane;
// docs/character.md).
struct DrumParams {
    Eigen::Vector3d center_m = Eigen::Vector3d(0.0, 0.7, 0.45); // membrane centre, world
    double radius_m = 0.178;                                    // 14 in snare
    double shell_depth_m = 0.10;
    double tension_n_per_m = 3000.0;
    double contact_damping_n_s_per_m = 3.0;
    double friction = 0.3;
    // The stick tip (externals/core/stick_tip.h: wood, nylon, felt), in series
    // with the head's spring: "" for none (the head's spring alone). Scene::
    // near_callback has the law.
    std::string stick_tip;
    // The head's film (Mylar: E, nu; thickness = 0.262 kg/m^2 / 1390 kg/m^3, the
    // membrane~ default head), for its stretching under the stick.
    double head_young_pa = 4.5e9;
    double head_poisson = 0.38;
    double head_thickness_m = 0.262 / 1390.0;
    // A cymbal instead of a membrane (docs/kit.md, "Cymbals"): the plate's
    // bending stiffness D (N m; 0: a membrane of tension_n_per_m). Its contact
    // is the point stiffness of a disc of its radius, 16 pi D / R^2, without
    // the membrane's stretching.
    double plate_bending_n_m = 0.0;
    // k = 2 pi T / ln(R / r_tip), N/m (a plate: 16 pi D / R^2).
    double stiffness_n_per_m(double tip_radius_m) const;
    // The stretching's cubic term k3 (N/m^3): F = k y + k3 y^3 under a point load
    // (stick_tip_head_k3 in externals/core/stick_tip.h, Begley & Mackin 2004).
    double stretch_n_per_m3() const;
};

enum class Stepper { quick, direct }; // dWorldQuickStep or dWorldStep

// How the sticks sit in the hands (docs/character.md, "The fulcrum").
// Rigid: each stick's mass and geometry merged into its hand body (it moves
// as the hand does and cannot bounce by itself). Fulcrum: each stick is its
// own body on a hinge at the grip point (StickInHand::grip_m), about the
// grip's fulcrum axis (StickInHand::fulcrum_axis), held at 0 rad by a
// spring-damper: the grip. The stick then rebounds off the head by itself
// (contact and fulcrum), and the grip's firmness decides bounce vs press.
enum class StickMount { rigid, fulcrum };

// The grip's spring at the fulcrum: torque = -k theta - c theta'.
struct GripSpring {
    double stiffness_nm_per_rad = 12.0;
    double damping_nm_s_per_rad = 0.02;
};
// Grip firmness 0..1 (the score's `firmness`, /ictus/grip/firmness) as a
// spring: k = 2 * 2^(7 f) N m/rad (2 at 0, a loose hold, 256 at 1, the hand
// clamped on the stick: a welded stick's press), c = 2 zeta sqrt(k I) for the
// stick's inertia I about its fulcrum (docs/character.md, "The fulcrum").
// Throws SimError outside [0, 1] or for a bad inertia or ratio.
GripSpring grip_spring(double firmness, double stick_inertia_kg_m2, double damping_ratio);
// Added to a fulcrum-mounted stick's inertia about its own axis, kg m^2 (the
// rod's own is 1.3e-6, the hand's there 5e-4): the fingers closed round the stick roll with it.
// Without it QuickStep lets the stick's roll chatter until the scene diverges
// (Scene::create_stick, docs/character.md, "The fulcrum").
constexpr double kStickRollInertia_kg_m2 = 1.0e-5;
constexpr double kDefaultGripFirmness = 0.35;
constexpr double kDefaultGripDampingRatio = 0.7;

struct SceneOptions {
    double step_s = 0.001;
    Stepper stepper = Stepper::quick;
    int quickstep_iterations = 13;
    // QuickStep's successive over-relaxation factor (dWorldSetQuickStepW), 0..2
    // exclusive; ODE's default is 1.3.
    double quickstep_w = 1.3;
    double gravity_mps2 = 9.81;
    DrumParams drum; // drum 0
    // A kit's further drums, 1 .. kMaxDrums - 1 (empty: the one drum). Each
    // is a static cylinder with its own contact law, created after drum 0.
    std::vector<DrumParams> extra_drums;
    // Divergence: any non-finite state, a body faster than these, or a ball
    // joint pulled apart by more than max_joint_separation_m.
    double max_linear_speed_mps = 50.0;
    double max_angular_speed_rad_s = 400.0;
    double max_joint_separation_m = 0.05;
    // Safety-net stops: a joint further than this outside its limit region
    // meets a one-sided stop (limits must be set, stops enabled).
    bool limit_stops = true;
    double stop_margin_rad = 0.0873; // 5 degrees
    // The stop's error reduction per step (ODE's dParamStopERP): 0.2 is
    // ODE's default; 1 corrects the whole overshoot in the next step (score
    // mode: with 0.2 fast strokes left elbows up to 3 degrees past the
    // margin, docs/perform.md).
    double stop_erp = 0.2;
    // How a stop engaged one step early (the joint would pass the margin
    // within the step at its present rate) acts. false: the row sees the
    // predicted angle, so it also reverses the step's whole travel (with ERP
    // 1 an elastic wall: elbows thrown back at 100 rad/s). true (score mode):
    // the row sees the present angle and holds the joint where it is for the
    // step when it is short of the margin, or takes it back to the margin
    // when past it (docs/perform.md, "Joint limits").
    bool stop_inelastic = false;
    // The pelvis's limbs that hold no stick (the legs) out of the solve
    // (score mode): with the pelvis welded to the world they move nothing
    // that plays, so their bodies and joints are disabled in ODE and each
    // step places them at their joint targets (forward kinematics from the
    // pelvis; at rest). Their motors give no torque, the weld carries no leg
    // weight. Off: every body simulated (docs/character.md, "Kinematic legs").
    bool legs_kinematic = false;
    // The pelvis as a kinematic body of ODE's (infinite mass, at rest)
    // instead of a body welded to the world (score mode): the same fixed
    // pelvis without the weld's six rows in the solve, and without its
    // softness (ERP 0.2, CFM 1e-9). support_force_n() is then the pelvis's
    // statics: its weight and its simulated joints' forces on it.
    bool pelvis_kinematic = false;
    // The stick-head contact's damping is the head's own: the implicit
    // step's numerical damping (h k) is taken back out of it (Scene::set_drum
    // comments). Off: the plain ODE mapping.
    bool contact_numerical_damping_compensated = true;
    bool rate_feedforward = true;
    StickMount sticks = StickMount::rigid;
    std::array<GripSpring, 2> grip{};                     // [side], fulcrum mount only
    double grip_damping_ratio = kDefaultGripDampingRatio; // set_grip_firmness()'s
};
// Throws SimError naming the first bad option.
void validate(const SceneOptions &options);
// Whether name is a stick tip of the table (DrumParams::stick_tip).
bool is_stick_tip(const std::string &name);

enum class StepResult { ok, diverged };

// What the drum did to one stick in the last step, from the stick-drum contact
// joints' feedback (dJointFeedback: the constraint forces ODE applied): the
// force on the stick, N, world frame (normal and friction together). The force
// on the membrane is its opposite. Zero when the stick did not touch the drum.
// ODE's soft-contact parameters for a spring k (N/m) and damper c (N s/m)
// at step h (s): ERP = h k / (h k + c'), CFM = 1 / (h k + c'), the implicit
// Euler step of the spring-damper (ODE manual). With `compensated`,
// c' = max(c - h k, -0.95 h k): the implicit step's own numerical damping
// (h k) is taken back out, so the contact dissipates as the damper c alone
// (Scene::set_drum).
struct SoftContact {
    double erp = 0.0;
    double cfm = 0.0;
};
SoftContact soft_contact(double h_s, double k_n_per_m, double c_n_s_per_m, bool compensated);

// The bead on the head: the stick tip's law F = k_tip x^alpha (DrumParams::stick_tip,
// externals/core/stick_tip.h, the law contact~ plays; k_tip 0: no tip) in series with
// the head's stiffening spring F = k_head y + k3 y^3 (massless; N/m, N/m^3). Returns
// the pair's secant stiffness F / depth (N/m) at the given depth (m): k_head for
// depth <= 0. The scene gives it to ODE's soft contact each step.
double series_contact_stiffness(double k_head, double k3, double k_tip, double alpha, double depth);

struct StickDrumContact {
    Eigen::Vector3d bead_force_n = Eigen::Vector3d::Zero();  // through the bead (tip sphere)
    Eigen::Vector3d shaft_force_n = Eigen::Vector3d::Zero(); // through the shaft (capsule)
    int bead_points = 0, shaft_points = 0;                   // contact points in the step
    Eigen::Vector3d force_n() const { return bead_force_n + shaft_force_n; }
};

// Wall-clock seconds spent in the parts of the last step (only filled when asked).
struct StepTiming {
    double control_s = 0.0;
    double collide_s = 0.0;
    double solve_s = 0.0;
    double check_s = 0.0;
};

// Not thread-safe: one thread builds and steps a scene (ODE's collision
// data is per thread and allocated for the constructing thread).
class Scene
{
  public:
    // Builds the physical character in `initial` pose (zero velocities).
    // gains.size() must be CharacterModel::kJoints.
    Scene(const CharacterModel &model, const SceneOptions &options, const CharacterPose &initial,
          const std::vector<JointGains> &gains);
    ~Scene();
    Scene(const Scene &) = delete;
    Scene &operator=(const Scene &) = delete;

    const CharacterModel &model() const { return model_; }
    const SceneOptions &options() const { return options_; }
    const std::vector<JointGains> &gains() const { return gains_; }
    void set_gains(const std::vector<JointGains> &gains);

    // Joint limits, one per joint (inactive refs for joints without a limit),
    // or an empty vector for none. Targets are clamped into the limit region;
    // stops catch a joint that leaves it anyway. The limits must outlive the scene.
    void set_joint_limits(const std::vector<JointLimitRef> &limits);

    // Targets for eq. 1: local rotations [joint] and their rates (rad/s, parent
    // frame). Clamped into the limits here.
    void set_joint_targets(const std::vector<Eigen::Quaterniond> &local,
                           const std::vector<Eigen::Vector3d> &rate_parent);
    const std::vector<Eigen::Quaterniond> &joint_targets() const { return target_; }

    // One fixed step. On divergence the character is reset to the current
    // targets' pose at rest and StepResult::diverged is returned.
    StepResult step(StepTiming *timing = nullptr);
    // Places the character in `pose` (pelvis ignored: it is welded), at rest.
    void reset(const CharacterPose &pose);
    // Whether body `b` is placed, not simulated (SceneOptions::legs_kinematic:
    // the legs; pelvis_kinematic: the pelvis).
    bool body_kinematic(int b) const { return kinematic_body_.at(static_cast<size_t>(b)); }

    double time_s() const { return time_s_; }
    long steps() const { return steps_; }
    int divergences() const { return divergences_; }
    int contacts_last_step() const { return contacts_last_step_; }
    long contact_steps() const { return contact_steps_; }
    // Times a stick part (bead or shaft) met a drum other than from above:
    // through the shell's side or bottom (docs/character.md, "Drum"). Such a
    // part passes through the drum until it is clear of it. All drums.
    long shell_passes() const { return shell_passes_; }
    int stops_active_last_step() const { return stops_active_; }
    // Motor torque of each joint in the last step (N m, on the child, world
    // frame; ODE joint feedback), and whether any axis hit its torque limit.
    Eigen::Vector3d motor_torque(int joint) const;
    bool motor_saturated(int joint) const;

    // State, in the model's terms (body frame = joint frame, not the CoM).
    void body_frames(BodyFrames &frames) const;
    void local_rotations(std::vector<Eigen::Quaterniond> &local) const;
    Eigen::Vector3d tip_position(Side side) const; // the stick's end point, world
    Eigen::Vector3d tip_velocity(Side side) const;
    // The bead's centre (the tip minus the bead radius along the stick axis:
    // the collision sphere's centre, what the strike detector watches) and
    // the velocity of that point, world frame.
    Eigen::Vector3d bead_position(Side side) const;
    Eigen::Vector3d bead_velocity(Side side) const;
    // Where the hand carries the stick: the stick's end point and the bead
    // centre as they would be at the fulcrum's rest angle (0), and their
    // velocities. What the arms are controlled by; equal to tip_position()
    // and bead_position() with rigid sticks.
    Eigen::Vector3d held_tip_position(Side side) const;
    Eigen::Vector3d held_tip_velocity(Side side) const;
    Eigen::Vector3d held_bead_position(Side side) const;
    // The fulcrum's angle (rad, > 0: the tip turned away from the palm side
    // the grip's axis defines) and rate; 0 with rigid sticks.
    double fulcrum_angle_rad(Side side) const;
    double fulcrum_rate_rad_s(Side side) const;
    // The stick's rotation in its hand's frame (identity: as the hand holds
    // it at rest; rigid sticks always): the fulcrum's turn and the joint's drift.
    Eigen::Quaterniond stick_in_hand(Side side) const;
    // The fulcrum's axis and the stick's axis (butt to tip), unit, world.
    Eigen::Vector3d fulcrum_axis(Side side) const;
    Eigen::Vector3d stick_axis(Side side) const;
    // The grip's spring (fulcrum mount), changed at once. Throws SimError
    // for a non-finite or non-positive stiffness, or a negative damping.
    void set_grip(Side side, const GripSpring &grip);
    const GripSpring &grip(Side side) const { return options_.grip[static_cast<int>(side)]; }
    // The grip as a firmness 0..1 (grip_spring()), for this scene's stick.
    void set_grip_firmness(Side side, double firmness);
    // Motor noise (docs/humanize.md): each physics step every
    // driven joint gets a torque (on the child, its reaction on the parent)
    // whose SD per axis is amount x kTorqueNoiseCv x the joint's commanded
    // stiffness torque kp |error|, drawn from the seeded stream `seed`
    // (the physics thread only). 0: no torque and no draw. Restarts the
    // stream.
    static constexpr double kTorqueNoiseCv = 0.02;
    void set_motor_noise(double amount, std::uint64_t seed);
    double motor_noise() const { return motor_noise_; }
    // The stick's moment of inertia about its fulcrum axis, kg m^2.
    double fulcrum_inertia_kg_m2(Side side) const;
    // The stick's effective mass at the bead along `normal` (unit, world), kg:
    // the mass an impulse along the normal at the bead meets, from the stick,
    // the grip and the hand at this instant (docs/character.md, "Effective
    // mass"). The hand is taken as free of the forearm (the wrist's PD is
    // compliant over a contact's few ms). Fulcrum mount: the stick pivoting
    // on the hand (a loose grip), blended toward the stick welded to the hand
    // by s = k_g / (k_g + k), k_g = k_f / l^2 the grip's stiffness seen at the
    // bead (l its distance from the fulcrum axis) and k the drum's contact
    // stiffness. Rigid mount: the hand and stick as one body.
    // `drum`: whose contact stiffness k (0: drum 0).
    double effective_mass_kg(Side side, const Eigen::Vector3d &normal, int drum = 0) const;
    // The drum's action on each stick in the last step (see StickDrumContact).
    const StickDrumContact &drum_contact(Side side) const
    {
        return drum_contact_[static_cast<int>(side)];
    }
    // The force the world exerts on the pelvis through its weld in the last
    // step, N, world frame (with the drum contacts, the only external forces
    // besides gravity: at rest they sum to the character's weight). A
    // kinematic pelvis (SceneOptions::pelvis_kinematic): what a weld would
    // carry, its weight less its simulated joints' forces on it.
    Eigen::Vector3d support_force_n() const;

    // The drum, changed on the live scene: the membrane moves and resizes at
    // once and the contact law (k = 2 pi T / ln(R / r_tip), c) is recomputed
    // for the next step; the character is untouched. Throws SimError
    // naming the bad value (the scene keeps its drum).
    void set_drum(const DrumParams &drum);
    const DrumParams &drum() const { return options_.drum; }
    // The contact law's stiffness k in use, N/m.
    double drum_contact_stiffness_n_per_m() const;
    // A kit: drum_count() drums, drum(0) the one above; index checked
    // (SimError). set_drum(i, d) changes drum i as set_drum(d) does drum 0.
    int drum_count() const { return 1 + static_cast<int>(options_.extra_drums.size()); }
    const DrumParams &drum(int index) const;
    void set_drum(int index, const DrumParams &drum);
    double drum_contact_stiffness_n_per_m(int index) const;
    // Shell passes of one drum (shell_passes() is their sum).
    long shell_passes(int index) const { return drum_shell_passes_.at(static_cast<size_t>(index)); }
    double max_linear_speed_mps() const;
    double max_angular_speed_rad_s() const;
    // Adds a velocity change to a body's centre of mass (tests: injected
    // kicks). Throws SimError for a bad or kinematic body or a
    // non-finite change.
    void kick(int body, const Eigen::Vector3d &delta_linear_mps,
              const Eigen::Vector3d &delta_angular_rad_s);

  private:
    double motor_noise_ = 0.0;
    MotorNoise motor_noise_stream_;
    // Building (scene_build.cpp), in the order ODE gets it.
    void build(const CharacterPose &initial);
    void create_world();
    void create_bodies(const BodyFrames &frames);
    void create_joints(const BodyFrames &frames);
    void make_legs_kinematic();
    void create_stick(int side, const BodyFrames &frames);
    void create_drum();
    // Stepping (scene_step.cpp): eq. 1's motor rows and the limit stops.
    struct LimitStop {
        bool engaged = false;
        Eigen::Vector3d axis = Eigen::Vector3d::UnitX(); // world, unit
        double violation = 0.0; // the angle past the limit the stop row sees, rad
        double stop_at = 0.0;   // the stop row's high stop, rad
    };
    void apply_control();
    Eigen::Vector3d relative_rate(int joint) const;
    LimitStop limit_stop(int joint, const Eigen::Quaterniond &parent,
                         const Eigen::Quaterniond &child, const MotorCommand &command) const;
    void look_ahead_stop(int joint, const Eigen::Quaterniond &parent,
                         const Eigen::Quaterniond &current, const MotorCommand &command,
                         LimitStop &stop) const;
    void drive_motor(int joint, const MotorCommand &command, const LimitStop &stop);
    bool check() const;
    static void near_callback(void *data, dxGeom *a, dxGeom *b);
    void place_drum(int index);
    void gather_contact_forces();
    CharacterPose target_pose() const;
    void place_kinematic_bodies();
    Eigen::Vector3d bead_rel_com(Side side) const;

    CharacterModel model_;
    SceneOptions options_;
    std::vector<JointGains> gains_;
    std::vector<JointLimitRef> limits_;
    std::vector<Eigen::Quaterniond> target_;
    std::vector<Eigen::Vector3d> target_rate_;
    std::array<Eigen::Vector3d, CharacterModel::kBodies> com_local_; // merged, body frame
    std::array<bool, CharacterModel::kJoints> motor_axes_world_;
    // SceneOptions::legs_kinematic: the bodies placed at their targets
    // (joint j moves body j + 1), none without it.
    std::array<bool, CharacterModel::kBodies> kinematic_body_{};
    bool any_kinematic_ = false;
    // The motor parameters last given to ODE, so that apply_control() sets only
    // what changed (NaN: never set).
    struct MotorParams {
        double cfm = std::numeric_limits<double>::quiet_NaN();
        std::array<double, 3> fmax = {std::numeric_limits<double>::quiet_NaN(),
                                      std::numeric_limits<double>::quiet_NaN(),
                                      std::numeric_limits<double>::quiet_NaN()};
        bool stops_open = false; // the stop rows set to +-infinity
        bool locked = false;     // score mode: axes 2 and 3 held with the stop
        // Score mode: consecutive steps the stop held the joint far from its target
        // (drive_motor's deadlock rule).
        int held_far = 0;
    };
    std::array<MotorParams, CharacterModel::kJoints> motor_params_{};

    dxWorld *world_ = nullptr;
    dxSpace *space_ = nullptr;
    dxJointGroup *contacts_ = nullptr;
    std::array<dxBody *, CharacterModel::kBodies> body_{};
    std::array<dxJoint *, CharacterModel::kJoints> ball_{};
    std::array<dxJoint *, CharacterModel::kJoints> motor_{};
    struct Feedback {
        double f1[4], t1[4], f2[4], t2[4]; // layout of dJointFeedback (dVector3 = 4 dReal)
    };
    std::array<Feedback, CharacterModel::kJoints> feedback_{};
    // One feedback slot per stick-drum contact point of the step: 2 sticks x
    // (bead, shaft) x at most 4 points each (near_callback's kMax).
    struct ContactSlot {
        Feedback feedback;
        int side = 0;
        bool bead = false;
    };
    std::array<ContactSlot, 16> contact_slot_{};
    int contact_slots_used_ = 0;
    std::array<StickDrumContact, 2> drum_contact_{};
    Feedback weld_feedback_{};
    // SceneOptions::pelvis_kinematic: the ball joints' forces on the pelvis.
    std::array<Feedback, CharacterModel::kJoints> ball_feedback_{};
    double pelvis_mass_kg_ = 0.0;
    std::array<std::array<Eigen::Vector3d, 3>, CharacterModel::kJoints> motor_axes_{};
    dxJoint *pelvis_weld_ = nullptr;
    std::array<dxGeom *, kMaxDrums> drum_geom_{}; // [drum]
    std::array<dxGeom *, 2> stick_shaft_{};
    std::array<dxGeom *, 2> stick_tip_{};
    // Fulcrum mount: the sticks' bodies (their frame = the hand's frame at
    // the rest angle, origin at their CoM) and their hinges.
    std::array<dxBody *, 2> stick_body_{};
    std::array<dxJoint *, 2> fulcrum_{};
    void apply_grip(int side);
    dxBody *tip_body(Side side) const;
    Eigen::Vector3d tip_body_com(Side side) const; // its CoM in the hand frame
    std::array<double, kMaxDrums> contact_erp_{}, contact_cfm_{}; // [drum]
    // The stick tip's law (the first drum's DrumParams::stick_tip: the sticks' tip, on
    // every drum), 0 stiffness: none; each head's stretching (stretch_n_per_m3()).
    double tip_stiffness_ = 0.0, tip_alpha_ = 1.0;
    std::array<double, kMaxDrums> head_k3_{}; // [drum]

    double time_s_ = 0.0;
    long steps_ = 0;
    int divergences_ = 0;
    int contacts_last_step_ = 0;
    long contact_steps_ = 0;
    // Per drum and stick part [drum * 4 + side * 2 + bead]: touching the
    // drum in the last step, in this one, and passing through its shell
    // (near_callback).
    std::array<bool, 4 * kMaxDrums> part_touching_{}, part_touching_now_{}, part_through_{};
    // A shaft whose touch began on a plate's edge, from the side (near_callback).
    std::array<bool, 4 * kMaxDrums> part_edge_on_{};
    long shell_passes_ = 0;
    std::array<long, kMaxDrums> drum_shell_passes_{};
    int stops_active_ = 0;
};

} // namespace ictus
