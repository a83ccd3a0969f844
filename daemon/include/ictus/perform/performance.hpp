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
#include "ictus/perform/body_stats.hpp"
#include "ictus/perform/commands.hpp"
#include "ictus/perform/kit.hpp"
#include "ictus/sim/scene.hpp"
#include "ictus/score/score.hpp"
#include "ictus/sim/strike_detector.hpp"
#include "ictus/perform/track.hpp"
#include "ictus/perform/strike_match.hpp"
#include "ictus/perform/tracker.hpp"

#include <array>
#include <atomic>
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
    // A score already built (ictusd --midi: a MIDI file's drum part); when
    // set, score_text is not read.
    std::shared_ptr<const Score> score;
    std::string midi_path; // --midi FILE, turned into `score` once the kit is known
    std::string gestures; // gesture database JSON; empty: GestureDatabase::builtin()
    TrackMode mode = TrackMode::cartesian;
    bool grip_given = false; // else the character holds the sticks as the score's first note
    // The score's tempo until its own first `tempo` statement (--tempo), bpm.
    double start_tempo_bpm = kDefaultTempoBpm;
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
    // Joint mode (eq. 1 alone) holds the tip lower than the Cartesian mode
    // does: its PD carries the arm's weight on a static error that no
    // Cartesian feedback corrects. The plan's contact lead adds this much
    // there (docs/perform.md, "Contact on the beat").
    double joint_contact_lead_m = 0.0018;
    // The plan options for a control mode: `plan` with the mode's contact lead.
    PlanOptions plan_for(TrackMode m) const;
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
    // --drum-preset: the head's name (externals/core/membrane_presets.h), "" for none;
    // the sound takes the rest of the preset (T60, modes, pickups, tuning) from it.
    std::string drum_preset;
    // Which of --drum-radius, --drum-tension, --drum-density were given (bits 1, 2, 4):
    // they win over the preset's, whatever the order of the options.
    int drum_given = 0;
    // The first score-mode option given (--humanize, --lead-in, ...): the command line
    // refuses it with --mocap, whose clip would play without it.
    std::string score_option_given;
    StrikeDetectorOptions strikes;
    ScorePerformOptions score; // score mode (no mocap)
    // The grip's firmness 0..1 (Scene's grip_spring()): the notes' default,
    // changed live by /ictus/grip/firmness; a note may give its own.
    double grip_firmness = kDefaultGripFirmness;
    // A kit (score mode; kit.hpp, docs/perform.md "A kit"); empty: the one
    // drum. Its first drum is scene.drum, placed as the one drum is; the
    // Performance takes its head (radius, tension, shell) from the kit.
    Kit kit;
    PerformanceOptions(); // the sticks on their fulcrum (SceneOptions::sticks)
};

class PerformMode;
class ClipMode;
class ScoreMode;
class Work;
class PlanningWorker;
class KickPedal;

// The most strikes one physics step ends or begins: one per hand and one per
// foot (the kick's pedal, the hi-hat's: docs/pedal.md).
constexpr int kStepStrikes = 4;

// The physics side of run and render: the character tracking the clip or
// performing a score, the drum, the strike detector, and the commands Pd may
// send. The motion source is a mode (clip_mode.cpp, score_mode.cpp) behind one
// interface: apply() handles each command once and asks the mode for what
// differs.
class Performance
{
  public:
    // Throws PerformError on bad options, the readers' errors on a bad file
    // (clip, score, gesture database).
    explicit Performance(const PerformanceOptions &options);
    ~Performance();

    // One physics step; returns the number of strikes ended in it (<=
    // kStepStrikes), written to out[0..n).
    int step(StrikeEvent out[kStepStrikes]);
    // The strikes whose contact began in the last step (<= 2), at their
    // onset: what a sound needs (time, hand, position, velocity), without
    // force, impulse and duration, which step() reports at the release
    // (docs/osc.md: `ictusd run` sends the one at once, the rest after).
    // Every strike step() or flush() reports had its onset here, and every
    // onset here has its strike there (a rebuild of the character ends the
    // contacts under way; a strike held back by the runaway guard is held
    // back whole).
    int take_onsets(StrikeEvent out[kStepStrikes]);
    // Ends contacts still open (end of a run), after the strikes still held.
    bool flush(StrikeEvent &out);
    // Applies a command from the OSC thread. Returns false with a reason when
    // it cannot be applied (the OSC thread has already validated the values;
    // what a command throws is refused with its what()).
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
    double tempo_scale() const;
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

