// Joint-space tracking run (ID mode, eq. 1).
#include "ictus/perform/track.hpp"
#include "ictus/base/rotation.hpp"

#include "ictus/mocap/rotation_stats.hpp"
#include "ictus/perform/tracker.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <ostream>

namespace ictus
{

namespace
{
constexpr double kRadToDeg = 180.0 / M_PI;

// The time from `t` to the nearest impact in `impacts` (in time order), s.
double to_nearest_impact_s(const std::vector<StrokeTurnaround> &impacts, double t)
{
    double best = std::numeric_limits<double>::infinity();
    auto it = std::lower_bound(impacts.begin(), impacts.end(), t,
                               [](const StrokeTurnaround &a, double x) { return a.time_s < x; });
    if (it != impacts.end())
        best = std::min(best, it->time_s - t);
    if (it != impacts.begin())
        best = std::min(best, t - std::prev(it)->time_s);
    return best;
}
} // namespace

double elbow_flexion_deg(const Eigen::Vector3d &upper_arm_axis, const Eigen::Vector3d &forearm_axis,
                         const Eigen::Quaterniond &elbow)
{
    const Eigen::Vector3d f = elbow * forearm_axis;
    return std::atan2(upper_arm_axis.cross(f).norm(), upper_arm_axis.dot(f)) * kRadToDeg;
}

void drummer_arms(const CharacterModel &model, CharacterPose &pose)
{
    const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
    const char *upper_arm[2] = {"l_upper_arm", "r_upper_arm"};
    const char *forearm[2] = {"l_forearm", "r_forearm"};
    const char *hand[2] = {"l_hand", "r_hand"};
    BodyFrames f;
    model.forward(pose, f);
    Eigen::Vector3d lateral =
        f.origin_m[model.body_index(upper_arm[0])] - f.origin_m[model.body_index(upper_arm[1])];
    lateral.y() = 0.0;
    if (lateral.norm() < 1e-9)
        return;
    lateral.normalize();
    const Eigen::Vector3d forward = lateral.cross(up); // left x up
    for (int s = 0; s < 2; ++s) {
        const int shoulder = model.joint_index(Tracker::kArmJoints[s][1]);
        const int elbow = model.joint_index(Tracker::kArmJoints[s][2]);
        const int bu = model.body_index(upper_arm[s]), bf = model.body_index(forearm[s]),
                  bh = model.body_index(hand[s]);
        if (shoulder < 0 || elbow < 0 || bu < 0 || bf < 0 || bh < 0)
            continue;
        // The upper arm hanging, kDrummerArmOut_rad out from the vertical.
        const Eigen::Vector3d u = (f.origin_m[bf] - f.origin_m[bu]).normalized();
        const Eigen::Vector3d out = (s == 0 ? 1.0 : -1.0) * lateral;
        const Eigen::Vector3d hanging =
            (-std::cos(kDrummerArmOut_rad) * up + std::sin(kDrummerArmOut_rad) * out).normalized();
        const Eigen::Quaterniond parent = f.rotation[model.joint_body(shoulder).parent];
        const Eigen::Quaterniond turn_u = Eigen::Quaterniond::FromTwoVectors(u, hanging);
        pose.local[shoulder] =
            (parent.conjugate() * turn_u * parent * pose.local[shoulder]).normalized();
        model.forward(pose, f);
        // The forearm forward (the elbow bent about the lateral axis).
        const Eigen::Vector3d fa = (f.origin_m[bh] - f.origin_m[bf]).normalized();
        const Eigen::Quaterniond upper = f.rotation[bu];
        const Eigen::Quaterniond turn_f = Eigen::Quaterniond::FromTwoVectors(fa, forward);
        pose.local[elbow] = (upper.conjugate() * turn_f * upper * pose.local[elbow]).normalized();
        model.forward(pose, f);
    }
}

TipTrajectory reference_tip_trajectory(const CharacterModel &model,
                                       const ReferenceMotion &reference)
{
    TipTrajectory tips;
    for (int f = 0; f < reference.frames(); ++f) {
        tips.time_s.push_back(f / reference.frame_rate_hz());
        const auto p = reference_tips(model, reference.frame(f));
        for (int s = 0; s < 2; ++s)
            tips.tip_m[s].push_back(p[s]);
    }
    return tips;
}

ReferenceFilter track_reference_filter()
{
    ReferenceFilter f;
    f.kernel = ReferenceFilter::Kernel::butterworth;
    f.spike_reference_rate_hz = 120.0; // 80_13's rate, where 5 degrees was chosen
    return f;
}

CartesianOptions track_cartesian_defaults()
{
    CartesianOptions c;
    c.start_from_simulated = true;
    c.posture_weight = 0.005;
    c.feedback_iterations = 2;
    c.kinematic_iterations = 1;
    c.correction_limit_m = 0.3;
    return c;
}

SceneOptions track_scene_defaults()
{
    SceneOptions s;
    s.pelvis_kinematic = true;
    return s;
}

void validate(const TrackOptions &o)
{
    validate(o.scene);
    if (!(std::isfinite(o.duration_s) && o.duration_s >= 0.0 && o.duration_s <= 86400.0))
        throw PerformError("duration: expected 0 <= s <= 86400, got " +
                           std::to_string(o.duration_s));
    if (!(std::isfinite(o.ramp_s) && o.ramp_s >= 0.0))
        throw PerformError("ramp: expected a finite value >= 0 s");
    if (!(std::isfinite(o.sample_rate_hz) && o.sample_rate_hz >= 0.0))
        throw PerformError("sample rate: expected a finite value >= 0 Hz");
    const CartesianOptions &c = o.cartesian;
    if (!(std::isfinite(c.gain) && c.gain > 0.0 && c.gain <= 100.0))
        throw PerformError("ik gain: expected 0 < gain <= 100, got " + std::to_string(c.gain));
    if (!std::isfinite(c.velocity_gain_s) || c.velocity_gain_s > 1.0)
        throw PerformError("ik velocity gain: expected a value <= 1 s (< 0: automatic)");
    if (!(std::isfinite(c.acceleration_feedforward_s2) && c.acceleration_feedforward_s2 >= 0.0 &&
          c.acceleration_feedforward_s2 <= 1.0))
        throw PerformError("ik acceleration feedforward: expected 0 <= s^2 <= 1");
    if (!(std::isfinite(c.correction_limit_m) && c.correction_limit_m >= 0.0))
        throw PerformError("ik correction limit: expected a finite value >= 0 m");
    if (!(std::isfinite(c.integral_per_s) && c.integral_per_s >= 0.0))
        throw PerformError("ik integral: expected a finite value >= 0 /s");
    if (!(std::isfinite(c.integral_limit_m) && c.integral_limit_m >= 0.0))
        throw PerformError("ik integral limit: expected a finite value >= 0 m");
    if (!(std::isfinite(c.posture_weight) && c.posture_weight >= 0.0 && c.posture_weight <= 1.0))
        throw PerformError("ik posture weight: expected 0 <= w <= 1, got " +
                           std::to_string(c.posture_weight));
    ChainIkSolverPos_dls probe(4);
    if (!probe.set_params(c.ik))
        throw PerformError("ik parameters: expected finite positive values");
}

namespace
{
// {"left": v[0], "right": v[1]}.
template <typename T> nlohmann::json sides(const T (&v)[2])
{
    return {{"left", v[0]}, {"right", v[1]}};
}
} // namespace

nlohmann::json TrackSummary::to_json() const
{
    nlohmann::json j = {
        {"mode", mode},
        {"frames", frames},
        {"samples", samples},
        {"steps", steps},
        {"duration_s", duration_s},
        {"wall_time_s", wall_time_s},
        {"realtime_factor", realtime_factor},
        {"us_per_step", steps > 0 ? 1e6 * wall_time_s / steps : 0.0},
        {"tip_rms_mm", sides(tip_rms_mm)},
        {"tip_rms_raw_mm", raw_measured ? sides(tip_rms_raw_mm) : nlohmann::json()},
        {"joint_rms_raw_deg_all",
         raw_measured ? nlohmann::json(joint_rms_raw_deg_all) : nlohmann::json()},
        {"tip_max_mm", sides(tip_max_mm)},
        {"tip_rms_free_mm", sides(tip_rms_free_mm)},
        {"tip_rms_contact_mm", sides(tip_rms_contact_mm)},
        {"tip_rms_raw_free_mm", raw_measured ? sides(tip_rms_raw_free_mm) : nlohmann::json()},
        {"tip_rms_raw_contact_mm", raw_measured ? sides(tip_rms_raw_contact_mm) : nlohmann::json()},
        {"captured_impacts", sides(captured_impacts)},
        {"diverged", diverged},
        {"interrupted", interrupted},
        {"divergences", divergences},
        {"max_linear_speed_mps", max_linear_speed_mps},
        {"max_angular_speed_rad_s", max_angular_speed_rad_s},
        {"contact_steps", contact_steps},
        {"stop_steps", stop_steps},
        {"drum_center_m", {drum_center_m.x(), drum_center_m.y(), drum_center_m.z()}},
        {"drum_rule", drum_rule},
        {"drum_through_fraction", drum_through_fraction}};
    nlohmann::json rms = nlohmann::json::object(), mx = nlohmann::json::object();
    nlohmann::json peak = nlohmann::json::object(), sat = nlohmann::json::object();
    double sum2 = 0.0;
    for (size_t i = 0; i < joint_names.size(); ++i) {
        rms[joint_names[i]] = joint_rms_deg[i];
        mx[joint_names[i]] = joint_max_deg[i];
        if (i < joint_peak_torque_nm.size()) {
            peak[joint_names[i]] = joint_peak_torque_nm[i];
            sat[joint_names[i]] = joint_saturated_fraction[i];
        }
        sum2 += joint_rms_deg[i] * joint_rms_deg[i];
    }
    j["joint_rms_deg"] = rms;
    j["joint_max_deg"] = mx;
    j["joint_peak_torque_nm"] = peak;
    j["joint_saturated_fraction"] = sat;
    j["joint_rms_deg_all"] = joint_names.empty() ? 0.0 : std::sqrt(sum2 / joint_names.size());
    if (mode == "cartesian") {
        j["ik"] = {
            {"mean_iterations", ik_mean_iterations},
            {"max_iterations", ik_max_iterations},
            {"us_per_step", ik_us_per_step},
            {"not_converged", ik_not_converged},
            {"reseeded", ik_reseeded},
            {"elbow_flexion_rms_deg", elbow_measured ? sides(elbow_ik_rms_deg) : nlohmann::json()}};
    }
    return j;
}

std::array<Eigen::Vector3d, 2> reference_tips(const CharacterModel &model,
                                              const CharacterPose &pose)
{
    BodyFrames frames;
    model.forward(pose, frames);
    std::array<Eigen::Vector3d, 2> tips;
    for (int s = 0; s < 2; ++s) {
        const Side side = static_cast<Side>(s);
        const int hb = model.hand_body(side);
        tips[s] = model.tip_position(side, frames.origin_m[hb], frames.rotation[hb]);
    }
    return tips;
}

Eigen::Vector3d auto_drum_center(const CharacterModel &model, const ReferenceMotion &reference)
{
    std::array<Eigen::Vector3d, 2> lowest;
    lowest.fill(Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()));
    for (int f = 0; f < reference.frames(); ++f) {
        const auto tips = reference_tips(model, reference.frame(f));
        for (int s = 0; s < 2; ++s)
            if (tips[s].y() < lowest[s].y())
                lowest[s] = tips[s];
    }
    Eigen::Vector3d c = 0.5 * (lowest[0] + lowest[1]);
    c.y() = std::min(lowest[0].y(), lowest[1].y()) - 0.5 * model.options().stick.tip_radius_m;
    return c;
}

