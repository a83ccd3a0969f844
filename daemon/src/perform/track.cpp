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
        throw CharacterError("duration: expected 0 <= s <= 86400, got " +
                             std::to_string(o.duration_s));
    if (!(std::isfinite(o.ramp_s) && o.ramp_s >= 0.0))
        throw CharacterError("ramp: expected a finite value >= 0 s");
    if (!(std::isfinite(o.sample_rate_hz) && o.sample_rate_hz >= 0.0))
        throw CharacterError("sample rate: expected a finite value >= 0 Hz");
    const CartesianOptions &c = o.cartesian;
    if (!(std::isfinite(c.gain) && c.gain > 0.0 && c.gain <= 100.0))
        throw CharacterError("ik gain: expected 0 < gain <= 100, got " + std::to_string(c.gain));
    if (!std::isfinite(c.velocity_gain_s) || c.velocity_gain_s > 1.0)
        throw CharacterError("ik velocity gain: expected a value <= 1 s (< 0: automatic)");
    if (!(std::isfinite(c.acceleration_feedforward_s2) && c.acceleration_feedforward_s2 >= 0.0 &&
          c.acceleration_feedforward_s2 <= 1.0))
        throw CharacterError("ik acceleration feedforward: expected 0 <= s^2 <= 1");
    if (!(std::isfinite(c.correction_limit_m) && c.correction_limit_m >= 0.0))
        throw CharacterError("ik correction limit: expected a finite value >= 0 m");
    if (!(std::isfinite(c.integral_per_s) && c.integral_per_s >= 0.0))
        throw CharacterError("ik integral: expected a finite value >= 0 /s");
    if (!(std::isfinite(c.integral_limit_m) && c.integral_limit_m >= 0.0))
        throw CharacterError("ik integral limit: expected a finite value >= 0 m");
    if (!(std::isfinite(c.posture_weight) && c.posture_weight >= 0.0 && c.posture_weight <= 1.0))
        throw CharacterError("ik posture weight: expected 0 <= w <= 1, got " +
                             std::to_string(c.posture_weight));
    ChainIkSolverPos_dls probe(4);
    if (!probe.set_params(c.ik))
        throw CharacterError("ik parameters: expected finite positive values");
}

