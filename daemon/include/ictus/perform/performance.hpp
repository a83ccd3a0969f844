// performance.hpp -- the physics side of `ictusd run` (real time) and `ictusd
// render` (offline): the character playing the drum, one physics step at a
// time, with the commands Pd may send applied between steps. Two motion
// sources: a mocap clip in joint space (paper eq. 1, as `ictusd track`), or a
// score performed through its gesture plan (stick-tip targets, Cartesian mode
// by default, on the default body). Strikes come from the interaction manager
// (sim/strike_detector.hpp). No network and no files here: the verbs in cli/
// own those. See docs/perform.md and docs/osc.md.
#pragma once

#include "ictus/character/character.hpp"
#include "ictus/mocap/bvh.hpp"
#include "ictus/gesture/gesture.hpp"
#include "ictus/score/gesture_score.hpp"
#include "ictus/control/joint_controller.hpp"
#include "ictus/perform/commands.hpp"
#include "ictus/sim/scene.hpp"
#include "ictus/score/score.hpp"
#include "ictus/sim/strike_detector.hpp"
#include "ictus/perform/track.hpp"
#include "ictus/perform/tracker.hpp"

#include <memory>
#include <string>
#include <vector>

namespace ictus
{

// Score mode: how a gesture plan is performed (docs/perform.md, where the
// defaults are measured).
struct ScorePerformOptions {
    std::string score_text; // the score; empty: default_score_text()
    std::string score_name = "default";
    std::string gestures; // gesture database JSON; empty: GestureDatabase::builtin()
    TrackMode mode = TrackMode::cartesian;
    bool grip_given = false; // else the character holds the sticks as the score's first note
    PlanOptions plan;        // strike_depth_m below: the default here
    // The tip targets are sampled this far ahead of the plan's clock: the
    // controller's measured tracking lag (docs/perform.md), so that the
    // physical tip, not the target, meets the membrane on the beat.
    double time_advance_s = 0.0;
    CartesianOptions cartesian;
    // A scripted rebound (off by default: the stick rebounds by itself on its
    // fulcrum): after each beat the target gets an upward offset leaving the
    // head at the impact speed, caught with this time constant, s
    // (docs/perform.md, "Scripted rebound").
    double rebound_s = 0.0;
    // The drum relative to the performer (derived from the model's shoulders,
    // facing +Z): membrane centre this far in front of and below the
    // midpoint of the shoulders.
    double drum_forward_m = 0.42;
    double drum_below_m = 0.42;
    // The arms' IK keeps its solutions this far (deg) inside the range of
    // motion on every side; the scene's stops and the excursion measured
    // stay at the true limits (docs/perform.md, "Joint limits").
    double ik_limit_margin_deg = 3.0;
    ScorePerformOptions();
};

struct PerformanceOptions {
    std::string mocap; // BVH with CMU joint names; empty: score mode
    double scale_m_per_unit = kCmuBvhScale_m;
    int skip_frames = 1;
    CharacterOptions character;
    SceneOptions scene;
    GainOptions gains;
    bool drum_auto = true; // clip: where its fast strokes turn around; score: before the shoulders
    double ramp_s = 0.25;
    double clip_bpm = 120.0; // tempo at which the clip plays at its own speed
    double tempo_bpm = 120.0;
    double drum_density_kg_per_m2 = 0.26; // for the sound only (membrane~)
    StrikeDetectorOptions strikes;
    ScorePerformOptions score; // score mode (no mocap)
    // The grip's firmness 0..1 (Scene's grip_spring()): the notes' default,
    // changed live by /ictus/grip/firmness; a note may give its own.
    double grip_firmness = kDefaultGripFirmness;
    PerformanceOptions(); // the sticks on their fulcrum (SceneOptions::sticks)
};

// How the strikes of a performance met its planned notes: per hand, each
// primary (non-bounce) strike is given to the nearest note of that hand; a
// note keeps the nearest of the strikes given to it (the others are extra).
struct NoteMatch {
    long strike_seq = -1; // -1: no strike for this note
    double strike_time_s = 0.0;
    double error_ms = 0.0; // strike - beat
    double normal_velocity_mps = 0.0;
    double duration_ms = 0.0;
};
struct MatchSummary {
    std::vector<NoteMatch> notes; // [note], as the plan's notes
    long primary_strikes = 0, bounces = 0;
    long matched_notes = 0;
    long extra_strikes = 0; // primary strikes not matched to a note
    double mean_abs_error_ms = 0.0, max_abs_error_ms = 0.0;
};
// `origin_s`: simulation time of the plan's time 0.
MatchSummary match_strikes(const std::vector<PlannedNote> &notes,
                           const std::vector<StrikeEvent> &strikes, double origin_s);

// The physics side of run and render: the character tracking the clip or
// performing a score, the drum, the strike detector, and the commands Pd may send.
class Performance
{
  public:
    explicit Performance(const PerformanceOptions &options); // throws on bad file/options
    ~Performance();

