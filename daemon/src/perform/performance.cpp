// The physics side of `ictusd run` and `ictusd render` (performance.hpp): the
// character tracks the clip in joint space (eq. 1, a Tracker in joint mode) or
// performs a score's gesture plan (Tracker: Algorithm 2 or joint targets from
// IK), and the interaction manager watches the stick tips against the drum.
// Score mode is described in docs/perform.md.
#include "ictus/mocap/bvh.hpp"
#include "ictus/character/character_limits.hpp"
#include "ictus/character/range_of_motion.hpp"
#include "ictus/base/rotation.hpp"
#include "ictus/character/stick_capture.hpp"
#include "ictus/perform/track.hpp"
#include "ictus/perform/tracker.hpp"
#include "ictus/perform/performance.hpp"
#include "ictus/base/spsc_queue.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <thread>

namespace ictus
{

namespace
{
double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

// Where the clip strikes: the reference stick tips' local minima of height
// reached at more than 1 m/s downwards (the mimed strokes; a captured
// performance without a drum still "hits" a plane). The membrane goes at the
// median of those points, so that about half of the mimed strokes reach it
// and are stopped by it. (track.hpp's auto_drum_center puts the drum under
// the lowest tips, which in a mimed clip are in the rest pose, not in a stroke.)
Eigen::Vector3d strike_drum_center(const CharacterModel &model, const ReferenceMotion &reference,
                                   const Eigen::Vector3d &fallback)
{
    const int frames = reference.frames();
    std::vector<std::array<Eigen::Vector3d, 2>> tips(static_cast<size_t>(frames));
    for (int f = 0; f < frames; ++f)
        tips[static_cast<size_t>(f)] = reference_tips(model, reference.frame(f));
    std::vector<double> xs, ys, zs;
    const double rate = reference.frame_rate_hz();
    for (int hand = 0; hand < 2; ++hand)
        for (int f = 2; f + 2 < frames; ++f) {
            auto y = [&](int g) { return tips[static_cast<size_t>(g)][hand].y(); };
            const bool minimum =
                y(f) < y(f - 1) && y(f) <= y(f + 1) && y(f) < y(f - 2) && y(f) <= y(f + 2);
            const double approach_mps = (y(f - 2) - y(f)) * rate / 2.0;
            if (minimum && approach_mps > 1.0) {
                xs.push_back(tips[static_cast<size_t>(f)][hand].x());
                ys.push_back(y(f));
                zs.push_back(tips[static_cast<size_t>(f)][hand].z());
            }
        }
    if (xs.size() < 4)
        return fallback;
    return Eigen::Vector3d(median(xs), median(ys), median(zs));
}

// The live tempo scale (docs/osc.md, /ictus/tempo in score mode): the tempo
// map with every tempo from `from_beat` on multiplied by `factor`, the beats
// before it (and so every time up to it) as they were. A ramp running at
// `from_beat` goes on, scaled, to its end. Throws std::runtime_error when a scaled
// tempo leaves the score's range (20..400 bpm).
TempoMap scale_tempo_from(const TempoMap &map, double from_beat, double factor)
{
    const std::vector<TempoMap::Change> &changes = map.changes();
    auto check = [&](double bpm, double beat, double scaled) {
        if (!(scaled >= kMinTempoBpm && scaled <= kMaxTempoBpm)) {
            char buf[200];
            std::snprintf(buf, sizeof buf,
                          "tempo: the score's %g bpm at beat %g would become %.4g bpm (beyond "
                          "%g..%g)",
                          bpm, beat, scaled, kMinTempoBpm, kMaxTempoBpm);
            throw std::runtime_error(buf);
        }
    };
    TempoMap out(changes.front().start_bpm);
    const TempoMap::Change *running = &changes.front();
    for (const TempoMap::Change &c : changes) {
        if (c.beat >= from_beat)
            break;
        out.add(c.beat, c.start_bpm, c.end_bpm, c.ramp_beats);
        running = &c;
    }
    for (const TempoMap::Change &c : changes)
        if (c.beat <= from_beat)
            running = &c;
    const double here = map.tempo_at_beat(from_beat);
    const double ramp_left = std::max(0.0, running->beat + running->ramp_beats - from_beat);
    check(here, from_beat, factor * here);
    check(running->end_bpm, running->beat + running->ramp_beats, factor * running->end_bpm);
    out.add(from_beat, factor * here, factor * (ramp_left > 0.0 ? running->end_bpm : here),
            ramp_left);
    for (const TempoMap::Change &c : changes) {
        if (c.beat <= from_beat)
            continue;
        check(c.start_bpm, c.beat, factor * c.start_bpm);
        check(c.end_bpm, c.beat + c.ramp_beats, factor * c.end_bpm);
        out.add(c.beat, factor * c.start_bpm, factor * c.end_bpm, c.ramp_beats);
    }
    return out;
}

// Where a live tempo change can start in a plan under way: the first beat
// such that every stroke the hands have begun by plan time `now_s` keeps its
// shape and time. A hand's stroke toward its note j is planned on the times
// of notes j - 1, j and j + 1 (its unit is made for its period and warped
// into the gaps, docs/score.md) and enters the hand's trajectory at the
// start of the cross-fade window t_{j-1} + m (t_j - t_{j-1}); so a note j
// whose window has not started can move its successors. Returns the beat
// of the latest such first unstarted note over the hands (infinity: a hand
// has begun its last stroke) and, in `until_s`, the earliest of those
// windows: up to that plan time the plan with the new tempo equals the old.
double tempo_split_beat(const Score &score, double score_start_s, double blend_margin, double now_s,
                        double &until_s)
{
    double split = 0.0;
    until_s = std::numeric_limits<double>::infinity();
    for (Side hand : {Side::left, Side::right}) {
        bool any = false, found = false;
        double previous_s = 0.0;
        for (const ScoreNote &n : score.notes) {
            if (n.hand != hand)
                continue;
            const double t = score_start_s + score.note_time_s(n);
            // The first stroke's window is the plan's start: always begun.
            if (any) {
                const double window_s = previous_s + blend_margin * (t - previous_s);
                if (window_s > now_s) {
                    split = std::max(split, n.beat);
                    until_s = std::min(until_s, window_s);
                    found = true;
                    break;
                }
            }
            any = true;
            previous_s = t;
        }
        if (any && !found)
            return std::numeric_limits<double>::infinity();
    }
    return split;
}

Score scale_score_from(const Score &score, double from_beat, double factor)
{
    Score out = score;
    out.tempo = scale_tempo_from(score.tempo, from_beat, factor);
    return out;
}
} // namespace

// Clip mode: everything that depends on the grip or the drum, rebuilt together
// when they change (the tracker's Scene keeps references to the limits, which
// are declared first and so outlive it).
struct Performance::Rig {
    CharacterModel model;
    ReferenceMotion reference;
    CharacterLimits limits;
    std::vector<JointGains> base_gains, gains;
    std::unique_ptr<Tracker> tracker;
    // Per-step scratch, sized once (no allocation in the loop).
    CharacterPose ref_pose, step_pose;
    Rig(const CharacterModel &m, const Motion &motion)
        : model(m), reference(model, motion, ReferenceFilter{}), limits(model, reference)
    {
    }
};

// The character, its controller and the drum of score mode, rebuilt together
// when the grip or the drum changes (a Scene has no setters for them).
struct Performance::ScoreRig {
    CharacterModel model;
    RangeOfMotion range_of_motion;    // the joint limits (declared before the tracker)
    RangeOfMotion ik_range_of_motion; // the same, narrowed: the arms' IK's
    std::vector<JointLimitRef> ik_limits = ik_range_of_motion.refs();
    int lumbar = model.joint_index("lumbar"), thorax = model.joint_index("thorax");
    std::vector<JointGains> base_gains, gains;
    std::unique_ptr<Tracker> tracker;
    CharacterPose body;      // the reference held by the trunk and legs (arms: IK)
    CharacterPose step_body; // body with the trunk's synergy of this step
    PerformerFrame frame;
    Eigen::Vector3d drum_center_m = Eigen::Vector3d::Zero(); // where the drum goes
    TipTargets tips;
    ScoreRig(const CharacterModel &m, double ik_limit_margin_rad)
        : model(m), range_of_motion(model), ik_range_of_motion(model, ik_limit_margin_rad)
    {
    }
};

// A plan ready to perform: the score it came from, the plan, and per hand and
// note the plan time of the beat, the lead of the target's first contact
// before it and the approach speed there (target_at).
struct Performance::PlanState {
    std::shared_ptr<const Score> score;
    GesturePlan plan;
    std::array<std::vector<double>, 2> beats, lead_s, approach_mps;
    std::array<std::vector<double>, 2> firmness; // < 0: the performance's
    std::array<std::vector<bool>, 2> press;      // a buzz: loose from its beat on
    std::array<std::vector<bool>, 2> down;       // a down stroke: firm until the next beat
    std::array<size_t, 2> grip_note = {0, 0};    // the note whose grip is applied
    std::vector<double> planned_speed_mps;       // [note of plan]
};

// Work for execute(): everything it needs is in the job (copies), so that it
// can run on the worker thread while the physics thread goes on.
struct Performance::Job {
    enum class Kind {
        play,      // finish `statements` (none: the current score), plan, start
        replan,    // plan the current score on a new frame; a plan under way goes on
        score_rig, // the character again (a grip change), from `pose`
        clip_rig,  // clip mode: the character and its reference again, then play
        tempo,     // the score under way at `bpm` from its first beat not yet under way
    };
    Kind kind = Kind::play;
    Command origin;
    std::unique_ptr<ScoreBuilder> statements;
    PerformerFrame frame;
    PerformanceOptions options;
    std::vector<Eigen::Quaterniond> pose;
    // play: the tempo scale of the score (start_bpm > 0: the scale that
    // starts it at start_bpm); tempo: the scale so far, the bpm asked for,
    // the plan's clock when it was asked and the plan time of beat 0.
    double tempo_scale = 1.0, start_bpm = 0.0, bpm = 0.0, plan_now_s = 0.0, score_start_s = 0.0;
    bool supersedes(const Job &earlier) const
    {
        if (earlier.kind == Kind::replan)
            return kind == Kind::replan || kind == Kind::play;
        return earlier.kind != Kind::play && kind == earlier.kind;
    }
};

struct Performance::Result {
    Job::Kind kind = Job::Kind::play;
    Command origin;
    std::string error; // not empty: refused, nothing changes
    std::unique_ptr<PlanState> plan;
    std::unique_ptr<ScoreRig> score_rig;
    std::unique_ptr<Rig> rig;
    Eigen::Vector3d drum_center_m = Eigen::Vector3d::Zero(); // clip_rig
    // play, tempo: the tempo scale now in force and the score's own first
    // tempo (play); tempo: the score the change was planned on, and the
    // plan time until which the new plan equals the old one.
    double tempo_scale = 1.0, first_bpm = 0.0;
    std::shared_ptr<const Score> based_on;
    double valid_until_s = 0.0;
};

// The worker thread: takes jobs, keeps only the last of a kind that a later
// one supersedes (a drum slider's 20 changes a second plan once), runs them
// in order and hands the results back; the old rigs and plans the physics
// thread has replaced are freed here too. Queues only: the physics thread
// never waits for it.
class Performance::Worker
{
  public:
    explicit Worker(Performance &performance) : perf_(performance), thread_([this] { loop(); }) {}
    ~Worker()
    {
        running_ = false;
        thread_.join();
        Job *j;
        while (jobs_.pop(j))
            delete j;
        Result *r;
        while (results_.pop(r))
            delete r;
        while (garbage_.pop(r))
            delete r;
    }
    Worker(const Worker &) = delete;
    Worker &operator=(const Worker &) = delete;
    bool submit(std::unique_ptr<Job> job)
    {
        if (!jobs_.push(job.get()))
            return false;
        job.release();
        outstanding_.fetch_add(1);
        return true;
    }
    std::unique_ptr<Result> take()
    {
        Result *r = nullptr;
        if (!results_.pop(r))
            return nullptr;
        outstanding_.fetch_sub(1);
        return std::unique_ptr<Result>(r);
    }
    void discard(std::unique_ptr<Result> old)
    {
        if (garbage_.push(old.get()))
            old.release(); // else freed here, by the caller
    }
    bool pending() const { return outstanding_.load() > 0; }