namespace
{

// The elbow flexion (elbow_flexion_deg) of either arm from its elbow's local rotation.
class ElbowFlexion
{
  public:
    explicit ElbowFlexion(const CharacterModel &model)
    {
        for (int s = 0; s < 2; ++s) {
            joint[s] = model.joint_index(Tracker::kArmJoints[s][2]);
            upper_arm_axis_[s] = model.joint_body(joint[s]).offset_m;
            forearm_axis_[s] =
                model.joint_body(model.joint_index(Tracker::kArmJoints[s][3])).offset_m;
        }
    }
    double operator()(int s, const Eigen::Quaterniond &q) const
    {
        return elbow_flexion_deg(upper_arm_axis_[s], forearm_axis_[s], q);
    }
    int joint[2]; // the elbows' joint indices [side]

  private:
    Eigen::Vector3d upper_arm_axis_[2], forearm_axis_[2];
};

// The sums behind the summary's errors, over the counted samples.
struct ErrorSums {
    explicit ErrorSums(int joints) : joint_sum2(joints, 0.0), joint_max(joints, 0.0) {}
    std::vector<double> joint_sum2, joint_max;
    double tip_sum2[2] = {0, 0}, tip_max[2] = {0, 0}, raw_tip_sum2[2] = {0, 0};
    double raw_joint_sum2 = 0.0;
    double elbow_sum2[2] = {0.0, 0.0};
    double split_sum2[2][2][2] = {}; // [side][raw?][contact?]
    long split_n[2][2] = {};         // [side][contact?]
};

// The CSV's header line (one column group per joint, per tip, per elbow).
void write_csv_header(const CharacterModel &model, std::ostream &csv)
{
    csv << "time_s";
    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        const std::string &n = model.joint_name(j);
        for (const char *what : {"ref", "sim"})
            for (const char *axis : {"x", "y", "z"})
                csv << ',' << n << '_' << what << '_' << axis << "_deg";
        csv << ',' << n << "_err_deg";
    }
    for (const char *side : {"left", "right"})
        for (const char *what : {"ref", "sim"})
            for (const char *axis : {"x", "y", "z"})
                csv << ",tip_" << side << '_' << what << '_' << axis << "_m";
    // Elbow flexion (the angle between upper arm and forearm, deg): cleaned
    // capture, PD target (joint mode: the capture; Cartesian mode: Theta^T from
    // IK), simulation. Then the raw capture's tips and elbow flexion.
    for (const char *side : {"l", "r"})
        for (const char *what : {"ref", "target", "sim"})
            csv << ',' << side << "_elbow_flexion_" << what << "_deg";
    for (const char *side : {"left", "right"}) {
        for (const char *axis : {"x", "y", "z"})
            csv << ",tip_" << side << "_raw_" << axis << "_m";
        csv << ',' << side[0] << "_elbow_flexion_raw_deg";
    }
    csv << ",contacts\n";
}