    // One physics step; returns the number of strikes ended in it (<= 2),
    // written to out[0..n).
    int step(StrikeEvent out[2]);
    // The strikes whose contact began in the last step (<= 2), at their
    // onset: what a sound needs (time, hand, position, velocity), without
    // force, impulse and duration, which step() reports at the release
    // (docs/osc.md: `ictusd run` sends the one at once, the rest after).
    int take_onsets(StrikeEvent out[2]);
    // Ends contacts still open (end of a run).
    bool flush(StrikeEvent &out) { return detector_.flush(out); }
    // Applies a command from the OSC thread. Returns false with a reason when
    // it cannot be applied (the OSC thread has already validated the values).
    bool apply(const Command &command, std::string *why = nullptr);

    void pose(PoseSnapshot &out) const;
    void tip(int hand, TipState &out) const;
    double time_s() const;
    // The clip's length at the current tempo, s.
    double clip_duration_s() const;
    double step_s() const { return options_.scene.step_s; }
    bool playing() const { return playing_; }
    // Clip: the playback tempo. Score mode: the tempo being played (the
    // score's tempo map at the plan's clock, times the live scale), and
    // stopped, the tempo the next play starts at (/ictus/tempo, docs/osc.md).
    double tempo_bpm() const;
    // Score mode: the live tempo scale (/ictus/tempo), 1 until one is sent;
    // a new score (/ictus/score/clear) plays at its own tempi again.
    double tempo_scale() const { return tempo_scale_; }
    // A live tempo change under way leaves alone the strokes the hands have
    // begun, and those they begin within this time (the planner's latency).
    static constexpr double kTempoLatency_s = 0.25;
    const PerformanceOptions &options() const { return options_; }
    const Scene &scene() const;
    // The character being simulated and the mocap skeleton it was built from
    // (score mode: default_skeleton()), for recording the performance as BVH.
    const CharacterModel &model() const;
    const Skeleton &skeleton() const { return skeleton_; }
    const StrikeDetector &detector() const { return detector_; }
    int divergences() const;

    // How the body moved (score mode, since the last rig was installed): how
    // far any joint went outside its range of motion (the simulated pose:
    // range_of_motion.hpp), and how far the trunk (thorax) turned from its
    // rest, degrees.
    struct BodyStats {
        double max_limit_excursion_deg = 0.0;
        std::string max_limit_joint;
        long steps = 0;
        double trunk_max_deg = 0.0;
        double trunk_sum_sq_deg2 = 0.0;
        double trunk_rms_deg() const;
    };
    const BodyStats &body_stats() const { return body_stats_; }

    // Score mode.
    bool score_mode() const { return options_.mocap.empty(); }
    // The plan being performed (or last performed); nullptr before the first.
    const GesturePlan *plan() const { return plan_; }
    bool plan_active() const { return plan_active_; }
    // Simulation time of the plan's time 0, and the plan's clock.
    double plan_origin_s() const { return plan_origin_s_; }
    double plan_time_s() const { return plan_time_s_; }
    // The tip target X^T the controller was given in the last step [hand].
    Eigen::Vector3d tip_target(int hand) const;
    Eigen::Vector3d tip_position(int hand) const;
    const PerformerFrame &performer_frame() const;
    TrackMode mode() const;
    // The planned target's speed toward the head as it reaches the contact,
    // per note of plan() (m/s).
    double planned_impact_speed_mps(size_t note) const;
    // Plans the current score and starts it now (what /ictus/play does in
    // score mode). Throws ScoreError / GestureError; on error nothing changes.
    void start_score();