  private:
    void loop()
    {
        std::deque<Job *> queued;
        while (running_.load()) {
            Result *g;
            while (garbage_.pop(g))
                delete g;
            Job *j;
            while (jobs_.pop(j))
                queued.push_back(j);
            for (size_t i = 0; i < queued.size();) {
                bool superseded = false;
                for (size_t k = i + 1; k < queued.size() && !superseded; ++k)
                    superseded = queued[k]->supersedes(*queued[i]);
                if (superseded) {
                    delete queued[i];
                    queued.erase(queued.begin() + static_cast<long>(i));
                    outstanding_.fetch_sub(1);
                } else {
                    ++i;
                }
            }
            if (queued.empty()) {
                std::this_thread::sleep_for(std::chrono::milliseconds(1));
                continue;
            }
            std::unique_ptr<Job> job(queued.front());
            queued.pop_front();
            std::unique_ptr<Result> r = perf_.execute(*job);
            while (running_.load() && !results_.push(r.get()))
                std::this_thread::sleep_for(std::chrono::milliseconds(1));
            if (running_.load())
                r.release();
        }
        for (Job *q : queued)
            delete q;
    }
    Performance &perf_;
    SpscQueue<Job *, 64> jobs_;
    SpscQueue<Result *, 64> results_;
    SpscQueue<Result *, 64> garbage_;
    std::atomic<bool> running_{true};
    std::atomic<long> outstanding_{0};
    std::thread thread_;
};

Performance::Performance(const PerformanceOptions &options)
    : options_(options), detector_(MembraneGeometry{}, options.strikes)
{
    validate(options_.scene);
    if (!(options_.clip_bpm > 0.0 && std::isfinite(options_.clip_bpm)))
        throw CharacterError("clip tempo: expected a finite value > 0 bpm");
    if (!(options_.tempo_bpm >= 20.0 && options_.tempo_bpm <= 400.0))
        throw CharacterError("tempo: expected 20 to 400 bpm");
    if (!score_mode()) {
        // Read once: a rebuild (grip change at /ictus/play) starts from this copy,
        // so that the physics thread never touches the disk.
        BvhOptions bo;
        bo.scale = options_.scale_m_per_unit;
        bo.skip_frames = options_.skip_frames;
        MocapWarnings warnings;
        clip_ = std::make_unique<BvhFile>(read_bvh(options_.mocap, bo, &warnings));
        for (const std::string &w : warnings)
            std::cerr << "ictusd: warning: " << w << "\n";
        skeleton_ = clip_->skeleton;
        install_clip_rig(make_clip_rig(options_));
        return;
    }
    const ScorePerformOptions &so = options_.score;
    if (!(std::isfinite(so.time_advance_s) && so.time_advance_s >= 0.0 && so.time_advance_s <= 0.1))
        throw CharacterError("time advance: expected 0 to 0.1 s");
    if (!(std::isfinite(so.drum_forward_m) && std::abs(so.drum_forward_m) <= 2.0 &&
          std::isfinite(so.drum_below_m) && std::abs(so.drum_below_m) <= 2.0))
        throw CharacterError("drum placement: expected offsets within 2 m");
    db_ = std::make_unique<GestureDatabase>(
        so.gestures.empty() ? GestureDatabase::builtin() : GestureDatabase::load_json(so.gestures));
    builder_ = std::make_unique<ScoreBuilder>("osc");
    score_ = std::make_shared<const Score>(
        parse_score(so.score_text.empty() ? default_score_text() : so.score_text, so.score_name));
    if (!so.grip_given && !score_->notes.empty())
        options_.character.grip = score_->notes.front().grip;
    score_first_bpm_ = score_->tempo.tempo_at_beat(0.0);
    skeleton_ = default_skeleton();
    install_score_rig(make_score_rig(options_, nullptr), false);
    playing_ = false;
}

Performance::~Performance()
{
    worker_.reset(); // joined before what it reads goes
}

// Clip mode: the character, its reference and controller for `options`
// (drum_auto: the drum centre is set in `options`). Reads only the clip.
std::unique_ptr<Performance::Rig> Performance::make_clip_rig(PerformanceOptions &options) const
{
    const BvhFile &bvh = *clip_;
    const CharacterModel model = CharacterModel::from_skeleton(bvh.skeleton, options.character);
    auto rig = std::make_unique<Rig>(model, bvh.motion);
    Rig &r = *rig;
    if (options.drum_auto)
        options.scene.drum.center_m =
            strike_drum_center(r.model, r.reference, auto_drum_center(r.model, r.reference));
    const CharacterPose initial = r.reference.frame(0);
    r.base_gains = default_gains(r.model, initial, options.gains);
    scale_gains(r.base_gains, gain_scale_, r.gains);
    // Eq. 1 on every joint: the tracker's joint mode, as `ictusd track --mode joint`,
    // in its scene (track_scene_defaults: the pelvis a kinematic body, not welded).
    SceneOptions scene = options.scene;
    scene.pelvis_kinematic = track_scene_defaults().pelvis_kinematic;
    r.tracker = std::make_unique<Tracker>(r.model, scene, initial, r.gains, r.limits.refs(),
                                          TrackMode::joint);
    r.ref_pose = initial;
    r.step_pose = initial;
    return rig;
}

void Performance::install_clip_rig(std::unique_ptr<Rig> rig)
{
    const double previous_time = rig_ ? time_s() : 0.0;
    if (rig_)
        divergences_before_ += rig_->tracker->scene().divergences();
    std::swap(rig_, rig);
    // The drum may have changed while the rig was built: the live one wins.
    rig_->tracker->scene().set_drum(options_.scene.drum);
    scale_gains(rig_->base_gains, gain_scale_, rig_->gains);
    rig_->tracker->scene().set_gains(rig_->gains);
    set_grips(options_.grip_firmness);
    // The simulation clock keeps running across rebuilds (strike times and
    // timetags stay monotonic); the clip restarts from its beginning.
    time_offset_s_ = previous_time;
    clip_time_s_ = 0.0;
    detector_.reset(membrane_of(scene()));
    if (rig && worker_) {
        auto old = std::make_unique<Result>();
        old->rig = std::move(rig);
        worker_->discard(std::move(old));
    }
}

// Clip mode: the live scene's drum changes at once (Scene::set_drum), and the
// strike detector watches the new membrane from its next contact on.
void Performance::apply_drum_now()
{
    rig_->tracker->scene().set_drum(options_.scene.drum);
    detector_.set_membrane(membrane_of(scene()));
}

const CharacterModel &Performance::model() const
{
    return rig_ ? rig_->model : score_rig_->model;
}

const Scene &Performance::scene() const
{
    return rig_ ? rig_->tracker->scene() : score_rig_->tracker->scene();
}

double Performance::time_s() const
{
    return time_offset_s_ + scene().time_s();
}

double Performance::clip_duration_s() const
{
    if (!rig_)
        return plan_ ? plan_->duration_s : 0.0;
    return rig_->reference.duration_s() * options_.clip_bpm / options_.tempo_bpm;
}

int Performance::divergences() const
{
    return divergences_before_ + scene().divergences();
}

int Performance::step(StrikeEvent out[2])
{
    take_results();
    const int k = rig_ ? step_clip(out) : step_score(out);
    return guard_runaway(k);
}

int Performance::take_onsets(StrikeEvent out[2])
{
    int n = 0;
    for (int hand = 0; hand < 2; ++hand)
        if (detector_.take_onset(hand, out[n]))
            ++n;
    return time_s() < quiet_until_s_ ? 0 : n;
}

bool Performance::check_gains(const double scale[2], std::string *why) const
{
    const std::vector<JointGains> &base = rig_ ? rig_->base_gains : score_rig_->base_gains;
    double rate = 0.0; // the largest kp / kd after scaling, 1/s
    for (const JointGains &g : base)
        rate = std::max(rate, g.kp_nm_per_rad * scale[0] / (g.kd_nm_s_per_rad * scale[1]));
    const double h = options_.scene.step_s;
    const double zeta0 = options_.gains.damping_ratio;
    const double zeta = zeta0 * scale[1] / std::sqrt(scale[0]);
    const double zeta_min = std::min(kMinDampingRatio, zeta0);
    if (zeta < zeta_min * (1.0 - 1e-9)) { // rounding of the scales aside
        if (why) {
            char buf[256];
            std::snprintf(buf, sizeof buf,
                          "gains: stiffness x%g with damping x%g leaves a damping ratio of %.2f, "
                          "under %.2f (the joints would ring, the controller is unstable): raise "
                          "the damping to x%.3g or more",
                          scale[0], scale[1], zeta, zeta_min,
                          zeta_min / zeta0 * std::sqrt(scale[0]));
            *why = buf;
        }
        return false;
    }
    if (rate * h <= kMaxPdRateStep)
        return true;
    if (why) {
        char buf[256];
        std::snprintf(buf, sizeof buf,
                      "gains: stiffness x%g with damping x%g gives a PD rate kp/kd of %.0f/s, "
                      "unstable at the %g ms step (at most %.0f/s): raise the damping to x%.3g "
                      "or more",
                      scale[0], scale[1], rate, 1e3 * h, kMaxPdRateStep / h,
                      scale[1] * rate * h / kMaxPdRateStep);
        *why = buf;
    }
    return false;
}

int Performance::guard_runaway(int k)
{
    double speed = 0.0;
    for (int s = 0; s < 2; ++s)
        speed = std::max(speed, scene().tip_velocity(static_cast<Side>(s)).norm());
    if (speed > kRunawayTipSpeed_mps && time_s() >= quiet_until_s_) {
        // No human stroke moves a stick tip this fast: the controller has
        // gone unstable. Default gains back, strikes held back meanwhile.
        ++runaways_;
        gain_scale_[0] = gain_scale_[1] = 1.0;
        if (rig_) {
            scale_gains(rig_->base_gains, gain_scale_, rig_->gains);
            rig_->tracker->scene().set_gains(rig_->gains);
        } else {
            scale_gains(score_rig_->base_gains, gain_scale_, score_rig_->gains);
            score_rig_->tracker->scene().set_gains(score_rig_->gains);
        }
        char buf[200];
        std::snprintf(buf, sizeof buf,
                      "runaway: a stick tip at %.1f m/s (> %g): gains back to 1 1, no strike "
                      "sent for %g s",
                      speed, kRunawayTipSpeed_mps, kRunawayQuiet_s);
        Command origin = last_gains_;
        if (origin.address[0] == '\0')
            std::snprintf(origin.address, sizeof origin.address, "/ictus/gains");
        refuse_later(origin, buf);
        quiet_until_s_ = time_s() + kRunawayQuiet_s;
    }
    if (time_s() < quiet_until_s_)
        return 0;
    return k;
}

int Performance::step_clip(StrikeEvent out[2])
{
    Rig &r = *rig_;
    const double h = options_.scene.step_s;
    if (playing_)
        clip_time_s_ += h * options_.tempo_bpm / options_.clip_bpm;
    const double since_build = r.tracker->scene().time_s() + h;
    // Targets for the end of this step, blended in from the first frame.
    r.reference.sample(clip_time_s_, r.ref_pose);
    blend_pose(r.reference.frame(0), r.ref_pose, ramp_weight(since_build, options_.ramp_s),
               r.step_pose);
    r.tracker->step(r.step_pose, nullptr);
    return detect_strikes(detector_, r.tracker->scene(), out, time_offset_s_);
}

bool Performance::apply(const Command &c, std::string *why)
{
    if (score_mode())
        return apply_score(c, why);
    auto fail = [&](const std::string &text) {
        if (why)
            *why = text;
        return false;
    };
    switch (c.kind) {
    case CommandKind::play:
        if (rebuild_pending_) {
            // The grip changed while stopped or playing: the character is
            // rebuilt at the clip's first frame (a Scene has no setter for
            // it), and plays when it is ready.
            rebuild_pending_ = false;
            auto job = std::make_unique<Job>();
            job->kind = Job::Kind::clip_rig;
            job->origin = c;
            job->options = options_;
            return submit(std::move(job), why);
        }
        playing_ = true;
        return true;
    case CommandKind::stop:
        playing_ = false;
        return true;
    case CommandKind::tempo:
        options_.tempo_bpm = c.value;
        return true;
    case CommandKind::grip:
        options_.character.grip = grip_from_string(c.text);
        rebuild_pending_ = true;
        return true;
    case CommandKind::nuance:
        return fail("nuance: a clip has no nuances; without --mocap the daemon plays scores, whose "
                    "notes name their nuance (/ictus/score \"R accent\")");
    case CommandKind::mode:
        if (std::strcmp(c.text, "joint") != 0)
            return fail("mode: only joint is implemented");
        return true;
    case CommandKind::gains: {
        const double scale[2] = {c.value, c.value2};
        if (!check_gains(scale, why))
            return false;
        gain_scale_[0] = c.value;
        gain_scale_[1] = c.value2;
        last_gains_ = c;
        Rig &r = *rig_;
        scale_gains(r.base_gains, gain_scale_, r.gains);
        r.tracker->scene().set_gains(r.gains);
        return true;
    }
    case CommandKind::drum_radius:
        if (!(c.value > rig_->model.options().stick.tip_radius_m * 2.0))
            return fail("drum radius: must exceed the stick tip's diameter");
        options_.scene.drum.radius_m = c.value;
        apply_drum_now();
        return true;
    case CommandKind::drum_tension:
        options_.scene.drum.tension_n_per_m = c.value;
        apply_drum_now();
        return true;
    case CommandKind::drum_density:
        // The membrane's density changes its modes (membrane~), not the
        // contact stiffness 2 pi T / ln(R / r): nothing to rebuild.
        options_.drum_density_kg_per_m2 = c.value;
        return true;
    case CommandKind::grip_firmness:
        options_.grip_firmness = c.value;
        set_grips(c.value);
        return true;
    case CommandKind::score:
    case CommandKind::score_clear:
        return fail("score: the daemon plays a clip (--mocap); start it without --mocap to "
                    "perform scores");
    }
    return fail("unknown command");
}

void Performance::pose(PoseSnapshot &p) const
{
    const CharacterModel &model = this->model();
    BodyFrames &frames = frames_;
    scene().body_frames(frames);
    p.time_s = time_s();
    p.bodies = std::min<int>(CharacterModel::kBodies, PoseSnapshot::kMaxBodies);
    for (int b = 0; b < p.bodies; ++b) {
        for (int i = 0; i < 3; ++i)
            p.position_m[b][i] = static_cast<float>(frames.origin_m[b][i]);
        const Eigen::Quaterniond &q = frames.rotation[b];
        p.rotation_wxyz[b][0] = static_cast<float>(q.w());
        p.rotation_wxyz[b][1] = static_cast<float>(q.x());
        p.rotation_wxyz[b][2] = static_cast<float>(q.y());
        p.rotation_wxyz[b][3] = static_cast<float>(q.z());
    }
    for (int hand = 0; hand < 2; ++hand) {
        const Side side = static_cast<Side>(hand);
        const int hb = model.hand_body(side);
        const StickInHand &st = model.stick(side);
        const Eigen::Vector3d tip = frames.origin_m[hb] + frames.rotation[hb] * st.tip_m;
        const Eigen::Vector3d butt = frames.origin_m[hb] + frames.rotation[hb] * st.butt_m;
        for (int i = 0; i < 3; ++i) {
            p.stick_tip_m[hand][i] = static_cast<float>(tip[i]);
            p.stick_butt_m[hand][i] = static_cast<float>(butt[i]);
        }
    }
    for (int i = 0; i < 3; ++i)
        p.drum_center_m[i] = static_cast<float>(options_.scene.drum.center_m[i]);
    p.drum_radius_m = static_cast<float>(options_.scene.drum.radius_m);
}

void Performance::tip(int hand, TipState &out) const
{
    const Side side = static_cast<Side>(hand & 1);
    out.time_s = time_s();
    out.hand = hand & 1;
    const Eigen::Vector3d p = scene().tip_position(side);
    const Eigen::Vector3d v = scene().tip_velocity(side);
    for (int i = 0; i < 3; ++i) {
        out.position_m[i] = static_cast<float>(p[i]);
        out.velocity_mps[i] = static_cast<float>(v[i]);
    }
}

// ---- score mode (docs/perform.md) ---------------------------------------------

namespace
{
// The stick-tip sits this far above the membrane plane when its bead touches
// it: the bead's centre is one tip radius above, the end point a further
// r * (stick axis . up) (the stick points down at the head, so less than 2 r).
// The plan's strike points are raised by it, so that the planned tip target
// on the beat is the tip at first contact (strike_depth_m is then measured
// from the contact, not from the plane).
double contact_height_m(double tip_radius_m, const Eigen::Vector3d &stick_dir_world)
{
    return tip_radius_m * (1.0 + stick_dir_world.normalized().y());
}
} // namespace

PerformanceOptions::PerformanceOptions()
{
    scene.sticks = StickMount::fulcrum;
}

ScorePerformOptions::ScorePerformOptions()
{
    // Measured in docs/perform.md: the target dips this far below the first
    // contact on each beat, and is sampled the controller's lag ahead.
    // With the sticks on their fulcrum the stick's own inertia carries the
    // bead into the head: the hand's target turns at the contact height
    // (4 mm below it, as with welded sticks, left the hand pressing on after
    // soft strokes; docs/perform.md).
    plan.strike_depth_m = 0.0;
    // But a fast stroke's hand turns ~2 ms before its target does (the
    // tracking lag): at 7 m/s the stick then stopped 5 mm short of the head
    // and the note was missed. The target aims through the head by 2.5 ms
    // of the planned impact speed above 1.5 m/s (14 mm at 7 m/s; softer
    // strokes aimed deeper pressed on the head in joint mode). Measured on
    // 200 random scores, docs/perform.md.
    plan.strike_aim_s = 0.0025;
    plan.strike_aim_from_mps = 1.5;
    time_advance_s = 0.0;
    // Algorithm 2 for strokes: `ictusd track`'s CMU-tuned velocity term
    // (c = 0.1 s) feeds the 1 kHz tip velocity back and makes the tip chatter
    // at strike speeds (impact speeds +-20 % off the plan, not monotonic in
    // the dynamics); without it and with gain 4 they are within ~1 %.
    cartesian.gain = 4.0;
    // With the sticks on their fulcrum the tip error is the held tip's (the
    // stick's own swing is not fed back), and a small velocity term damps the
    // hand's chatter after soft strokes (docs/perform.md, measured).
    cartesian.velocity_gain_s = 0.03;
    // The kinematic IK turns no joint faster than this (CartesianOptions):
    // the 99th percentile of the strokes' own joint rates (docs/perform.md).
    cartesian.max_joint_speed_rad_s = 35.0;
}

namespace
{
// The plan's frame for a drum: the shared frames of docs/perform.md, facing
// `forward` with `right` to the performer's right, the membrane raised by the
// tip's contact height (see contact_height_m).
PerformerFrame frame_for(const DrumParams &drum, double tip_radius_m, const Eigen::Vector3d &right,
                         const Eigen::Vector3d &forward)
{
    const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
    PerformerFrame f = performer_frame_for_drum(
        drum.center_m + contact_height_m(tip_radius_m, kDefaultStickDirection) * up, drum.radius_m);
    f.right = right;
    f.forward = forward;
    return f;
}
} // namespace

// Score mode: the default body (stick_capture.hpp), standing with the hips
// 0.9 m up, pelvis welded, facing +Z, in `pose` (joint rotations) or with the
// arms solved to hold the sticks at the rest tips. Reads only `options`.
std::unique_ptr<Performance::ScoreRig>
Performance::make_score_rig(const PerformanceOptions &options,
                            const std::vector<Eigen::Quaterniond> *pose) const
{
    const Skeleton skeleton = default_skeleton();
    Motion motion;
    motion.frame_rate_hz = 100.0;
    motion.root_position_m.push_back(Eigen::Vector3d(0.0, 0.9, 0.0));
    motion.local_rotation.emplace_back(skeleton.joints.size(), Eigen::Quaterniond::Identity());
    const CharacterModel model = CharacterModel::from_skeleton(skeleton, options.character);
    auto rig = std::make_unique<ScoreRig>(model, options.score.ik_limit_margin_deg * M_PI / 180.0);
    ScoreRig &r = *rig;
    r.body = model.pose_from_motion(motion, 0);

    // The drum in front of the performer: from the midpoint of the shoulders,
    // drum_forward_m along the facing direction and drum_below_m down, unless
    // a centre was given.
    BodyFrames frames;
    model.forward(r.body, frames);
    const Eigen::Vector3d shoulder[2] = {frames.origin_m[model.body_index("l_upper_arm")],
                                         frames.origin_m[model.body_index("r_upper_arm")]};
    Eigen::Vector3d left = shoulder[0] - shoulder[1];
    left.y() = 0.0;
    left.normalize();
    const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
    const Eigen::Vector3d forward = left.cross(up);
    SceneOptions scene = options.scene;
    // A joint pushed outside its range of motion (the stick's reactions on the
    // wrist) meets its stop 1 degree out, which takes the whole overshoot
    // back in one step (docs/perform.md, "Joint limits").
    scene.stop_margin_rad = std::min(scene.stop_margin_rad, 1.0 * M_PI / 180.0);
    scene.stop_erp = 1.0;
    scene.stop_inelastic = true;
    // The legs hang off the welded pelvis and hold no stick: placed at their
    // targets, not simulated (SceneOptions::legs_kinematic, docs/perform.md).
    scene.legs_kinematic = true;
    scene.pelvis_kinematic = true; // welded: fixed, without the weld's rows
    if (options.drum_auto)
        scene.drum.center_m = 0.5 * (shoulder[0] + shoulder[1]) +
                              options.score.drum_forward_m * forward -
                              options.score.drum_below_m * up;
    r.drum_center_m = scene.drum.center_m;
    r.frame = frame_for(scene.drum, options.character.stick.tip_radius_m, -left, forward);

    // Start: the arms solved to hold the sticks at the rest tips (or the
    // pose the old rig was in, when a grip change rebuilds it).
    CharacterPose initial = r.body;
    if (pose && pose->size() == initial.local.size())
        initial.local = *pose;
    else {
        const std::array<Eigen::Vector3d, 2> directions = {rest_stick_direction(r.frame, 0),
                                                           rest_stick_direction(r.frame, 1)};
        Tracker::solve_arms(model, r.ik_limits, options.score.cartesian.ik, r.frame.rest_tip_m,
                            initial, &directions);
    }
    r.base_gains = default_gains(model, initial, options.gains);
    // The trunk is compliant: lumbar and thorax under eq. 1 at kTrunkHz (the
    // arms' natural frequency is options.gains'), so they sway under the arms'
    // reactions (docs/perform.md, "The trunk").
    const double trunk_ratio = kTrunkHz / options.gains.natural_frequency_hz;
    if (trunk_ratio < 1.0)
        for (int j : {r.lumbar, r.thorax}) {
            r.base_gains[j].kp_nm_per_rad *= trunk_ratio * trunk_ratio;
            r.base_gains[j].kd_nm_s_per_rad *= trunk_ratio;
        }
    r.step_body = r.body;
    r.gains = r.base_gains; // scaled when installed
    CartesianOptions co = options.score.cartesian;
    co.reference_has_arms = false; // the body's reference has no arm motion
    r.tracker =
        std::make_unique<Tracker>(r.model, scene, initial, r.gains, r.range_of_motion.refs(),
                                  options.score.mode, co, options.gains, &r.ik_limits);
    r.tips.has_position = true;
    for (int s = 0; s < 2; ++s)
        r.tips.position_m[s] = r.tracker->scene().tip_position(static_cast<Side>(s));
    return rig;
}

void Performance::install_score_rig(std::unique_ptr<ScoreRig> rig, bool keep_pose)
{
    const double previous_time = score_rig_ ? time_s() : 0.0;
    TrackMode mode = options_.score.mode;
    if (score_rig_) {
        divergences_before_ += score_rig_->tracker->scene().divergences();
        mode = score_rig_->tracker->mode();
        if (keep_pose) {
            // Built from the pose of a while ago (background work): it starts
            // from the pose the old rig is in now, at rest, as a rebuild in
            // place would.
            score_rig_->tracker->scene().local_rotations(pose_scratch_);
            CharacterPose now = rig->body;
            now.local = pose_scratch_;
            rig->tracker->scene().reset(now);
            for (int s = 0; s < 2; ++s)
                rig->tips.position_m[s] = rig->tracker->scene().tip_position(static_cast<Side>(s));
        }
    }
    std::swap(score_rig_, rig);
    ScoreRig &r = *score_rig_;
    // The live drum and gains win over those the rig was built with.
    options_.scene.drum.center_m = r.drum_center_m;
    r.tracker->scene().set_drum(options_.scene.drum);
    r.frame = frame_for(options_.scene.drum, options_.character.stick.tip_radius_m, r.frame.right,
                        r.frame.forward);
    scale_gains(r.base_gains, gain_scale_, r.gains);
    r.tracker->scene().set_gains(r.gains);
    set_grips(options_.grip_firmness);
    r.tracker->set_mode(mode);
    if (!keep_pose)
        rest_from_m_ = r.frame.rest_tip_m;
    time_offset_s_ = previous_time;
    detector_.reset(membrane_of(scene()));
    if (rig && worker_) {
        auto old = std::make_unique<Result>();
        old->score_rig = std::move(rig);
        worker_->discard(std::move(old));
    }
}

const PerformerFrame &Performance::performer_frame() const
{
    static const PerformerFrame none;
    return score_rig_ ? score_rig_->frame : none;
}

TrackMode Performance::mode() const
{
    return score_rig_ ? score_rig_->tracker->mode() : TrackMode::joint;
}

Eigen::Vector3d Performance::tip_target(int hand) const
{
    return score_rig_ ? score_rig_->tips.position_m[hand & 1] : tip_position(hand);
}

Eigen::Vector3d Performance::tip_position(int hand) const
{
    return scene().tip_position(static_cast<Side>(hand & 1));
}

std::unique_ptr<Performance::PlanState> Performance::make_plan(std::shared_ptr<const Score> score,
                                                               const PerformerFrame &frame,
                                                               const PlanOptions &options) const
{
    // Planning allocates (the whole trajectory at 1 kHz): the worker's job
    // in `ictusd run`, inline in render.
    auto ps = std::make_unique<PlanState>();
    ps->plan = plan_performance(*score, *db_, frame, options);
    ps->score = std::move(score);
    const GesturePlan &plan = ps->plan;
    // Per note: its beat, how long before it the target reaches the contact
    // (the lead that target_at removes) and its approach speed there.
    ps->planned_speed_mps.assign(plan.notes.size(), 0.0);
    for (int s = 0; s < 2; ++s) {
        for (size_t i = 0; i < plan.notes.size(); ++i) {
            const PlannedNote &n = plan.notes[i];
            if (static_cast<int>(n.hand) != s)
                continue;
            auto height = [&](double t) {
                return (plan.tips.sample(s, t) - frame.membrane_center_m).dot(frame.up);
            };
            double lead = 0.0;
            constexpr double kSearch_s = 0.05, kStep_s = 1e-4;
            if (height(n.time_s) < 0.0)
                for (double back = kStep_s; back <= kSearch_s; back += kStep_s) {
                    const double h0 = height(n.time_s - back),
                                 h1 = height(n.time_s - back + kStep_s);
                    if (h0 >= 0.0) {
                        lead = back - kStep_s * h0 / (h0 - h1); // linear between the two
                        break;
                    }
                }
            constexpr double kApproach_s = 0.002;
            const double t_contact = n.time_s - lead;
            const double v =
                std::max(0.0, (height(t_contact - kApproach_s) - height(t_contact)) / kApproach_s);
            ps->beats[s].push_back(n.time_s);
            ps->lead_s[s].push_back(lead);
            ps->approach_mps[s].push_back(v);
            // A buzz's press is played with the loosest grip from its strike on
            // (the downswing keeps the performance's grip: a loose stick lags a
            // fast hand), unless the note gives its own.
            const bool press = n.firmness < 0.0 && n.nuance == Nuance::buzz;
            ps->firmness[s].push_back(press ? kBuzzGripFirmness : n.firmness);
            ps->press[s].push_back(press);
            ps->planned_speed_mps[i] = v;
        }
        // Down strokes: a stroke followed soon by a much softer one of the
        // same hand, neither with a grip of its own.
        const size_t count = ps->beats[s].size();
        ps->down[s].assign(count, false);
        for (size_t k = 0; k + 1 < count; ++k)
            ps->down[s][k] = ps->firmness[s][k] < 0.0 && ps->firmness[s][k + 1] < 0.0 &&
                             !ps->press[s][k + 1] &&
                             ps->beats[s][k + 1] - ps->beats[s][k] <= kDownStrokeGap_s &&
                             ps->approach_mps[s][k + 1] < kDownStrokeRatio * ps->approach_mps[s][k];
    }
    return ps;
}

void Performance::install_plan(std::unique_ptr<PlanState> plan, bool start_now)
{
    std::swap(plan_state_, plan);
    plan_ = &plan_state_->plan;
    if (start_now) {
        plan_active_ = true;
        playing_ = true;
        plan_time_s_ = 0.0;
        plan_origin_s_ = time_s();
    }
    // else: a plan under way goes on from where it was (the notes keep their times)
    if (plan && worker_) {
        auto old = std::make_unique<Result>();
        old->plan = std::move(plan);
        worker_->discard(std::move(old));
    }
}

double Performance::tempo_bpm() const
{
    if (!score_mode())
        return options_.tempo_bpm;
    if (plan_active_ && plan_state_ && plan_state_->score) {
        const TempoMap &map = plan_state_->score->tempo;
        const double beat = map.beat_at_time(std::max(0.0, plan_time_s_ - plan_->score_start_s));
        return map.tempo_at_beat(std::max(0.0, beat));
    }
    return start_bpm_ > 0.0 ? start_bpm_ : score_first_bpm_ * tempo_scale_;
}

double Performance::planned_impact_speed_mps(size_t note) const
{
    return plan_state_ && note < plan_state_->planned_speed_mps.size()
               ? plan_state_->planned_speed_mps[note]
               : 0.0;
}

void Performance::start_score()
{
    if (!score_rig_)
        throw CharacterError("play: not in score mode");
    if (worker_ && worker_->pending())
        throw CharacterError("play: background work under way; use apply()");
    install_plan(make_plan(score_, score_rig_->frame, options_.score.plan), true);
}

// ---- background work -----------------------------------------------------------

std::unique_ptr<Performance::Job> Performance::plan_job(const Command &origin, bool start_now) const
{
    auto job = std::make_unique<Job>();
    job->kind = start_now ? Job::Kind::play : Job::Kind::replan;
    job->origin = origin;
    if (start_now && builder_->statements() > 0)
        job->statements = std::make_unique<ScoreBuilder>(*builder_);
    job->frame = score_rig_->frame;
    job->options.score.plan = options_.score.plan;
    job->tempo_scale = tempo_scale_;
    return job;
}

std::unique_ptr<Performance::Result> Performance::execute(Job &job)
{
    auto r = std::make_unique<Result>();
    r->kind = job.kind;
    r->origin = job.origin;
    try {
        switch (job.kind) {
        case Job::Kind::play: {
            // A faulty score throws here: nothing changes, nothing plays.
            std::shared_ptr<const Score> score =
                job.statements ? std::make_shared<const Score>(job.statements->finish()) : score_;
            // Played at the live tempo scale (/ictus/tempo): its map times
            // the scale, or the scale that starts it at start_bpm.
            const double first = score->tempo.tempo_at_beat(0.0);
            const double scale = job.start_bpm > 0.0 ? job.start_bpm / first : job.tempo_scale;
            std::shared_ptr<const Score> played =
                scale == 1.0 ? score
                             : std::make_shared<const Score>(scale_score_from(*score, 0.0, scale));
            r->plan = make_plan(played, job.frame, job.options.score.plan);
            r->tempo_scale = scale;
            r->first_bpm = first;
            score_ = std::move(score); // the current score from now on
            played_ = std::move(played);
            break;
        }
        case Job::Kind::replan:
            // The score as it plays (at its tempo scale), on the new frame.
            r->plan = make_plan(played_ ? played_ : score_, job.frame, job.options.score.plan);
            break;
        case Job::Kind::tempo: {
            // The score as it plays, from its first beat that no hand has
            // begun to play toward: the strokes under way keep their shape
            // and time.
            std::shared_ptr<const Score> base = played_ ? played_ : score_;
            double until_s = 0.0;
            const double split =
                tempo_split_beat(*base, job.score_start_s, job.options.score.plan.blend_margin,
                                 job.plan_now_s + kTempoLatency_s, until_s);
            const double factor = job.bpm / base->tempo.tempo_at_beat(
                                                std::isfinite(split) ? split : base->length_beats);
            r->tempo_scale = job.tempo_scale * factor;
            r->based_on = base;
            if (std::isfinite(split) && split < base->length_beats) {
                auto scaled = std::make_shared<const Score>(scale_score_from(*base, split, factor));
                r->plan = make_plan(scaled, job.frame, job.options.score.plan);
                r->valid_until_s = until_s;
                played_ = std::move(scaled);
            }
            break;
        }
        case Job::Kind::score_rig:
            r->score_rig = make_score_rig(job.options, &job.pose);
            break;
        case Job::Kind::clip_rig:
            r->rig = make_clip_rig(job.options);
            r->drum_center_m = job.options.scene.drum.center_m;
            break;
        }
    } catch (const std::exception &e) {
        r->error = e.what();
        r->plan.reset();
        r->score_rig.reset();
        r->rig.reset();
    }
    return r;
}

bool Performance::submit(std::unique_ptr<Job> job, std::string *why)
{
    if (!worker_)
        return install(execute(*job), why);
    if (!worker_->submit(std::move(job))) {
        if (why)
            *why = "busy: 64 changes are waiting to be planned; send fewer";
        return false;
    }
    return true;
}

bool Performance::install(std::unique_ptr<Result> r, std::string *why)
{
    if (r->kind == Job::Kind::play)
        play_pending_ = false;
    if (!r->error.empty()) {
        if (why)
            *why = r->error;
        return false;
    }
    switch (r->kind) {
    case Job::Kind::play:
        install_plan(std::move(r->plan), true);
        tempo_scale_ = r->tempo_scale;
        score_first_bpm_ = r->first_bpm;
        break;
    case Job::Kind::tempo:
        if (r->plan && plan_active_) {
            // Planned on the score under way, and in time (the plan clock
            // has not passed the first stroke that changes).
            if (!plan_state_ || plan_state_->score != r->based_on) {
                if (why)
                    *why = "tempo: the score changed while the new tempo was planned; send it "
                           "again";
                return false;
            }
            if (plan_time_s_ > r->valid_until_s) {
                if (why)
                    *why = "tempo: planned too late (the performance passed the stroke it would "
                           "change); send it again";
                return false;
            }
            install_plan(std::move(r->plan), false);
        }
        tempo_scale_ = r->tempo_scale;
        break;
    case Job::Kind::replan:
        // Only a plan under way is replaced; a stopped one stays stopped
        // (the next play plans on the frame of its time).
        if (plan_active_)
            install_plan(std::move(r->plan), false);
        break;
    case Job::Kind::score_rig:
        install_score_rig(std::move(r->score_rig), true);
        break;
    case Job::Kind::clip_rig:
        if (options_.drum_auto)
            options_.scene.drum.center_m = r->drum_center_m;
        install_clip_rig(std::move(r->rig));
        playing_ = true;
        break;
    }
    if (worker_)
        worker_->discard(std::move(r));
    return true;
}

void Performance::take_results()
{
    if (!worker_)
        return;
    while (std::unique_ptr<Result> r = worker_->take()) {
        const Command origin = r->origin;
        std::string why;
        if (!install(std::move(r), &why))
            refuse_later(origin, why);
    }
}

void Performance::refuse_later(const Command &origin, const std::string &why)
{
    if (refusals_.size() >= 64)
        refusals_.erase(refusals_.begin()); // nobody reads them: keep the newest
    Refusal f;
    f.peer_ipv4 = origin.peer_ipv4;
    f.peer_port = origin.peer_port;
    std::snprintf(f.address, sizeof f.address, "%s", origin.address);
    std::snprintf(f.why, sizeof f.why, "%s", why.c_str());
    refusals_.push_back(f);
}

bool Performance::pop_refusal(Refusal &out)
{
    if (refusals_.empty())
        return false;
    out = refusals_.front();
    refusals_.erase(refusals_.begin());
    return true;
}

void Performance::set_background_work(bool on)
{
    if (on && !worker_)
        worker_ = std::make_unique<Worker>(*this);
    else if (!on)
        worker_.reset();
}

bool Performance::work_pending() const
{
    return worker_ && worker_->pending();
}

void Performance::start_rest_move()
{
    set_grips(options_.grip_firmness);
    for (int s = 0; s < 2; ++s)
        rest_from_m_[s] = score_rig_->tips.position_m[s];
    rest_move_start_s_ = time_s();
}

Eigen::Vector3d Performance::direction_at(int s, double t) const
{
    const GesturePlan &plan = *plan_;
    const std::vector<double> &times = plan.tips.time_s;
    const std::vector<Eigen::Vector3d> &dir = plan.stick_dir[s];
    if (times.empty() || dir.size() != times.size())
        return rest_direction(s);
    const double tp = times.front() + std::clamp(plan_time_of(s, t), 0.0, plan.tips.duration_s());
    const size_t k = static_cast<size_t>(
        std::min<std::ptrdiff_t>(std::upper_bound(times.begin(), times.end(), tp) - times.begin(),
                                 static_cast<std::ptrdiff_t>(times.size()) - 1));
    if (k == 0)
        return dir.front();
    const double w = (tp - times[k - 1]) / std::max(times[k] - times[k - 1], 1e-12);
    const Eigen::Vector3d d = (1.0 - w) * dir[k - 1] + w * dir[k];
    return d.norm() > 1e-9 ? Eigen::Vector3d(d.normalized()) : dir[k];
}

Eigen::Vector3d Performance::rest_direction(int s) const
{
    return rest_stick_direction(score_rig_->frame, s);
}

// The plan time whose target the hand follows at plan time t (target_at's delay).
double Performance::plan_time_of(int s, double t) const
{
    const std::vector<double> &beats = plan_state_->beats[s];
    if (beats.empty())
        return t;
    auto it = std::upper_bound(beats.begin(), beats.end(), t);
    const size_t k = static_cast<size_t>(it - beats.begin()); // beats[k-1] <= t < beats[k]
    const std::vector<double> &lead = plan_state_->lead_s[s];
    double delay;
    if (k == 0)
        delay = lead.front();
    else if (k == beats.size())
        delay = lead.back();
    else {
        const double w = (t - beats[k - 1]) / (beats[k] - beats[k - 1]);
        delay = (1.0 - w) * lead[k - 1] + w * lead[k];
    }
    return t - delay;
}

Eigen::Vector3d Performance::target_at(int s, double t) const
{
    const GesturePlan &plan = *plan_;
    const std::vector<double> &beats = plan_state_->beats[s];
    if (beats.empty())
        return plan.tips.sample(s, t);
    // The contact on the beat: the plan's target passes strike_depth_m below
    // the first contact at the beat, so it reaches the contact a little
    // before (depth / speed: 4 ms for a soft 1 m/s stroke). Each note's
    // target is delayed by that lead, the delay interpolated linearly in
    // time between the hand's beats (a rate change of well under 2 %).
    const double tp = plan_time_of(s, t);
    const Eigen::Vector3d p = plan.tips.sample(s, tp);
    double tc = options_.score.rebound_s;
    if (tc <= 0.0)
        return p;
    // The scripted rebound (off by default, --rebound: the stick on its
    // fulcrum rebounds by itself). The units of the database lift slowly
    // after the strike, so an arm driven down at the impact speed toward a
    // target that barely rises presses into the head for 30-70 ms
    // (docs/perform.md). After each beat the target gets an upward offset
    //     r(tau) = v tau exp(-tau / tc),
    // v the target's approach speed at the beat: it leaves the head at the
    // impact speed, peaks v tc / e above the unit at tau = tc and fades
    // smoothly (never faster downward than 0.14 v), so the hand does not
    // strike again.
    auto it = std::upper_bound(beats.begin(), beats.end(), tp);
    if (it == beats.begin())
        return p;
    const size_t j = static_cast<size_t>(it - beats.begin()) - 1;
    const double beat = beats[j];
    if (it != beats.end())
        tc = std::min(tc, 0.1 * (*it - beat)); // faded out (< 5e-4 v tc) by the next beat
    const double tau = tp - beat;
    if (tau >= 20.0 * tc)
        return p;
    return p + plan_state_->approach_mps[s][j] * tau * std::exp(-tau / tc) * score_rig_->frame.up;
}

double Performance::BodyStats::trunk_rms_deg() const
{
    return steps > 0 ? std::sqrt(trunk_sum_sq_deg2 / static_cast<double>(steps)) : 0.0;
}

void Performance::measure_body()
{
    const ScoreRig &r = *score_rig_;
    const Scene &scene = r.tracker->scene();
    scene.local_rotations(pose_scratch_);
    int joint = -1;
    const double e = r.range_of_motion.max_excursion_rad(pose_scratch_, &joint) * 180.0 / M_PI;
    if (e > body_stats_.max_limit_excursion_deg) {
        body_stats_.max_limit_excursion_deg = e;
        body_stats_.max_limit_joint = r.model.joint_name(joint);
    }
    // The thorax relative to the pelvis: lumbar then thorax joint.
    const double trunk = rotation_angle_between(Eigen::Quaterniond::Identity(),
                                                pose_scratch_[r.lumbar] * pose_scratch_[r.thorax]) *
                         180.0 / M_PI;
    body_stats_.trunk_max_deg = std::max(body_stats_.trunk_max_deg, trunk);
    body_stats_.trunk_sum_sq_deg2 += trunk * trunk;
    ++body_stats_.steps;
}

// The trunk takes part in the strokes: it leans forward as the sticks go
// down (kTrunkLean_rad_per_m of the mean tip target's drop below the rest
// tips) and turns the shoulder of the higher stick back (kTrunkTwist_rad_per_m
// of the difference of the tips' heights), 40 % at the lumbar joint and 60 %
// at the thorax; eq. 1 then follows it with the trunk's compliant gains.
void Performance::trunk_synergy(ScoreRig &r) const
{
    const PerformerFrame &f = r.frame;
    const TipTargets &tips = r.tips;
    auto height = [&](int s) { return (tips.position_m[s] - f.membrane_center_m).dot(f.up); };
    const double rest = 0.5 * ((f.rest_tip_m[0] - f.membrane_center_m).dot(f.up) +
                               (f.rest_tip_m[1] - f.membrane_center_m).dot(f.up));
    const int right = static_cast<int>(Side::right), left = static_cast<int>(Side::left);
    const double lean = kTrunkLean_rad_per_m * (rest - 0.5 * (height(left) + height(right)));
    const double twist = -kTrunkTwist_rad_per_m * (height(right) - height(left));
    // Lean about the performer's left axis (forward flexion), twist about up.
    const Eigen::Vector3d left_axis = -f.right;
    const Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::AngleAxisd(twist, f.up)) *
                                 Eigen::Quaterniond(Eigen::AngleAxisd(lean, left_axis));
    const Eigen::Quaterniond part = Eigen::Quaterniond::Identity().slerp(0.4, q);
    r.step_body.local[r.lumbar] = r.body.local[r.lumbar] * part;
    r.step_body.local[r.thorax] = r.body.local[r.thorax] * part.conjugate() * q;
}