// `options` checked (validate()) and completed for the run: a stick-only capture
// checked, the IK's reference arms off where nothing gives them.
TrackOptions run_options(const TrackOptions &options_in)
{
    validate(options_in);
    TrackOptions options = options_in;
    const TipTrajectory *tips_in = options.tip_reference;
    if (tips_in) {
        if (options.mode != TrackMode::cartesian)
            throw PerformError("a stick-only capture needs the Cartesian mode");
        if (tips_in->time_s.size() < 2 || tips_in->tip_m[0].size() != tips_in->time_s.size() ||
            tips_in->tip_m[1].size() != tips_in->time_s.size())
            throw PerformError("stick capture: expected at least two frames of both tips");
        options.cartesian.reference_has_arms = false;
    }
    // Algorithm 2 literally: the arms are driven by the stick tips alone; the
    // capture's arm rotations seed no IK (its clip-wide mean is the posture).
    if (options.cartesian.start_from_simulated)
        options.cartesian.reference_has_arms = false;
    return options;
}

// One run of track_joint_space: set up in the constructor (drum, tips, initial
// pose, tracker), then run() steps it, measures and writes the CSV.
class TrackRun
{
  public:
    TrackRun(const CharacterModel &model, const ReferenceMotion &reference,
             const TrackOptions &options_in, const std::vector<JointLimitRef> &limits,
             std::ostream *csv, const ProgressFn &progress, const std::vector<JointGains> *gains_in,
             const ReferenceMotion *raw_reference);
    TrackRun(const TrackRun &) = delete;
    TrackRun &operator=(const TrackRun &) = delete;
    TrackSummary run();