    // Background work. Finishing and planning a score and rebuilding the
    // character (a grip change; a clip after one) can take 100 ms or more.
    // With background work on (`ictusd run`), apply() hands them to a worker
    // thread of the performance and returns at once; the result is handed
    // over whole at the start of a later step, and the physics loop never
    // waits for it. Off (the default: render, tests), they run inside
    // apply(), deterministically. A drum change never rebuilds: the live
    // scene takes it at once, and a plan under way is planned again.
    void set_background_work(bool on);
    bool background_work() const { return worker_ != nullptr; }
    // Whether work handed to the worker has not come back yet.
    bool work_pending() const;
    // Refusals found after apply() returned (a score that fails to plan in
    // the background, the runaway guard), oldest first, each naming the
    // command's peer and address (Command's peer fields).
    bool pop_refusal(Refusal &out);

    // The runaway guard (docs/perform.md): a stick tip faster than this is
    // no human stroke but a controller gone unstable (the built-in strokes
    // peak at 10-18 m/s with the default gains, up to 27 m/s with stiff,
    // lightly damped ones; a controller past its stability bound reached
    // 54 m/s). The guard then puts
    // the gains back to their defaults, sends no strike for
    // kRunawayQuiet_s, counts it and reports it as a refusal of the last
    // /ictus/gains command.
    // The grip of a buzz note that gives none (docs/perform.md, "Buzz").
    static constexpr double kBuzzGripFirmness = 0.0;
    // A down stroke (drumming pedagogy: a stroke that stops the stick low,
    // for a soft note next): a stroke whose next note of the same hand comes
    // within kDownStrokeGap_s and hits at under kDownStrokeRatio of its
    // planned speed is held with this firmness from its strike to that next
    // beat, unless either note gives its own grip (docs/perform.md).
    static constexpr double kDownStrokeGripFirmness = 0.8;
    static constexpr double kDownStrokeGap_s = 0.25;
    static constexpr double kDownStrokeRatio = 0.5;
    static constexpr double kRunawayTipSpeed_mps = 40.0;
    static constexpr double kRunawayQuiet_s = 1.0;
    long runaways() const { return runaways_; }
    // What /ictus/gains scales may do (refused otherwise, naming the bound):
    // - keep the largest PD rate kp / kd times the step under this: the
    //   stiffness part of eq. 1 is explicit in ODE's motor rows (a velocity
    //   target (kp / kd) e), stable only for (kp / kd) h < 2; half is allowed;
    // - keep each joint's damping ratio zeta = kd / (2 sqrt(kp I)), scaled
    //   as zeta x damping / sqrt(stiffness), at or above 1/sqrt(2) (or the
    //   configured ratio, if lower): below it a second-order joint has a
    //   resonant peak, and the strikes' impulses ring it up (measured in
    //   docs/perform.md: tips past 25 m/s at zeta 0.5-0.6 and 2-4x stiffness).
    static constexpr double kMaxPdRateStep = 1.0;
    static constexpr double kMinDampingRatio = 0.70710678118654752;