void Performance::set_grips(double firmness)
{
    Scene &scene = score_rig_ ? score_rig_->tracker->scene() : rig_->tracker->scene();
    for (int s = 0; s < 2; ++s) {
        scene.set_grip_firmness(static_cast<Side>(s), firmness);
        applied_firmness_[s] = firmness;
    }
}

// Each hand holds its stick as its note asks (ScoreNote::firmness, else the
// performance's), from halfway between the hand's previous beat and the
// note's to halfway to its next: the grip of a stroke holds through its
// strike and what follows it (a press).
void Performance::apply_note_grips(double t)
{
    PlanState &ps = *plan_state_;
    for (int s = 0; s < 2; ++s) {
        const std::vector<double> &beats = ps.beats[s];
        if (beats.empty())
            continue;
        size_t k = std::min(ps.grip_note[s], beats.size() - 1);
        while (k + 1 < beats.size() && t > 0.5 * (beats[k] + beats[k + 1]))
            ++k;
        const bool before_press = ps.press[s][k] && t < beats[k];
        // A down stroke holds the stick firm from its strike to the next beat.
        const bool down = t >= beats[k] ? ps.down[s][k] : k > 0 && ps.down[s][k - 1];
        const double f = down                                        ? kDownStrokeGripFirmness
                         : ps.firmness[s][k] >= 0.0 && !before_press ? ps.firmness[s][k]
                                                                     : options_.grip_firmness;
        if (f != applied_firmness_[s]) {
            score_rig_->tracker->scene().set_grip_firmness(static_cast<Side>(s), f);
            applied_firmness_[s] = f;
        }
        ps.grip_note[s] = k;
    }
}