  private:
    void place_the_drum();
    void press_impacts();
    void start_tracker(const std::vector<JointGains> *gains_in);
    void set_capture_posture();
    void start_summary();
    void update_tip_rates(double t_next);
    void update_tip_positions(double t_next);
    void record_step();
    void sample(double t_next);
    void count_errors(double t_next, const std::array<Eigen::Vector3d, 2> &ref_tips,
                      const std::array<Eigen::Vector3d, 2> &sim_tips);
    void write_csv_row(double t_next, const std::array<Eigen::Vector3d, 2> &ref_tips,
                       const std::array<Eigen::Vector3d, 2> &sim_tips);
    void report_progress(long n, long &last_progress) const;
    void finish_summary(long n);
    Scene &scene() { return tracker_->scene(); }

    static constexpr int nj = CharacterModel::kJoints;
    const CharacterModel &model_;
    const ReferenceMotion &reference_;
    TrackOptions options_;
    const std::vector<JointLimitRef> &limits_;
    std::ostream *csv_;
    const ProgressFn &progress_;
    const ReferenceMotion *raw_reference_;
    const bool cartesian_;
    // The tips the errors are measured against (and the Cartesian mode's X^T):
    // the stick-only capture, else the cleaned tip motion, else the reference.
    const ReferenceMotion &tip_src_;
    // The stick-only capture (tips_in_: with its impacts restored when the drum
    // fit found them) and the tips its X^T follows (targets_in_); null for a
    // full-body capture.
    const TipTrajectory *tips_in_, *targets_in_;
    // A stick-only capture's impacts restored between its samples (X^T and the errors).
    TipTrajectory restored_;
    // X^T asks for more at an impact: the stick's end down to the membrane plane at the
    // vertex (the fitted membrane: kImpactPitchFactor tip radii below it), so that the
    // simulated stick's bead reaches the head whatever its pitch, as the captured one did
    // (docs/ik.md, "Stick-only captures"). The errors stay against the capture.
    TipTrajectory pressed_;
    DrumPlacement placement_;
    bool have_impacts_ = true;
    double h_ = 0.0, sample_rate_ = 0.0;
    long steps_ = 0, last_sample_index_ = 0;
    CharacterPose initial_;
    std::unique_ptr<Tracker> tracker_;
    ElbowFlexion flexion_;
    ErrorSums sums_;
    TrackSummary summary_;
    // Per-step scratch.
    CharacterPose ref_pose_, step_pose_, around_pose_, tip_pose_, raw_pose_;
    std::vector<Eigen::Quaterniond> sim_local_;
    TipTargets tip_targets_;
};