  private:
    struct Rig;
    struct ScoreRig;
    struct PlanState;
    struct Job;
    struct Result;
    class Worker;
    // Built off the live state, from copies (the worker thread may run them).
    std::unique_ptr<Rig> make_clip_rig(PerformanceOptions &options) const;
    std::unique_ptr<ScoreRig> make_score_rig(const PerformanceOptions &options,
                                             const std::vector<Eigen::Quaterniond> *pose) const;
    std::unique_ptr<PlanState> make_plan(std::shared_ptr<const Score> score,
                                         const PerformerFrame &frame,
                                         const PlanOptions &plan) const;
    std::unique_ptr<Result> execute(Job &job); // the worker, or inline
    // Runs or queues a job; false with why when it was refused inline.
    bool submit(std::unique_ptr<Job> job, std::string *why);
    bool install(std::unique_ptr<Result> result, std::string *why);
    void install_clip_rig(std::unique_ptr<Rig> rig);
    void install_score_rig(std::unique_ptr<ScoreRig> rig, bool keep_pose);
    void install_plan(std::unique_ptr<PlanState> plan, bool start_now);
    void take_results();
    void refuse_later(const Command &origin, const std::string &why);
    bool check_gains(const double scale[2], std::string *why) const;
    int guard_runaway(int k); // the strikes that may leave (0 while quiet)
    PerformerFrame frame_for_drum(const ScoreRig &rig) const;
    std::unique_ptr<Job> plan_job(const Command &origin, bool start_now) const;
    int step_clip(StrikeEvent out[2]);
    int step_score(StrikeEvent out[2]);
    bool apply_score(const Command &command, std::string *why);
    void start_rest_move();
    Eigen::Vector3d target_at(int side, double plan_time_s) const;
    Eigen::Vector3d direction_at(int side, double plan_time_s) const;
    Eigen::Vector3d rest_direction(int side) const;
    double plan_time_of(int side, double plan_time_s) const;
    void apply_note_grips(double plan_time_s);
    void trunk_synergy(ScoreRig &rig) const;
    // The trunk (docs/perform.md, "The trunk"): eq. 1's natural frequency of
    // the lumbar and thorax joints, and how they follow the sticks.
    static constexpr double kTrunkHz = 8.0;
    static constexpr double kTrunkLean_rad_per_m = 0.15;
    static constexpr double kTrunkTwist_rad_per_m = 0.2;
    void set_grips(double firmness); // both hands, now
    double applied_firmness_[2] = {-1.0, -1.0};
    BodyStats body_stats_;
    void measure_body();
    void apply_drum_now();
    PerformanceOptions options_;
    Skeleton skeleton_;
    std::unique_ptr<BvhFile> clip_; // clip mode: the capture, read once
    mutable BodyFrames frames_;     // scratch of pose()
    std::unique_ptr<Rig> rig_;
    std::unique_ptr<ScoreRig> score_rig_;
    StrikeDetector detector_;
    // Score mode: the database (read only after construction), the
    // statements received (physics thread), the current score (only
    // execute() touches it: the worker's, or inline) and the plan performed.
    std::unique_ptr<GestureDatabase> db_;
    std::unique_ptr<ScoreBuilder> builder_;
    std::shared_ptr<const Score> score_;
    std::shared_ptr<const Score> played_;    // score_ at its tempo scale (execute() only)
    double tempo_scale_ = 1.0;               // the physics thread's (Result::tempo_scale)
    double start_bpm_ = 0.0;                 // > 0: the next play starts at this tempo
    bool play_pending_ = false;              // a play handed to the worker, not back yet
    double score_first_bpm_ = 120.0;         // the current score's own first tempo
    Nuance default_nuance_ = Nuance::legato; // /ictus/nuance: of the statements that follow
    std::unique_ptr<PlanState> plan_state_;
    const GesturePlan *plan_ = nullptr; // &plan_state_->plan
    bool plan_active_ = false;
    double plan_origin_s_ = 0.0, plan_time_s_ = 0.0;
    // Between plans the tips move to (and hold) the rest tips.
    std::array<Eigen::Vector3d, 2> rest_from_m_;
    double rest_move_start_s_ = -1e9;
    std::vector<double> no_speeds_;
    bool playing_ = true;
    bool rebuild_pending_ = false;
    std::unique_ptr<Worker> worker_;
    std::vector<Refusal> refusals_; // oldest first
    std::vector<Eigen::Quaterniond> pose_scratch_;
    Command last_gains_; // the origin a runaway is reported to
    long runaways_ = 0;
    double quiet_until_s_ = -1.0; // no strike leaves before this time (runaway)
    double clip_time_s_ = 0.0;
    double time_offset_s_ = 0.0; // simulation time at the last (re)build
    double gain_scale_[2] = {1.0, 1.0};
    int divergences_before_ = 0;
};

} // namespace ictus