int Performance::step_score(StrikeEvent out[2])
{
    ScoreRig &r = *score_rig_;
    const double h = options_.scene.step_s;
    TipTargets &tips = r.tips;
    if (plan_active_) {
        // Targets for the end of this step, time_advance_s ahead (the lag).
        plan_time_s_ += h;
        const GesturePlan &plan = *plan_;
        const double t = plan_time_s_ + options_.score.time_advance_s;
        // V^T by a central difference over one plan sample (1 ms): the plan
        // is piecewise linear between its samples.
        const double dt = 1.0 / options_.score.plan.rate_hz;
        for (int s = 0; s < 2; ++s) {
            tips.position_m[s] = target_at(s, t);
            tips.velocity_mps[s] = (target_at(s, t + dt) - target_at(s, t - dt)) / (2.0 * dt);
            tips.stick_direction[s] = direction_at(s, t);
        }
        tips.has_direction = true;
        apply_note_grips(plan_time_s_);
        if (plan_time_s_ >= plan.duration_s) {
            plan_active_ = false;
            playing_ = false;
            start_rest_move();
        }
    } else {
        // Between plans: a smooth move (0.6 s) to the rest tips, then hold.
        const double move_s = options_.score.plan.return_time_s;
        const double x = (time_s() + h - rest_move_start_s_) / move_s;
        const double w = smoothstep(x);
        const double dw = x > 0.0 && x < 1.0 ? 6.0 * x * (1.0 - x) / move_s : 0.0;
        for (int s = 0; s < 2; ++s) {
            const Eigen::Vector3d d = r.frame.rest_tip_m[s] - rest_from_m_[s];
            tips.position_m[s] =
                x >= 1.0 ? r.frame.rest_tip_m[s] : Eigen::Vector3d(rest_from_m_[s] + w * d);
            tips.velocity_mps[s] = dw * d;
            tips.stick_direction[s] = rest_direction(s);
        }
        tips.has_direction = true;
    }
    trunk_synergy(r);
    r.tracker->step(r.step_body, &tips, true);
    const int n = detect_strikes(detector_, r.tracker->scene(), out, time_offset_s_);
    measure_body();
    return n;
}