TrackRun::TrackRun(const CharacterModel &model, const ReferenceMotion &reference,
                   const TrackOptions &options_in, const std::vector<JointLimitRef> &limits,
                   std::ostream *csv, const ProgressFn &progress,
                   const std::vector<JointGains> *gains_in, const ReferenceMotion *raw_reference)
    : model_(model), reference_(reference), options_(run_options(options_in)), limits_(limits),
      csv_(csv), progress_(progress), raw_reference_(raw_reference),
      cartesian_(options_.mode == TrackMode::cartesian),
      tip_src_(options_.tip_motion ? *options_.tip_motion : reference),
      tips_in_(options_.tip_reference), targets_in_(options_.tip_reference), flexion_(model),
      sums_(nj)
{
    place_the_drum();
    press_impacts();
    h_ = options_.scene.step_s;
    const double duration = options_.duration_s > 0.0 ? options_.duration_s
                            : tips_in_                ? tips_in_->duration_s()
                                                      : reference_.duration_s();
    steps_ = std::max(1L, std::lround(duration / h_));
    sample_rate_ =
        options_.sample_rate_hz > 0.0 ? options_.sample_rate_hz : reference_.frame_rate_hz();
    start_tracker(gains_in);
    set_capture_posture();
    start_summary();
}

// The strokes' turnarounds: the drum (--drum auto) and the contact windows.
// The drum at the turnarounds, for stick-only and full-body captures alike,
// unless the captured tips pass through it there (a drum kit: strokes for the
// other drums cross its place); then under the lowest tips (place_drum,
// docs/mocap.md, "Drum placement").
void TrackRun::place_the_drum()
{
    try {
        placement_ = place_drum(tips_in_ ? *tips_in_ : reference_tip_trajectory(model_, tip_src_),
                                model_.options().stick.tip_radius_m, options_.scene.drum.radius_m);
    } catch (const CharacterError &) {
        if (options_.drum_auto && tips_in_)
            throw;
        have_impacts_ = false;
    }
    if (options_.drum_auto)
        options_.scene.drum.center_m =
            have_impacts_ ? placement_.center_m : auto_drum_center(model_, reference_);
}

void TrackRun::press_impacts()
{
    if (!(tips_in_ && have_impacts_))
        return;
    restored_ = with_impact_vertices(*tips_in_, placement_.fit.impacts);
    // ... and a little deeper, by the dent a strike at the captured speed makes
    // in the simulated membrane (impact_press_depth_m): the tracked end rounds
    // the V off by millimetres, and with the end asked to the contact height
    // alone a third to all of the impacts at 120 Hz went unstruck.
    std::array<std::vector<StrokeTurnaround>, 2> at_membrane = placement_.fit.impacts;
    const double r_tip = model_.options().stick.tip_radius_m;
    for (auto &side : at_membrane)
        for (StrokeTurnaround &ta : side)
            ta.position_m.y() -=
                kImpactPitchFactor * r_tip +
                impact_press_depth_m(ta.speed_in_mps, model_.options().stick.mass_kg,
                                     options_.scene.drum.stiffness_n_per_m(r_tip));
    pressed_ = with_impact_vertices(*tips_in_, at_membrane);
    tips_in_ = &restored_;
    targets_in_ = &pressed_;
}

void TrackRun::start_tracker(const std::vector<JointGains> *gains_in)
{
    initial_ = reference_.frame(0);
    if (tips_in_) {
        // The arms' first pose: a cold IK solve to the first tips from a drummer's
        // arms (drummer_arms), not from the reference's (the default body's T-pose):
        // from the T-pose the solve ended in a pose whose first impacts threw the
        // sticks sideways (6.7 m/s strokes: 21 and 20 mm in the first two strokes'
        // free flight, 2.5 after; docs/ik.md, "Stick-only captures").
        drummer_arms(model_, initial_);
        Tracker::solve_arms(model_, limits_, options_.cartesian.ik,
                            {tips_in_->tip_m[0][0], tips_in_->tip_m[1][0]}, initial_);
    }
    const std::vector<JointGains> gains =
        gains_in ? *gains_in : default_gains(model_, initial_, options_.gains);
    tracker_ = std::make_unique<Tracker>(model_, options_.scene, initial_, gains, limits_,
                                         options_.mode, options_.cartesian, options_.gains);
    step_pose_ = initial_;
}

// The posture of the IK's null-space task: a full-body capture's mean arm
// pose over the clip (the centre of the learned limits, Algorithm 1's
// mean), a stick-only capture's first (cold-solved) arms.
void TrackRun::set_capture_posture()
{
    if (tips_in_ || reference_.frames() <= 0)
        return;
    for (int s = 0; s < 2; ++s) {
        Eigen::Quaterniond posture[4];
        std::vector<Eigen::Quaterniond> series(reference_.frames());
        for (int k = 0; k < 4; ++k) {
            const int j = model_.joint_index(Tracker::kArmJoints[s][k]);
            for (int f = 0; f < reference_.frames(); ++f)
                series[f] = reference_.frame(f).local[j];
            posture[k] = mean_rotation(series);
        }
        tracker_->set_posture(s, posture);
    }
}