    // How the body moved (score mode, since the performance began:
    // body_stats.hpp); all zero for a clip.
    using BodyStats = ::ictus::BodyStats;
    const BodyStats &body_stats() const;

    // Score mode.
    bool score_mode() const { return options_.mocap.empty(); }
    // The plan being performed (or last performed); nullptr before the first.
    const GesturePlan *plan() const;
    bool plan_active() const;
    // Simulation time of the plan's time 0, and the plan's clock.
    double plan_origin_s() const;
    double plan_time_s() const;
    // The tip target X^T the controller was given in the last step [hand].
    Eigen::Vector3d tip_target(int hand) const;
    Eigen::Vector3d tip_position(int hand) const;
    const PerformerFrame &performer_frame() const;
    // The kick's pedal (the kit's foot piece, docs/pedal.md), nullptr without
    // one; where its head's centre stands (world; zero without one).
    const KickPedal *kick_pedal() const;
    Eigen::Vector3d foot_piece_center_m() const;
    TrackMode mode() const;
    // The planned target's speed toward the head as it reaches the contact,
    // per note of plan() (m/s).
    double planned_impact_speed_mps(size_t note) const;
    // Plans the current score and starts it now (what /ictus/play does in
    // score mode). Throws PerformError (not in score mode, background work
    // under way), ScoreError / GestureError; on error nothing changes.
    void start_score();
    // Plans the current score as start_score() would, and keeps nothing: a score
    // that cannot be played throws here, before anyone presses play.
    void check_score() const;

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
    // Whether the last apply() handed its command to the worker: its verdict
    // comes later, as a refusal or as a confirmation (pop_confirmation).
    bool deferred() const { return deferred_; }
    // Commands whose background work was installed (or cancelled by a stop),
    // oldest first: the sender's /ictus/reply waits for this.
    bool pop_confirmation(Command &out);