bool Performance::apply_score(const Command &c, std::string *why)
{
    auto fail = [&](const std::string &text) {
        if (why)
            *why = text;
        return false;
    };
    ScoreRig &r = *score_rig_;
    try {
        switch (c.kind) {
        case CommandKind::play: {
            // Finished and planned by the worker (run) or here (render):
            // a faulty score is refused, nothing changes, nothing plays.
            auto job = plan_job(c, true);
            job->start_bpm = start_bpm_;
            start_bpm_ = 0.0;
            play_pending_ = true; // until its plan is installed or refused
            return submit(std::move(job), why);
        }
        case CommandKind::stop:
            // The performance ends; the sticks go back to their rest.
            if (plan_active_)
                start_rest_move();
            plan_active_ = false;
            playing_ = false;
            return true;
        case CommandKind::tempo: {
            // A live scale of the score's tempo map (docs/osc.md): under way,
            // from the first beat no hand has begun to play toward; stopped,
            // the next play starts at this tempo.
            if (!plan_active_ && !play_pending_) {
                start_bpm_ = c.value;
                return true;
            }
            auto job = plan_job(c, false);
            job->kind = Job::Kind::tempo;
            job->bpm = c.value;
            job->plan_now_s = plan_active_ ? plan_time_s_ : 0.0;
            job->score_start_s = plan_ ? plan_->score_start_s : options_.score.plan.lead_in_s;
            return submit(std::move(job), why);
        }
        case CommandKind::nuance:
            // The nuance of the statements that follow and name none.
            default_nuance_ = nuance_from_string(c.text);
            builder_->set_default_nuance(default_nuance_);
            return true;
        case CommandKind::grip: {
            // The character is rebuilt (by the worker, in run) in its current
            // pose with the sticks in the new grip, and takes over from the
            // pose it is in then; the plan, in tip space, goes on.
            options_.character.grip = grip_from_string(c.text);
            auto job = std::make_unique<Job>();
            job->kind = Job::Kind::score_rig;
            job->origin = c;
            job->options = options_;
            r.tracker->scene().local_rotations(job->pose);
            return submit(std::move(job), why);
        }
        case CommandKind::mode:
            options_.score.mode = track_mode_from_string(c.text);
            r.tracker->set_mode(options_.score.mode);
            return true;
        case CommandKind::gains: {
            const double scale[2] = {c.value, c.value2};
            if (!check_gains(scale, why))
                return false;
            gain_scale_[0] = c.value;
            gain_scale_[1] = c.value2;
            last_gains_ = c;
            scale_gains(r.base_gains, gain_scale_, r.gains);
            r.tracker->scene().set_gains(r.gains);
            return true;
        }
        case CommandKind::drum_radius:
        case CommandKind::drum_tension: {
            DrumParams drum = options_.scene.drum;
            if (c.kind == CommandKind::drum_radius) {
                if (!(c.value > options_.character.stick.tip_radius_m * 2.0))
                    return fail("drum radius: must exceed the stick tip's diameter");
                drum.radius_m = c.value;
            } else {
                drum.tension_n_per_m = c.value;
            }
            r.tracker->scene().set_drum(drum); // throws naming the value: nothing changed
            options_.scene.drum = drum;
            // At once on the live scene (its contact law) and the detector;
            // the plan's frame follows the membrane, and a plan under way
            // (or on its way) is planned again on it and goes on from where
            // it is (the notes keep their times). No rebuild.
            detector_.set_membrane(membrane_of(scene()));
            r.frame = frame_for(options_.scene.drum, options_.character.stick.tip_radius_m,
                                r.frame.right, r.frame.forward);
            if (plan_active_ || work_pending())
                return submit(plan_job(c, false), why);
            return true;
        }
        case CommandKind::drum_density:
            options_.drum_density_kg_per_m2 = c.value;
            return true;
        case CommandKind::grip_firmness:
            // The notes without a firmness of their own take it at once.
            options_.grip_firmness = c.value;
            if (plan_active_) {
                applied_firmness_[0] = applied_firmness_[1] = -1.0;
                apply_note_grips(plan_time_s_);
            } else {
                set_grips(c.value);
            }
            return true;
        case CommandKind::score:
            // Parsed now (an error names the statement and column); played at
            // the next /ictus/play. A score with a faulty statement never plays.
            builder_->add_statement(c.text);
            return true;
        case CommandKind::score_clear:
            // A new score: its own tempi; the selected nuance still applies
            // to the statements that follow.
            builder_->reset();
            if (default_nuance_ != Nuance::legato)
                builder_->set_default_nuance(default_nuance_);
            tempo_scale_ = 1.0;
            start_bpm_ = 0.0;
            return true;
        }
    } catch (const std::exception &e) {
        return fail(e.what());
    }
    return fail("unknown command");
}