void TrackRun::start_summary()
{
    summary_.mode = to_string(options_.mode);
    // A stick-only capture's own samples, not the default body's two still frames.
    summary_.frames = options_.tip_reference
                          ? static_cast<int>(options_.tip_reference->time_s.size())
                          : reference_.frames();
    summary_.drum_center_m = options_.scene.drum.center_m;
    summary_.drum_rule = !options_.drum_auto         ? "given"
                         : !have_impacts_            ? "lowest_tips"
                         : placement_.at_turnarounds ? "turnarounds"
                                                     : "lowest_tips";
    summary_.drum_through_fraction = have_impacts_ ? placement_.through_fraction : 0.0;
    for (int j = 0; j < nj; ++j)
        summary_.joint_names.push_back(model_.joint_name(j));
    summary_.joint_peak_torque_nm.assign(nj, 0.0);
    summary_.joint_saturated_fraction.assign(nj, 0.0);
}

TrackSummary TrackRun::run()
{
    if (csv_)
        write_csv_header(model_, *csv_);
    long last_progress = -1;
    const auto wall_start = std::chrono::steady_clock::now();
    long n = 0;
    for (; n < steps_; ++n) {
        if (options_.interrupt && *options_.interrupt) {
            summary_.interrupted = true;
            break;
        }
        const double t_next = (n + 1) * h_;
        // Targets for the end of this step, blended in from the initial pose.
        reference_.sample(t_next, ref_pose_);
        blend_pose(initial_, ref_pose_, ramp_weight(t_next, options_.ramp_s), step_pose_);
        if (cartesian_) {
            update_tip_rates(t_next);
            update_tip_positions(t_next);
        }
        tracker_->step(step_pose_, cartesian_ ? &tip_targets_ : nullptr, t_next >= options_.ramp_s);
        if (options_.on_step)
            options_.on_step(scene());
        record_step();
        // Sample on the rate's grid (nearest following step), so that a 120 Hz
        // CSV has 120 rows per second at any physics step.
        const long sample_index = static_cast<long>(std::floor(t_next * sample_rate_ + 1e-9));
        if (sample_index > last_sample_index_) {
            last_sample_index_ = sample_index;
            sample(t_next);
        }
        report_progress(n, last_progress);
    }
    summary_.wall_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    finish_summary(n);
    return summary_;
}

// Algorithm 2. X^T's velocity and acceleration: the stick tips of the (blended)
// reference pose, or of the stick-only capture, by central differences over one
// reference frame (the sampled reference is piecewise linear between frames, so
// per-step differences would be steps and spikes).
void TrackRun::update_tip_rates(double t_next)
{
    const double frame_s =
        tips_in_ ? tips_in_->duration_s() / static_cast<double>(tips_in_->time_s.size() - 1)
                 : 1.0 / reference_.frame_rate_hz();
    if (!(t_next - frame_s >= options_.ramp_s)) {
        tip_targets_.velocity_mps.fill(Eigen::Vector3d::Zero());
        tip_targets_.acceleration_mps2.fill(Eigen::Vector3d::Zero());
        return;
    }
    std::array<Eigen::Vector3d, 2> before, after, now;
    if (tips_in_) {
        for (int s = 0; s < 2; ++s) {
            before[s] = targets_in_->sample(s, t_next - frame_s);
            after[s] = targets_in_->sample(s, t_next + frame_s);
            now[s] = targets_in_->sample(s, t_next);
        }
    } else {
        tip_src_.sample(t_next - frame_s, around_pose_);
        before = reference_tips(model_, around_pose_);
        tip_src_.sample(t_next + frame_s, around_pose_);
        after = reference_tips(model_, around_pose_);
        if (options_.tip_motion) {
            tip_src_.sample(t_next, around_pose_);
            now = reference_tips(model_, around_pose_);
        } else {
            now = reference_tips(model_, ref_pose_);
        }
    }
    for (int s = 0; s < 2; ++s) {
        tip_targets_.velocity_mps[s] = (after[s] - before[s]) / (2.0 * frame_s);
        tip_targets_.acceleration_mps2[s] =
            (after[s] - 2.0 * now[s] + before[s]) / (frame_s * frame_s);
    }
}

// X^T itself: the stick-only capture's, the cleaned tips' or (has_position
// false) the tracker's own forward kinematics of the step's reference pose.
void TrackRun::update_tip_positions(double t_next)
{
    tip_targets_.has_position = tips_in_ != nullptr || options_.tip_motion != nullptr;
    if (tips_in_) {
        for (int s = 0; s < 2; ++s)
            tip_targets_.position_m[s] = targets_in_->sample(s, t_next);
    } else if (options_.tip_motion) {
        // The cleaned tips, blended in from the (ramped) reference's tips
        // like the joint targets: X^T = tips(step pose) + w (tips(tip motion)
        // - tips(reference)).
        const double w = ramp_weight(t_next, options_.ramp_s);
        options_.tip_motion->sample(t_next, tip_pose_);
        const auto cleaned = reference_tips(model_, tip_pose_);
        const auto body = reference_tips(model_, ref_pose_);
        const auto blended = reference_tips(model_, step_pose_);
        for (int s = 0; s < 2; ++s)
            tip_targets_.position_m[s] = blended[s] + w * (cleaned[s] - body[s]);
    }
}

