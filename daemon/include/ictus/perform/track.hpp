// track.hpp -- joint-space tracking of a reference motion (the paper's ID mode,
// eq. 1): the headless run behind `ictusd track --mode joint`. Writes, if
// asked, a CSV of reference vs simulated joint rotations and stick tips, and
// returns a summary (tip and joint RMS errors, real-time factor, divergences).
#pragma once

#include "ictus/character/character.hpp"
#include "ictus/character/stick_capture.hpp"
#include "ictus/control/joint_controller.hpp"
#include "ictus/perform/tracker.hpp"
#include "ictus/sim/scene.hpp"

#include <csignal>
#include <functional>
#include <iosfwd>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace ictus
{

// `ictusd track`'s Cartesian settings: Algorithm 2 as the paper states it, the
// feedback IK started from the simulated state every step, with the posture
// task holding the arm's null space (docs/ik.md). (The score performance keeps
// CartesianOptions' own defaults.)
CartesianOptions track_cartesian_defaults();

// `ictusd track`'s scene: SceneOptions' own, with the pelvis a kinematic body
// (SceneOptions::pelvis_kinematic) instead of welded: the same fixed pelvis
// without the weld's six rows in QuickStep (docs/benchmarks.md).
SceneOptions track_scene_defaults();

// The reference clean-up of `ictusd track` and `ictusd limits`: one-frame
// spikes over 5 degrees replaced, then the zero-phase Butterworth low-pass at
// 10 Hz (flat through a drummer's 4-8 Hz strokes; the Gaussian at the same
// cutoff rounded the strokes' turnarounds off by 21-25 mm, docs/mocap.md).
// ReferenceFilter's own default (the Gaussian) is the score performance's.
ReferenceFilter track_reference_filter();

struct TrackOptions {
    TrackMode mode = TrackMode::joint;
    CartesianOptions cartesian = track_cartesian_defaults();
    SceneOptions scene = track_scene_defaults();
    GainOptions gains;
    // Simulated time; 0 means the reference's length (longer runs play it
    // back and forth).
    double duration_s = 0.0;
    // Targets are blended from the initial pose over this time (a step in the
    // targets at start-up jolts the trunk, ode-findings.md); errors are not
    // counted during it.
    double ramp_s = 0.25;
    // Place the drum automatically (else scene.drum.center_m): at the strokes'
    // turnarounds, for stick-only and full-body captures alike, unless the captured
    // tips pass through a drum there (then under the lowest tips; place_drum,
    // docs/mocap.md, "Drum placement"). The turnarounds of the tips the errors are
    // measured against give the contact windows in either case.
    bool drum_auto = true;
    // The cleaned capture for the stick tips (full-body captures): the Cartesian mode's
    // X^T and both modes' tip errors are the stick tips of this motion (else the
    // reference's). The reference (joint targets) may be smoothed more than this.
    const ReferenceMotion *tip_motion = nullptr;
    // CSV rows per second of simulated time; 0: the reference's frame rate.
    double sample_rate_hz = 0.0;
    // Stick-only capture (Cartesian mode only): the tip targets and the
    // errors come from it instead of the reference's stick tips; the
    // reference then only holds the trunk and legs, the arms start from a cold
    // IK solve to the first tips, and drum_auto fits the drum to its strokes.
    const TipTrajectory *tip_reference = nullptr;
    // Checked every step; when it becomes non-zero the run stops early (SIGINT).
    const volatile std::sig_atomic_t *interrupt = nullptr;
    // Called on the calling thread after every physics step, the ramp
    // included (e.g. the strike detector behind `ictusd track`'s strikes.csv).
    std::function<void(const Scene &)> on_step;
};
// Throws PerformError naming the first bad option (the scene's options: the
// scene's own error).
void validate(const TrackOptions &options);

struct TrackSummary {
    std::string mode = "joint";
    int frames = 0;  // the capture's frames (a stick-only capture's samples)
    int samples = 0; // rows measured (and written to the CSV)
    long steps = 0;
    double duration_s = 0.0;
    double wall_time_s = 0.0;
    double realtime_factor = 0.0;
    double tip_rms_mm[2] = {0.0, 0.0}; // left, right
    double tip_max_mm[2] = {0.0, 0.0};
    // Against the unfiltered capture, when given (includes what the filter
    // removed: spikes and jitter no torque-limited body follows).
    double tip_rms_raw_mm[2] = {0.0, 0.0};
    // The same RMS errors split by time: within kContactWindow_s of a captured
    // impact of that stick (contact) and the rest (free flight); impacts are the
    // drum fit's (fit_drum_to_turnarounds on the cleaned tips).
    double tip_rms_free_mm[2] = {0.0, 0.0}, tip_rms_contact_mm[2] = {0.0, 0.0};
    double tip_rms_raw_free_mm[2] = {0.0, 0.0}, tip_rms_raw_contact_mm[2] = {0.0, 0.0};
    int captured_impacts[2] = {0, 0};
    double joint_rms_raw_deg_all = 0.0;
    // The *_raw_* errors were measured: an unfiltered full-body capture was given.
    // Not measured (null in JSON) for stick-only captures, or without one.
    bool raw_measured = false;
    std::vector<std::string> joint_names;
    std::vector<double> joint_rms_deg;
    std::vector<double> joint_max_deg;
    std::vector<double> joint_peak_torque_nm;     // largest motor torque seen (norm)
    std::vector<double> joint_saturated_fraction; // of steps with an axis at its limit
    bool diverged = false;
    bool interrupted = false;
    int divergences = 0;
    double max_linear_speed_mps = 0.0;
    double max_angular_speed_rad_s = 0.0;
    long contact_steps = 0;
    long stop_steps = 0; // joint-steps during which a safety-net stop was active
    Eigen::Vector3d drum_center_m = Eigen::Vector3d::Zero();
    // How the drum was placed: "turnarounds" (--drum auto at the strokes'
    // turnarounds), "lowest_tips" (--drum auto, the tips pass through a drum
    // there or have no strokes) or "given"; the fraction of samples of the
    // more affected stick inside the drum at the turnarounds (place_drum).
    std::string drum_rule = "given";
    double drum_through_fraction = 0.0;
    // Cartesian mode: IK statistics over all arm solves (two per step).
    double ik_mean_iterations = 0.0;
    int ik_max_iterations = 0;
    double ik_us_per_step = 0.0; // wall time of the IK (both arms, both solves)
    long ik_not_converged = 0;   // solves that ended other than `converged`
    long ik_reseeded = 0;        // stuck kinematic solves taken again from the posture
    // Elbow flexion (elbow_flexion_deg: the angle between upper arm and forearm), IK target
    // Theta^T vs the capture, RMS over the samples [side], degrees.
    // Not measured (null in JSON) for stick-only captures: no captured elbow.
    double elbow_ik_rms_deg[2] = {0.0, 0.0};
    bool elbow_measured = true;
    nlohmann::json to_json() const;
};

// The reference stick tips [side] at the reference's frame f.
std::array<Eigen::Vector3d, 2> reference_tips(const CharacterModel &model,
                                              const CharacterPose &pose);

// A drum centre under the lowest reference tips: x, z the mean of the two
// tips at their lowest, y half a tip radius below the lower of them. (The score
// performance's clip mode; `ictusd track` fits the turnarounds instead.)
Eigen::Vector3d auto_drum_center(const CharacterModel &model, const ReferenceMotion &reference);

// The arms of `pose` as a drummer holds them at rest: each upper arm hanging,
// kDrummerArmOut_rad out from the vertical, the forearm forward (the body's
// forward: its left x up). The seed of a stick-only capture's cold arm solve.
constexpr double kDrummerArmOut_rad = 10.0 * M_PI / 180.0;
void drummer_arms(const CharacterModel &model, CharacterPose &pose);

// The stick tips of every frame of `reference` as a trajectory (for the drum fit).
TipTrajectory reference_tip_trajectory(const CharacterModel &model,
                                       const ReferenceMotion &reference);

// Half-width of a contact window about a captured impact, s.
constexpr double kContactWindow_s = 0.03;

// Elbow flexion proper, degrees: the angle between the upper arm's axis and the
// forearm's (0 straight), from the elbow's local rotation `elbow` and the two
// segments' directions in their own bodies' frames; the forearm's twist about
// its axis does not count.
double elbow_flexion_deg(const Eigen::Vector3d &upper_arm_axis, const Eigen::Vector3d &forearm_axis,
                         const Eigen::Quaterniond &elbow);

using ProgressFn = std::function<void(double fraction)>;

// Runs the tracking of `reference` in options.mode (errors are measured against it, and also
// against `raw_reference` when given). `limits` as Scene::set_joint_limits (empty: none). When
// csv is given, writes a header and one row per sample. Throws PerformError (bad options or
// input), and what the areas below throw (the drum fit, the scene, the gains).
TrackSummary track_joint_space(const CharacterModel &model, const ReferenceMotion &reference,
                               const TrackOptions &options,
                               const std::vector<JointLimitRef> &limits = {},
                               std::ostream *csv = nullptr, const ProgressFn &progress = {},
                               const std::vector<JointGains> *gains = nullptr,
                               const ReferenceMotion *raw_reference = nullptr);

} // namespace ictus