nlohmann::json TrackSummary::to_json() const
{
    nlohmann::json j;
    j["mode"] = mode;
    j["frames"] = frames;
    j["samples"] = samples;
    j["steps"] = steps;
    j["duration_s"] = duration_s;
    j["wall_time_s"] = wall_time_s;
    j["realtime_factor"] = realtime_factor;
    j["us_per_step"] = steps > 0 ? 1e6 * wall_time_s / steps : 0.0;
    j["tip_rms_mm"] = {{"left", tip_rms_mm[0]}, {"right", tip_rms_mm[1]}};
    j["tip_rms_raw_mm"] = {{"left", tip_rms_raw_mm[0]}, {"right", tip_rms_raw_mm[1]}};
    j["joint_rms_raw_deg_all"] = joint_rms_raw_deg_all;
    j["tip_max_mm"] = {{"left", tip_max_mm[0]}, {"right", tip_max_mm[1]}};
    j["tip_rms_free_mm"] = {{"left", tip_rms_free_mm[0]}, {"right", tip_rms_free_mm[1]}};
    j["tip_rms_contact_mm"] = {{"left", tip_rms_contact_mm[0]}, {"right", tip_rms_contact_mm[1]}};
    j["tip_rms_raw_free_mm"] = {{"left", tip_rms_raw_free_mm[0]},
                                {"right", tip_rms_raw_free_mm[1]}};
    j["tip_rms_raw_contact_mm"] = {{"left", tip_rms_raw_contact_mm[0]},
                                   {"right", tip_rms_raw_contact_mm[1]}};
    j["captured_impacts"] = {{"left", captured_impacts[0]}, {"right", captured_impacts[1]}};
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
    j["diverged"] = diverged;
    j["interrupted"] = interrupted;
    j["divergences"] = divergences;
    j["max_linear_speed_mps"] = max_linear_speed_mps;
    j["max_angular_speed_rad_s"] = max_angular_speed_rad_s;
    j["contact_steps"] = contact_steps;
    j["stop_steps"] = stop_steps;
    j["drum_center_m"] = {drum_center_m.x(), drum_center_m.y(), drum_center_m.z()};
    j["drum_rule"] = drum_rule;
    j["drum_through_fraction"] = drum_through_fraction;
    if (mode == "cartesian") {
        j["ik"] = {{"mean_iterations", ik_mean_iterations},
                   {"max_iterations", ik_max_iterations},
                   {"us_per_step", ik_us_per_step},
                   {"not_converged", ik_not_converged},
                   {"elbow_flexion_rms_deg", elbow_measured
                                                 ? nlohmann::json{{"left", elbow_ik_rms_deg[0]},
                                                                  {"right", elbow_ik_rms_deg[1]}}
                                                 : nlohmann::json()}};
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

TrackSummary track_joint_space(const CharacterModel &model, const ReferenceMotion &reference,
                               const TrackOptions &options_in,
                               const std::vector<JointLimitRef> &limits, std::ostream *csv,
                               const ProgressFn &progress, const std::vector<JointGains> *gains_in,
                               const ReferenceMotion *raw_reference)
{
    validate(options_in);
    TrackOptions options = options_in;
    const TipTrajectory *tips_in = options.tip_reference;
    if (tips_in) {
        if (options.mode != TrackMode::cartesian)
            throw CharacterError("a stick-only capture needs the Cartesian mode");
        if (tips_in->time_s.size() < 2 || tips_in->tip_m[0].size() != tips_in->time_s.size() ||
            tips_in->tip_m[1].size() != tips_in->time_s.size())
            throw CharacterError("stick capture: expected at least two frames of both tips");
        options.cartesian.reference_has_arms = false;
    }
    // Algorithm 2 literally: the arms are driven by the stick tips alone; the
    // capture's arm rotations seed no IK (its clip-wide mean is the posture).
    if (options.cartesian.start_from_simulated)
        options.cartesian.reference_has_arms = false;
    // The tips the errors are measured against (and the Cartesian mode's X^T):
    // the stick-only capture, else the cleaned tip motion, else the reference.
    const ReferenceMotion &tip_src = options.tip_motion ? *options.tip_motion : reference;
    // The strokes' turnarounds: the drum (--drum auto) and the contact windows.
    // The drum at the turnarounds, for stick-only and full-body captures alike,
    // unless the captured tips pass through it there (a drum kit: strokes for the
    // other drums cross its place); then under the lowest tips (place_drum,
    // docs/mocap.md, "Drum placement").
    DrumFit drum_fit;
    bool have_impacts = true;
    DrumPlacement placement;
    try {
        placement = place_drum(tips_in ? *tips_in : reference_tip_trajectory(model, tip_src),
                               model.options().stick.tip_radius_m, options.scene.drum.radius_m);
        drum_fit = placement.fit;
    } catch (const CharacterError &) {
        if (options.drum_auto && tips_in)
            throw;
        have_impacts = false;
    }
    if (options.drum_auto)
        options.scene.drum.center_m =
            have_impacts ? placement.center_m : auto_drum_center(model, reference);
    // A stick-only capture's impacts restored between its samples (X^T and the errors).
    TipTrajectory restored;
    // X^T asks for more at an impact: the stick's end down to the membrane plane at the
    // vertex (the fitted membrane: kImpactPitchFactor tip radii below it), so that the
    // simulated stick's bead reaches the head whatever its pitch, as the captured one did
    // (docs/ik.md, "Stick-only captures"). The errors stay against the capture.
    TipTrajectory pressed;
    const TipTrajectory *targets_in = tips_in;
    if (tips_in && have_impacts) {
        restored = with_impact_vertices(*tips_in, drum_fit.impacts);
        // ... and a little deeper, by the dent a strike at the captured speed makes
        // in the simulated membrane (impact_press_depth_m): the tracked end rounds
        // the V off by millimetres, and with the end asked to the contact height
        // alone a third to all of the impacts at 120 Hz went unstruck.
        std::array<std::vector<StrokeTurnaround>, 2> at_membrane = drum_fit.impacts;
        const double r_tip = model.options().stick.tip_radius_m;
        for (auto &side : at_membrane)
            for (StrokeTurnaround &ta : side)
                ta.position_m.y() -=
                    kImpactPitchFactor * r_tip +
                    impact_press_depth_m(ta.speed_in_mps, model.options().stick.mass_kg,
                                         options.scene.drum.stiffness_n_per_m(r_tip));
        pressed = with_impact_vertices(*tips_in, at_membrane);
        tips_in = &restored;
        targets_in = &pressed;
    }
    const double h = options.scene.step_s;
    const double duration = options.duration_s > 0.0 ? options.duration_s
                            : tips_in                ? tips_in->duration_s()
                                                     : reference.duration_s();
    const long steps = std::max(1L, std::lround(duration / h));
    const double sample_rate =
        options.sample_rate_hz > 0.0 ? options.sample_rate_hz : reference.frame_rate_hz();
    long last_sample_index = 0;

    CharacterPose initial = reference.frame(0);
    if (tips_in) {
        // The arms' first pose: a cold IK solve to the first tips from a drummer's
        // arms (drummer_arms), not from the reference's (the default body's T-pose):
        // from the T-pose the solve ended in a pose whose first impacts threw the
        // sticks sideways (6.7 m/s strokes: 21 and 20 mm in the first two strokes'
        // free flight, 2.5 after; docs/ik.md, "Stick-only captures").
        drummer_arms(model, initial);
        Tracker::solve_arms(model, limits, options.cartesian.ik,
                            {tips_in->tip_m[0][0], tips_in->tip_m[1][0]}, initial);
    }
    const std::vector<JointGains> gains =
        gains_in ? *gains_in : default_gains(model, initial, options.gains);
    Tracker tracker(model, options.scene, initial, gains, limits, options.mode, options.cartesian,
                    options.gains);
    Scene &scene = tracker.scene();
    // The posture of the IK's null-space task: a full-body capture's mean arm
    // pose over the clip (the centre of the learned limits, Algorithm 1's
    // mean), a stick-only capture's first (cold-solved) arms.
    if (!tips_in && reference.frames() > 0)
        for (int s = 0; s < 2; ++s) {
            Eigen::Quaterniond posture[4];
            std::vector<Eigen::Quaterniond> series(reference.frames());
            for (int k = 0; k < 4; ++k) {
                const int j = model.joint_index(Tracker::kArmJoints[s][k]);
                for (int f = 0; f < reference.frames(); ++f)
                    series[f] = reference.frame(f).local[j];
                posture[k] = mean_rotation(series);
            }
            tracker.set_posture(s, posture);
        }

    const int nj = CharacterModel::kJoints;
    const bool cartesian = options.mode == TrackMode::cartesian;
    double elbow_sum2[2] = {0.0, 0.0};
    CharacterPose around_pose, tip_pose;
    Eigen::Vector3d upper_arm_axis[2], forearm_axis[2];
    int elbow_joint[2];
    for (int s = 0; s < 2; ++s) {
        elbow_joint[s] = model.joint_index(Tracker::kArmJoints[s][2]);
        upper_arm_axis[s] = model.joint_body(elbow_joint[s]).offset_m;
        forearm_axis[s] = model.joint_body(model.joint_index(Tracker::kArmJoints[s][3])).offset_m;
    }
    const auto flexion = [&](int s, const Eigen::Quaterniond &q) {
        return elbow_flexion_deg(upper_arm_axis[s], forearm_axis[s], q);
    };
    double split_sum2[2][2][2] = {}; // [side][raw?][contact?]
    long split_n[2][2] = {};         // [side][contact?]

    TrackSummary summary;
    summary.mode = to_string(options.mode);
    summary.frames = reference.frames();
    summary.drum_center_m = options.scene.drum.center_m;
    summary.drum_rule = !options.drum_auto         ? "given"
                        : !have_impacts            ? "lowest_tips"
                        : placement.at_turnarounds ? "turnarounds"
                                                   : "lowest_tips";
    summary.drum_through_fraction = have_impacts ? placement.through_fraction : 0.0;
    for (int j = 0; j < nj; ++j)
        summary.joint_names.push_back(model.joint_name(j));
    std::vector<double> joint_sum2(nj, 0.0), joint_max(nj, 0.0);
    summary.joint_peak_torque_nm.assign(nj, 0.0);
    summary.joint_saturated_fraction.assign(nj, 0.0);
    double tip_sum2[2] = {0, 0}, tip_max[2] = {0, 0}, raw_tip_sum2[2] = {0, 0};
    double raw_joint_sum2 = 0.0;
    CharacterPose raw_pose;

    if (csv) {
        *csv << "time_s";
        for (int j = 0; j < nj; ++j) {
            const std::string &n = model.joint_name(j);
            for (const char *what : {"ref", "sim"})
                for (const char *axis : {"x", "y", "z"})
                    *csv << ',' << n << '_' << what << '_' << axis << "_deg";
            *csv << ',' << n << "_err_deg";
        }
        for (const char *side : {"left", "right"})
            for (const char *what : {"ref", "sim"})
                for (const char *axis : {"x", "y", "z"})
                    *csv << ",tip_" << side << '_' << what << '_' << axis << "_m";
        // Elbow flexion (the angle between upper arm and forearm, deg): cleaned
        // capture, PD target (joint mode: the capture; Cartesian mode: Theta^T from
        // IK), simulation. Then the raw capture's tips and elbow flexion.
        for (const char *side : {"l", "r"})
            for (const char *what : {"ref", "target", "sim"})
                *csv << ',' << side << "_elbow_flexion_" << what << "_deg";
        for (const char *side : {"left", "right"}) {
            for (const char *axis : {"x", "y", "z"})
                *csv << ",tip_" << side << "_raw_" << axis << "_m";
            *csv << ',' << side[0] << "_elbow_flexion_raw_deg";
        }
        *csv << ",contacts\n";
    }

    CharacterPose ref_pose, step_pose = initial;
    std::vector<Eigen::Quaterniond> sim_local;
    TipTargets tip_targets;
    long last_progress = -1;
    const auto wall_start = std::chrono::steady_clock::now();

    long n = 0;
    for (; n < steps; ++n) {
        if (options.interrupt && *options.interrupt) {
            summary.interrupted = true;
            break;
        }
        const double t_next = (n + 1) * h;
        // Targets for the end of this step, blended in from the initial pose.
        reference.sample(t_next, ref_pose);
        blend_pose(initial, ref_pose, ramp_weight(t_next, options.ramp_s), step_pose);
        if (cartesian) {
            // Algorithm 2. X^T: the stick tips of the (blended) reference pose,
            // or of the stick-only capture.
            // Reference tip velocity and acceleration by central differences over
            // one reference frame (the sampled reference is piecewise linear
            // between frames, so per-step differences would be steps and spikes).
            const double frame_s =
                tips_in ? tips_in->duration_s() / static_cast<double>(tips_in->time_s.size() - 1)
                        : 1.0 / reference.frame_rate_hz();
            if (t_next - frame_s >= options.ramp_s) {
                std::array<Eigen::Vector3d, 2> before, after, now;
                if (tips_in) {
                    for (int s = 0; s < 2; ++s) {
                        before[s] = targets_in->sample(s, t_next - frame_s);
                        after[s] = targets_in->sample(s, t_next + frame_s);
                        now[s] = targets_in->sample(s, t_next);
                    }
                } else {
                    tip_src.sample(t_next - frame_s, around_pose);
                    before = reference_tips(model, around_pose);
                    tip_src.sample(t_next + frame_s, around_pose);
                    after = reference_tips(model, around_pose);
                    if (options.tip_motion) {
                        tip_src.sample(t_next, around_pose);
                        now = reference_tips(model, around_pose);
                    } else {
                        now = reference_tips(model, ref_pose);
                    }
                }
                for (int s = 0; s < 2; ++s) {
                    tip_targets.velocity_mps[s] = (after[s] - before[s]) / (2.0 * frame_s);
                    tip_targets.acceleration_mps2[s] =
                        (after[s] - 2.0 * now[s] + before[s]) / (frame_s * frame_s);
                }
            } else {
                tip_targets.velocity_mps.fill(Eigen::Vector3d::Zero());
                tip_targets.acceleration_mps2.fill(Eigen::Vector3d::Zero());
            }
            tip_targets.has_position = tips_in != nullptr || options.tip_motion != nullptr;
            if (tips_in) {
                for (int s = 0; s < 2; ++s)
                    tip_targets.position_m[s] = targets_in->sample(s, t_next);
            } else if (options.tip_motion) {
                // The cleaned tips, blended in from the (ramped) reference's tips
                // like the joint targets: X^T = tips(step pose) + w (tips(tip motion)
                // - tips(reference)).
                const double w = ramp_weight(t_next, options.ramp_s);
                options.tip_motion->sample(t_next, tip_pose);
                const auto cleaned = reference_tips(model, tip_pose);
                const auto body = reference_tips(model, ref_pose);
                const auto blended = reference_tips(model, step_pose);
                for (int s = 0; s < 2; ++s)
                    tip_targets.position_m[s] = blended[s] + w * (cleaned[s] - body[s]);
            }
        }
        tracker.step(step_pose, cartesian ? &tip_targets : nullptr, t_next >= options.ramp_s);
        if (options.on_step)
            options.on_step(scene);
        const std::vector<Eigen::Quaterniond> &target = tracker.targets();
        summary.max_linear_speed_mps =
            std::max(summary.max_linear_speed_mps, scene.max_linear_speed_mps());
        summary.max_angular_speed_rad_s =
            std::max(summary.max_angular_speed_rad_s, scene.max_angular_speed_rad_s());
        summary.stop_steps += scene.stops_active_last_step();
        for (int j = 0; j < nj; ++j) {
            summary.joint_peak_torque_nm[j] =
                std::max(summary.joint_peak_torque_nm[j], scene.motor_torque(j).norm());
            if (scene.motor_saturated(j))
                summary.joint_saturated_fraction[j] += 1.0;
        }

        // Sample on the rate's grid (nearest following step), so that a 120 Hz
        // CSV has 120 rows per second at any physics step.
        const long sample_index = static_cast<long>(std::floor(t_next * sample_rate + 1e-9));
        if (sample_index > last_sample_index) {
            last_sample_index = sample_index;
            // Errors against the reference itself (not the ramped or clamped target).
            scene.local_rotations(sim_local);
            std::array<Eigen::Vector3d, 2> ref_tips;
            if (tips_in) {
                ref_tips = {tips_in->sample(0, t_next), tips_in->sample(1, t_next)};
            } else {
                tip_src.sample(t_next, tip_pose);
                ref_tips = reference_tips(model, tip_pose);
            }
            std::array<Eigen::Vector3d, 2> sim_tips = {scene.tip_position(Side::left),
                                                       scene.tip_position(Side::right)};
            const bool counted = t_next >= options.ramp_s;
            if (counted) {
                ++summary.samples;
                for (int j = 0; j < nj; ++j) {
                    const double e =
                        log_map(ref_pose.local[j] * sim_local[j].conjugate()).norm() * kRadToDeg;
                    joint_sum2[j] += e * e;
                    joint_max[j] = std::max(joint_max[j], e);
                }
                bool contact[2] = {false, false};
                for (int s = 0; s < 2; ++s) {
                    const double e = (ref_tips[s] - sim_tips[s]).norm() * 1e3;
                    tip_sum2[s] += e * e;
                    tip_max[s] = std::max(tip_max[s], e);
                    const double de = flexion(s, ref_pose.local[elbow_joint[s]]) -
                                      flexion(s, target[elbow_joint[s]]);
                    elbow_sum2[s] += de * de;
                    contact[s] = have_impacts && to_nearest_impact_s(drum_fit.impacts[s], t_next) <=
                                                     kContactWindow_s;
                    split_sum2[s][0][contact[s]] += e * e;
                    ++split_n[s][contact[s]];
                }
                if (raw_reference && !tips_in) {
                    raw_reference->sample(t_next, raw_pose);
                    const auto raw_tips = reference_tips(model, raw_pose);
                    for (int s = 0; s < 2; ++s) {
                        const double e2 = 1e6 * (raw_tips[s] - sim_tips[s]).squaredNorm();
                        raw_tip_sum2[s] += e2;
                        split_sum2[s][1][contact[s]] += e2;
                    }
                    for (int j = 0; j < nj; ++j) {
                        const double e =
                            log_map(raw_pose.local[j] * sim_local[j].conjugate()).norm() *
                            kRadToDeg;
                        raw_joint_sum2 += e * e;
                    }
                }
            }
            if (csv) {
                *csv << t_next;
                for (int j = 0; j < nj; ++j) {
                    const Eigen::Vector3d r = log_map(ref_pose.local[j]) * kRadToDeg;
                    const Eigen::Vector3d q = log_map(sim_local[j]) * kRadToDeg;
                    const double e =
                        log_map(ref_pose.local[j] * sim_local[j].conjugate()).norm() * kRadToDeg;
                    *csv << ',' << r.x() << ',' << r.y() << ',' << r.z() << ',' << q.x() << ','
                         << q.y() << ',' << q.z() << ',' << e;
                }
                for (int s = 0; s < 2; ++s)
                    for (const Eigen::Vector3d &p : {ref_tips[s], sim_tips[s]})
                        *csv << ',' << p.x() << ',' << p.y() << ',' << p.z();
                for (int s = 0; s < 2; ++s) {
                    const int elbow = elbow_joint[s];
                    *csv << ',' << flexion(s, ref_pose.local[elbow]) << ','
                         << flexion(s, target[elbow]) << ',' << flexion(s, sim_local[elbow]);
                }
                if (raw_reference && !tips_in) {
                    raw_reference->sample(t_next, raw_pose);
                    const auto raw_tips = reference_tips(model, raw_pose);
                    for (int s = 0; s < 2; ++s)
                        *csv << ',' << raw_tips[s].x() << ',' << raw_tips[s].y() << ','
                             << raw_tips[s].z() << ','
                             << flexion(s, raw_pose.local[elbow_joint[s]]);
                } else {
                    *csv << ",,,,,,,,";
                }
                *csv << ',' << scene.contacts_last_step() << '\n';
            }
        }
        if (progress) {
            const long pct = (n + 1) * 100 / steps;
            if (pct != last_progress) {
                last_progress = pct;
                progress(static_cast<double>(n + 1) / steps);
            }
        }
    }
    summary.wall_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    summary.steps = n;
    for (double &f : summary.joint_saturated_fraction)
        f /= std::max(1L, n);
    summary.duration_s = n * h;
    summary.realtime_factor =
        summary.wall_time_s > 0.0 ? summary.duration_s / summary.wall_time_s : 0.0;
    const double ns = std::max(1, summary.samples);
    for (int j = 0; j < nj; ++j) {
        summary.joint_rms_deg.push_back(std::sqrt(joint_sum2[j] / ns));
        summary.joint_max_deg.push_back(joint_max[j]);
    }
    for (int s = 0; s < 2; ++s) {
        summary.tip_rms_mm[s] = std::sqrt(tip_sum2[s] / ns);
        summary.tip_max_mm[s] = tip_max[s];
        summary.tip_rms_raw_mm[s] = std::sqrt(raw_tip_sum2[s] / ns);
        for (int c = 0; c < 2; ++c) {
            const double m = std::max(1L, split_n[s][c]);
            (c ? summary.tip_rms_contact_mm : summary.tip_rms_free_mm)[s] =
                std::sqrt(split_sum2[s][0][c] / m);
            (c ? summary.tip_rms_raw_contact_mm : summary.tip_rms_raw_free_mm)[s] =
                std::sqrt(split_sum2[s][1][c] / m);
        }
        summary.captured_impacts[s] =
            have_impacts ? static_cast<int>(drum_fit.impacts[s].size()) : 0;
    }
    summary.joint_rms_raw_deg_all = std::sqrt(raw_joint_sum2 / (ns * nj));
    if (cartesian) {
        const TrackerIkStats &ik = tracker.ik_stats();
        summary.ik_mean_iterations =
            ik.solves > 0 ? static_cast<double>(ik.iterations) / ik.solves : 0.0;
        summary.ik_max_iterations = ik.max_iterations;
        summary.ik_not_converged = ik.not_converged;
        summary.ik_us_per_step = n > 0 ? 1e6 * ik.wall_s / n : 0.0;
        for (int s = 0; s < 2; ++s)
            summary.elbow_ik_rms_deg[s] = std::sqrt(elbow_sum2[s] / ns);
        summary.elbow_measured = tips_in == nullptr;
    }
    summary.divergences = scene.divergences();
    summary.diverged = summary.divergences > 0;
    summary.contact_steps = scene.contact_steps();
    return summary;
}

} // namespace ictus