// Every step's statistics: the body's speeds, the stops, the motors' torques.
void TrackRun::record_step()
{
    Scene &sc = scene();
    summary_.max_linear_speed_mps =
        std::max(summary_.max_linear_speed_mps, sc.max_linear_speed_mps());
    summary_.max_angular_speed_rad_s =
        std::max(summary_.max_angular_speed_rad_s, sc.max_angular_speed_rad_s());
    summary_.stop_steps += sc.stops_active_last_step();
    for (int j = 0; j < nj; ++j) {
        summary_.joint_peak_torque_nm[j] =
            std::max(summary_.joint_peak_torque_nm[j], sc.motor_torque(j).norm());
        if (sc.motor_saturated(j))
            summary_.joint_saturated_fraction[j] += 1.0;
    }
}

// One sample: errors against the reference itself (not the ramped or clamped
// target), counted after the ramp, and the CSV row.
void TrackRun::sample(double t_next)
{
    scene().local_rotations(sim_local_);
    std::array<Eigen::Vector3d, 2> ref_tips;
    if (tips_in_) {
        ref_tips = {tips_in_->sample(0, t_next), tips_in_->sample(1, t_next)};
    } else {
        tip_src_.sample(t_next, tip_pose_);
        ref_tips = reference_tips(model_, tip_pose_);
    }
    std::array<Eigen::Vector3d, 2> sim_tips = {scene().tip_position(Side::left),
                                               scene().tip_position(Side::right)};
    if (t_next >= options_.ramp_s)
        count_errors(t_next, ref_tips, sim_tips);
    if (csv_)
        write_csv_row(t_next, ref_tips, sim_tips);
}

void TrackRun::count_errors(double t_next, const std::array<Eigen::Vector3d, 2> &ref_tips,
                            const std::array<Eigen::Vector3d, 2> &sim_tips)
{
    const std::vector<Eigen::Quaterniond> &target = tracker_->targets();
    ++summary_.samples;
    for (int j = 0; j < nj; ++j) {
        const double e = log_map(ref_pose_.local[j] * sim_local_[j].conjugate()).norm() * kRadToDeg;
        sums_.joint_sum2[j] += e * e;
        sums_.joint_max[j] = std::max(sums_.joint_max[j], e);
    }
    bool contact[2] = {false, false};
    for (int s = 0; s < 2; ++s) {
        const double e = (ref_tips[s] - sim_tips[s]).norm() * 1e3;
        sums_.tip_sum2[s] += e * e;
        sums_.tip_max[s] = std::max(sums_.tip_max[s], e);
        const double de = flexion_(s, ref_pose_.local[flexion_.joint[s]]) -
                          flexion_(s, target[flexion_.joint[s]]);
        sums_.elbow_sum2[s] += de * de;
        contact[s] = have_impacts_ &&
                     to_nearest_impact_s(placement_.fit.impacts[s], t_next) <= kContactWindow_s;
        sums_.split_sum2[s][0][contact[s]] += e * e;
        ++sums_.split_n[s][contact[s]];
    }
    if (!(raw_reference_ && !tips_in_))
        return;
    raw_reference_->sample(t_next, raw_pose_);
    const auto raw_tips = reference_tips(model_, raw_pose_);
    for (int s = 0; s < 2; ++s) {
        const double e2 = 1e6 * (raw_tips[s] - sim_tips[s]).squaredNorm();
        sums_.raw_tip_sum2[s] += e2;
        sums_.split_sum2[s][1][contact[s]] += e2;
    }
    for (int j = 0; j < nj; ++j) {
        const double e = log_map(raw_pose_.local[j] * sim_local_[j].conjugate()).norm() * kRadToDeg;
        sums_.raw_joint_sum2 += e * e;
    }
}