    // The runaway guard (docs/perform.md): a stick tip faster than this is
    // no human stroke but a controller gone unstable (the built-in strokes
    // peak at 10-18 m/s with the default gains, up to 27 m/s with stiff,
    // lightly damped ones; a controller past its stability bound reached
    // 54 m/s). The guard then puts
    // the gains back to their defaults, sends no strike for
    // kRunawayQuiet_s, counts it and reports it, naming its cause: as a
    // refusal of the last /ictus/gains when that scaled the gains, else with
    // no address (no command caused it).
    // The grip of a buzz note that gives none (docs/perform.md, "Buzz").
    static constexpr double kBuzzGripFirmness = 0.0;
    // A down stroke (drumming pedagogy: a stroke that stops the stick low,
    // for a soft note next): a stroke whose next note of the same hand comes
    // within kDownStrokeGap_s and hits at under kDownStrokeRatio of its
    // planned speed is held with this firmness from its strike to that next
    // beat, unless either note gives its own grip (docs/perform.md).
    static constexpr double kDownStrokeGripFirmness = 0.8;
    // The least firmness a stroke is thrown with (docs/perform.md, "Grip
    // firmness"): a note's looser grip holds from its strike, unless the
    // hand's next stroke comes within kReboundGrip_s.
    static constexpr double kSwingGripFirmness = kDefaultGripFirmness;
    static constexpr double kReboundGrip_s = 0.1;
    static constexpr double kDownStrokeGap_s = 0.25;
    static constexpr double kDownStrokeRatio = 0.5;
    static constexpr double kRunawayTipSpeed_mps = 40.0;
    static constexpr double kRunawayQuiet_s = 1.0;
    // With the built-in controller (default gains, scale 1 1, the joints'
    // stops on), which does not run away, a tip that fast is first taken for
    // the move throwing the stick (a whip across the kit): the guard holds
    // back that hand's strikes only, while its tip stays that fast and for
    // kWhipSettle_s after, and leaves the gains as they are. A tip fast for
    // longer than kWhipLongest_s, or a second whip within kRunawayQuiet_s of
    // the last, is a runaway after all (a controller's oscillation lasts).
    static constexpr double kWhipSettle_s = 0.1;
    static constexpr double kWhipLongest_s = 0.02;
    long runaways() const { return runaways_; }
    // Sticks thrown past kRunawayTipSpeed_mps by a move (kWhipSettle_s).
    long whips() const { return whips_; }
    // Strikes held back whole (onset and release) by the runaway guard.
    long withheld_strikes() const { return withheld_; }
    // Score statements over OSC (/ictus/score) refused: faulty (each answered
    // with its error), or kMaxPendingStatements are waiting already (docs/osc.md).
    long refused_statements() const { return refused_statements_; }
    // Statements (parsed; a line may hold several) a score received over OSC
    // may hold until /ictus/score/clear: what a play copies, and what the
    // daemon's memory holds of them, stay bounded (docs/osc.md).
    static constexpr int kMaxPendingStatements = 10000;
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
    friend class ClipMode;
    friend class ScoreMode;
    // What both modes share. The rig's gains at the live scale, on its scene.
    void apply_gains();
    void set_grips(double firmness); // both hands, now
    // A new rig took over (clip_mode.cpp, score_mode.cpp): the live drum,
    // gains and grip on its scene; the simulation clock goes on from
    // `previous_time_s` (strike times and timetags stay monotonic).
    void took_over(double previous_time_s);
    // Runs or queues a job; false with why when it was refused inline.
    bool submit(std::unique_ptr<Work> job, std::string *why);
    bool install(std::unique_ptr<Work> work, std::string *why);
    // Frees what the physics thread replaced on the worker thread (here without one).
    void discard(std::unique_ptr<Work> old);
    void take_results();
    void refuse_later(const Command &origin, const std::string &why);
    bool check_gains(const double scale[2], std::string *why) const;
    bool apply_gains_command(const Command &c, std::string *why);
    bool apply_drum_command(const Command &c, std::string *why);
    int guard_runaway(int k, StrikeEvent out[kStepStrikes]); // the strikes that may leave
    bool withheld(const StrikeEvent &e) const;    // an onset while the guard is quiet
    // A strike on a hi-hat gets the pedal of the note it plays (score mode).
    void mark_pedal(StrikeEvent &e) const;
    // Contacts a rebuild (took_over) ended, and onsets it took, given out by
    // the next step() and take_onsets().
    void hold_open_contacts();

    PerformanceOptions options_;
    Skeleton skeleton_;
    mutable BodyFrames frames_; // scratch of pose()
    StrikeDetector detector_;
    std::unique_ptr<PerformMode> mode_;
    ClipMode *clip_ = nullptr;   // mode_, in clip mode
    ScoreMode *score_ = nullptr; // mode_, in score mode
    bool playing_ = true;
    std::unique_ptr<PlanningWorker> worker_;
    std::vector<Refusal> refusals_; // oldest first
    std::vector<Command> confirmations_; // oldest first
    bool deferred_ = false;              // apply() handed its command to the worker
    Command last_gains_;            // the origin a runaway is reported to
    long runaways_ = 0;
    double quiet_until_s_ = -1.0; // no strike with an onset before this time (runaway)
    double quiet_from_s_ = -1.0;  // and from this one on leaves
    // The whips' quiet times, per hand [Side], the latest kWhipWindows (a
    // strike is held back whole when its onset fell in one: kept while its
    // contact may still be open).
    struct QuietWindow {
        double from_s = -1.0, until_s = -1.0;
    };
    static constexpr int kWhipWindows = 4;
    QuietWindow whip_windows_[2][kWhipWindows];
    int whip_newest_[2] = {0, 0};
    double last_whip_s_ = -1e300;
    long whips_ = 0;
    long withheld_ = 0;
    long refused_statements_ = 0;
    // Counted by apply(stop), read by the worker: a play asked for before the
    // last stop is cancelled (Work::cancelled()).
    std::atomic<long> stops_{0};
    std::array<StrikeEvent, 8> held_ends_{};
    int held_ends_n_ = 0;
    std::array<StrikeEvent, kStepStrikes> held_onsets_{};
    int held_onsets_n_ = 0;
    double time_offset_s_ = 0.0;  // simulation time at the last (re)build
    double gain_scale_[2] = {1.0, 1.0};
    int divergences_before_ = 0;
    double applied_firmness_[2] = {-1.0, -1.0};
};

} // namespace ictus