MatchSummary match_strikes(const std::vector<PlannedNote> &notes,
                           const std::vector<StrikeEvent> &strikes, double origin_s)
{
    MatchSummary m;
    m.notes.assign(notes.size(), NoteMatch{});
    std::vector<double> best(notes.size(), std::numeric_limits<double>::infinity());
    for (const StrikeEvent &e : strikes) {
        if (e.bounce) {
            ++m.bounces;
            continue;
        }
        ++m.primary_strikes;
        // The nearest note of the strike's hand.
        long nearest = -1;
        double nearest_d = std::numeric_limits<double>::infinity();
        for (size_t i = 0; i < notes.size(); ++i) {
            if (static_cast<int>(notes[i].hand) != e.hand)
                continue;
            const double d = std::abs(e.time_s - (origin_s + notes[i].time_s));
            if (d < nearest_d) {
                nearest_d = d;
                nearest = static_cast<long>(i);
            }
        }
        if (nearest < 0) {
            ++m.extra_strikes;
            continue;
        }
        const size_t i = static_cast<size_t>(nearest);
        if (m.notes[i].strike_seq >= 0)
            ++m.extra_strikes; // the note already has one: one of the two is extra
        if (nearest_d < best[i]) {
            best[i] = nearest_d;
            m.notes[i].strike_seq = e.seq;
            m.notes[i].strike_time_s = e.time_s;
            m.notes[i].error_ms = 1e3 * (e.time_s - (origin_s + notes[i].time_s));
            m.notes[i].normal_velocity_mps = e.normal_velocity_mps;
            m.notes[i].duration_ms = e.duration_ms;
        }
    }
    double sum = 0.0;
    for (const NoteMatch &n : m.notes) {
        if (n.strike_seq < 0)
            continue;
        ++m.matched_notes;
        sum += std::abs(n.error_ms);
        m.max_abs_error_ms = std::max(m.max_abs_error_ms, std::abs(n.error_ms));
    }
    m.mean_abs_error_ms = m.matched_notes > 0 ? sum / m.matched_notes : 0.0;
    return m;
}

} // namespace ictus