void TrackRun::write_csv_row(double t_next, const std::array<Eigen::Vector3d, 2> &ref_tips,
                             const std::array<Eigen::Vector3d, 2> &sim_tips)
{
    const std::vector<Eigen::Quaterniond> &target = tracker_->targets();
    std::ostream &csv = *csv_;
    csv << t_next;
    for (int j = 0; j < nj; ++j) {
        const Eigen::Vector3d r = log_map(ref_pose_.local[j]) * kRadToDeg;
        const Eigen::Vector3d q = log_map(sim_local_[j]) * kRadToDeg;
        const double e = log_map(ref_pose_.local[j] * sim_local_[j].conjugate()).norm() * kRadToDeg;
        csv << ',' << r.x() << ',' << r.y() << ',' << r.z() << ',' << q.x() << ',' << q.y() << ','
            << q.z() << ',' << e;
    }
    for (int s = 0; s < 2; ++s)
        for (const Eigen::Vector3d &p : {ref_tips[s], sim_tips[s]})
            csv << ',' << p.x() << ',' << p.y() << ',' << p.z();
    for (int s = 0; s < 2; ++s) {
        const int elbow = flexion_.joint[s];
        csv << ',' << flexion_(s, ref_pose_.local[elbow]) << ',' << flexion_(s, target[elbow])
            << ',' << flexion_(s, sim_local_[elbow]);
    }
    if (raw_reference_ && !tips_in_) {
        raw_reference_->sample(t_next, raw_pose_);
        const auto raw_tips = reference_tips(model_, raw_pose_);
        for (int s = 0; s < 2; ++s)
            csv << ',' << raw_tips[s].x() << ',' << raw_tips[s].y() << ',' << raw_tips[s].z() << ','
                << flexion_(s, raw_pose_.local[flexion_.joint[s]]);
    } else {
        csv << ",,,,,,,,";
    }
    csv << ',' << scene().contacts_last_step() << '\n';
}

void TrackRun::report_progress(long n, long &last_progress) const
{
    if (!progress_)
        return;
    const long pct = (n + 1) * 100 / steps_;
    if (pct != last_progress) {
        last_progress = pct;
        progress_(static_cast<double>(n + 1) / steps_);
    }
}

// The summary's figures from the sums, after `n` steps.
void TrackRun::finish_summary(long n)
{
    summary_.steps = n;
    for (double &f : summary_.joint_saturated_fraction)
        f /= std::max(1L, n);
    summary_.duration_s = n * h_;
    summary_.realtime_factor =
        summary_.wall_time_s > 0.0 ? summary_.duration_s / summary_.wall_time_s : 0.0;
    const double ns = std::max(1, summary_.samples);
    for (int j = 0; j < nj; ++j) {
        summary_.joint_rms_deg.push_back(std::sqrt(sums_.joint_sum2[j] / ns));
        summary_.joint_max_deg.push_back(sums_.joint_max[j]);
    }
    for (int s = 0; s < 2; ++s) {
        summary_.tip_rms_mm[s] = std::sqrt(sums_.tip_sum2[s] / ns);
        summary_.tip_max_mm[s] = sums_.tip_max[s];
        summary_.tip_rms_raw_mm[s] = std::sqrt(sums_.raw_tip_sum2[s] / ns);
        for (int c = 0; c < 2; ++c) {
            const double m = std::max(1L, sums_.split_n[s][c]);
            (c ? summary_.tip_rms_contact_mm : summary_.tip_rms_free_mm)[s] =
                std::sqrt(sums_.split_sum2[s][0][c] / m);
            (c ? summary_.tip_rms_raw_contact_mm : summary_.tip_rms_raw_free_mm)[s] =
                std::sqrt(sums_.split_sum2[s][1][c] / m);
        }
        summary_.captured_impacts[s] =
            have_impacts_ ? static_cast<int>(placement_.fit.impacts[s].size()) : 0;
    }
    summary_.joint_rms_raw_deg_all = std::sqrt(sums_.raw_joint_sum2 / (ns * nj));
    summary_.raw_measured = raw_reference_ != nullptr && tips_in_ == nullptr;
    if (cartesian_) {
        const TrackerIkStats &ik = tracker_->ik_stats();
        summary_.ik_mean_iterations =
            ik.solves > 0 ? static_cast<double>(ik.iterations) / ik.solves : 0.0;
        summary_.ik_max_iterations = ik.max_iterations;
        summary_.ik_not_converged = ik.not_converged;
        summary_.ik_reseeded = ik.reseeded;
        summary_.ik_us_per_step = n > 0 ? 1e6 * ik.wall_s / n : 0.0;
        for (int s = 0; s < 2; ++s)
            summary_.elbow_ik_rms_deg[s] = std::sqrt(sums_.elbow_sum2[s] / ns);
        summary_.elbow_measured = tips_in_ == nullptr;
    }
    summary_.divergences = scene().divergences();
    summary_.diverged = summary_.divergences > 0;
    summary_.contact_steps = scene().contact_steps();
}

} // namespace

TrackSummary track_joint_space(const CharacterModel &model, const ReferenceMotion &reference,
                               const TrackOptions &options,
                               const std::vector<JointLimitRef> &limits, std::ostream *csv,
                               const ProgressFn &progress, const std::vector<JointGains> *gains,
                               const ReferenceMotion *raw_reference)
{
    TrackRun run(model, reference, options, limits, csv, progress, gains, raw_reference);
    return run.run();
}

} // namespace ictus
