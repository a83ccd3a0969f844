// A Performance of a score (score_mode.hpp): the gesture plan's stick-tip
// targets followed by the Tracker (Algorithm 2, or joint targets from IK),
// the interaction manager watching the stick tips against the drum. Score
// mode is described in docs/perform.md.
#include "score_mode.hpp"

#include "ictus/character/stick_capture.hpp"
#include "ictus/perform/perform_error.hpp"

#include <algorithm>
#include <cmath>

namespace ictus
{

// Work for run(): everything it needs is in the job (copies), so that it can
// run on the worker thread while the physics thread goes on.
class ScoreMode::Job : public Work
{
  public:
    Job(ScoreMode &mode, Kind kind, const Command &origin) : Work(kind), mode_(mode)
    {
        this->origin = origin;
    }
    std::unique_ptr<ScoreBuilder> statements;
    PerformerFrame frame;
    PerformanceOptions options;
    std::vector<Eigen::Quaterniond> pose;
    // play: the tempo scale of the score (start_bpm > 0: the scale that
    // starts it at start_bpm); tempo: the scale so far, the bpm asked for,
    // the plan's clock when it was asked and the plan time of beat 0.
    double tempo_scale = 1.0, start_bpm = 0.0, bpm = 0.0, plan_now_s = 0.0, score_start_s = 0.0;
    // The score it plays (ScoreMode::score_epoch_ when it was made).
    unsigned score_epoch = 0;

    // The result.
    std::unique_ptr<ScorePlan> plan;
    std::unique_ptr<ScoreRig> score_rig;
    // play, tempo: the tempo scale now in force and the score's own first
    // tempo (play); tempo: the score the change was planned on, and the
    // plan time until which the new plan equals the old one.
    double new_tempo_scale = 1.0, first_bpm = 0.0;
    std::shared_ptr<const Score> based_on;
    double valid_until_s = 0.0;

  protected:
    void build() override { mode_.run(*this); }
    void clear_result() override
    {
        plan.reset();
        score_rig.reset();
    }

  private:
    ScoreMode &mode_;
};

ScoreMode::ScoreMode(Performance &performance) : perf_(performance)
{
    PerformanceOptions &o = perf_.options_;
    const ScorePerformOptions &so = o.score;
    if (!(std::isfinite(so.time_advance_s) && so.time_advance_s >= 0.0 && so.time_advance_s <= 0.1))
        throw PerformError("time advance: expected 0 to 0.1 s");
    if (!(std::isfinite(so.drum_forward_m) && std::abs(so.drum_forward_m) <= 2.0 &&
          std::isfinite(so.drum_below_m) && std::abs(so.drum_below_m) <= 2.0))
        throw PerformError("drum placement: expected offsets within 2 m");
    db_ = std::make_unique<GestureDatabase>(
        so.gestures.empty() ? GestureDatabase::builtin() : GestureDatabase::load_json(so.gestures));
    builder_ = std::make_unique<ScoreBuilder>("osc");
    score_ = so.score ? so.score
                      : std::make_shared<const Score>(parse_score(
                            so.score_text.empty() ? default_score_text() : so.score_text,
                            so.score_name, so.start_tempo_bpm));
    if (!so.grip_given && !score_->notes.empty())
        o.character.grip = score_->notes.front().grip;
    score_first_bpm_ = score_->tempo.tempo_at_beat(0.0);
}

void ScoreMode::begin()
{
    install_rig(make_score_rig(perf_.options_, nullptr), false);
    const Kit &kit = perf_.options_.kit;
    if (const int k = kit_foot_piece(kit); k >= 0)
        feet_[0] =
            std::make_unique<FootPlayer>(kit.drums[static_cast<size_t>(k)], k, rig_->frame.forward);
    for (size_t k = 0; k < kit.drums.size(); ++k)
        if (kit_drum_has_pedal(kit.drums[k])) {
            feet_[1] = std::make_unique<FootPlayer>(kit.drums[k], static_cast<int>(k),
                                                    -rig_->frame.up, Side::left);
            break; // the first hi-hat (the left foot's: docs/pedal.md)
        }
    perf_.playing_ = false;
}

void ScoreMode::install_rig(std::unique_ptr<ScoreRig> rig, bool keep_pose)
{
    const double previous_time = rig_ ? perf_.time_s() : 0.0;
    PerformanceOptions &o = perf_.options_;
    TrackMode mode = o.score.mode;
    if (rig_) {
        perf_.divergences_before_ += rig_->tracker->scene().divergences();
        mode = rig_->tracker->mode();
        if (keep_pose) {
            // Built from the pose of a while ago (background work): it starts
            // from the pose the old rig is in now, at rest, as a rebuild in
            // place would.
            rig_->tracker->scene().local_rotations(pose_scratch_);
            CharacterPose now = rig->body;
            now.local = pose_scratch_;
            rig->tracker->scene().reset(now);
            for (int s = 0; s < 2; ++s)
                rig->tips.position_m[s] = rig->tracker->scene().tip_position(static_cast<Side>(s));
        }
    }
    std::swap(rig_, rig);
    ScoreRig &r = *rig_;
    use_rig(r.model, *r.tracker, r.base_gains, r.gains);
    // The live drum and gains win over those the rig was built with.
    o.scene.drum.center_m = r.drum_center_m;
    r.frame = frame_for(o.scene.drum, o.character.stick.tip_radius_m, r.frame.right,
                        r.frame.forward, &o.kit, &r.kit_drums, r.right_sole_m, &r.shoulder_m);
    r.tracker->set_mode(mode);
    if (!keep_pose) {
        rest_from_m_ = r.frame.rest_tip_m;
        rest_from_direction_ = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    }
    perf_.took_over(previous_time);
    if (rig && perf_.worker_)
        perf_.discard(std::make_unique<Disposal<ScoreRig>>(std::move(rig)));
}

void ScoreMode::install_plan(std::unique_ptr<ScorePlan> plan, bool start_now)
{
    std::swap(plan_, plan);
    if (start_now) {
        plan_active_ = true;
        perf_.playing_ = true;
        plan_time_s_ = 0.0;
        plan_origin_s_ = perf_.time_s();
        // The controller's motor noise restarts with the plan's amount and seed.
        const PlanOptions &po = perf_.options_.score.plan;
        if (plan_ && plan_->score)
            rig_->tracker->scene().set_motor_noise(humanize_amount(*plan_->score, po), po.seed);
        for (auto &foot : feet_)
            if (foot && plan_)
                foot->start(plan_->plan, plan_origin_s_, perf_.time_s());
    } else if (plan_) {
        for (auto &foot : feet_)
            if (foot)
                foot->replace(plan_->plan);
    }
    // else: a plan under way goes on from where it was (the notes keep their times)
    if (plan && perf_.worker_)
        perf_.discard(std::make_unique<Disposal<ScorePlan>>(std::move(plan)));
}

double ScoreMode::tempo_bpm() const
{
    if (plan_active_ && plan_ && plan_->score) {
        const TempoMap &map = plan_->score->tempo;
        const double beat =
            map.beat_at_time(std::max(0.0, plan_time_s_ - plan_->plan.score_start_s));
        return map.tempo_at_beat(std::max(0.0, beat));
    }
    // Stopped: the next play's, the statements received when there are any
    // (a play plays them), else the current score.
    if (start_bpm_ > 0.0)
        return start_bpm_;
    const double first =
        builder_->statements() > 0 ? builder_->first_tempo_bpm() : score_first_bpm_;
    return first * tempo_scale_;
}

double ScoreMode::planned_impact_speed_mps(size_t note) const
{
    return plan_ && note < plan_->planned_speed_mps.size() ? plan_->planned_speed_mps[note] : 0.0;
}

void ScoreMode::start_score()
{
    if (perf_.work_pending())
        throw PerformError("play: background work under way; use apply()");
    install_plan(make_score_plan(score_, *db_, rig_->frame,
                                 perf_.options_.score.plan_for(rig_->tracker->mode())),
                 true);
}

void ScoreMode::check_score() const
{
    make_score_plan(score_, *db_, rig_->frame,
                    perf_.options_.score.plan_for(rig_->tracker->mode()));
}

// ---- background work -----------------------------------------------------------

std::unique_ptr<ScoreMode::Job> ScoreMode::plan_job(const Command &origin, Work::Kind kind)
{
    auto job = std::make_unique<Job>(*this, kind, origin);
    if (kind == Work::Kind::play && builder_->statements() > 0)
        job->statements = std::make_unique<ScoreBuilder>(*builder_);
    job->frame = rig_->frame;
    job->options.score.plan = perf_.options_.score.plan_for(rig_->tracker->mode());
    job->tempo_scale = tempo_scale_;
    job->score_epoch = score_epoch_;
    return job;
}

void ScoreMode::run(Job &job)
{
    switch (job.kind) {
    case Work::Kind::play:
        run_play(job);
        break;
    case Work::Kind::replan:
        // The score as it plays (at its tempo scale), on the new frame.
        job.plan =
            make_score_plan(played_ ? played_ : score_, *db_, job.frame, job.options.score.plan);
        break;
    case Work::Kind::tempo:
        run_tempo(job);
        break;
    case Work::Kind::score_rig:
        job.score_rig = make_score_rig(job.options, &job.pose);
        break;
    default:
        break;
    }
}

void ScoreMode::run_play(Job &job)
{
    // A faulty score throws here: nothing changes, nothing plays.
    std::shared_ptr<const Score> score =
        job.statements ? std::make_shared<const Score>(job.statements->finish()) : score_;
    // Played at the live tempo scale (/ictus/tempo): its map times the
    // scale, or the scale that starts it at start_bpm.
    const double first = score->tempo.tempo_at_beat(0.0);
    const double scale = job.start_bpm > 0.0 ? job.start_bpm / first : job.tempo_scale;
    std::shared_ptr<const Score> played =
        scale == 1.0 ? score : std::make_shared<const Score>(scale_score_from(*score, 0.0, scale));
    job.plan = make_score_plan(played, *db_, job.frame, job.options.score.plan);
    job.new_tempo_scale = scale;
    job.first_bpm = first;
    score_ = std::move(score); // the current score from now on
    played_ = std::move(played);
}

void ScoreMode::run_tempo(Job &job)
{
    // The score as it plays, from its first beat that no hand has begun to
    // play toward: the strokes under way keep their shape and time.
    std::shared_ptr<const Score> base = played_ ? played_ : score_;
    double until_s = 0.0;
    const double split =
        tempo_split_beat(*base, job.score_start_s, job.options.score.plan.blend_margin,
                         job.plan_now_s + Performance::kTempoLatency_s, until_s);
    const double factor =
        job.bpm / base->tempo.tempo_at_beat(std::isfinite(split) ? split : base->length_beats);
    job.new_tempo_scale = job.tempo_scale * factor;
    job.based_on = base;
    if (std::isfinite(split) && split < base->length_beats) {
        auto scaled = std::make_shared<const Score>(scale_score_from(*base, split, factor));
        job.plan = make_score_plan(scaled, *db_, job.frame, job.options.score.plan);
        job.valid_until_s = until_s;
        played_ = std::move(scaled);
    }
}

void ScoreMode::returned(const Work &work)
{
    if (work.kind == Work::Kind::play)
        play_pending_ = false;
}

bool ScoreMode::install(Work &work, std::string *why)
{
    Job &job = static_cast<Job &>(work);
    switch (job.kind) {
    case Work::Kind::play:
        if (job.cancelled()) {
            // A stop came while it was planned: nothing starts. The score it
            // finished is the current one (its tempo with it); one never
            // planned leaves the next play its start tempo.
            // A new score begun meanwhile keeps its own tempi.
            if (job.plan) {
                if (job.score_epoch == score_epoch_)
                    tempo_scale_ = job.new_tempo_scale;
                score_first_bpm_ = job.first_bpm;
            } else if (start_bpm_ == 0.0 && job.score_epoch == score_epoch_) {
                start_bpm_ = job.start_bpm;
            }
            break;
        }
        install_plan(std::move(job.plan), true);
        plan_epoch_ = job.score_epoch;
        if (job.score_epoch == score_epoch_)
            tempo_scale_ = job.new_tempo_scale;
        score_first_bpm_ = job.first_bpm;
        break;
    case Work::Kind::tempo:
        return install_tempo(job, why);
    case Work::Kind::replan:
        // Only a plan under way is replaced; a stopped one stays stopped
        // (the next play plans on the frame of its time).
        if (plan_active_)
            install_plan(std::move(job.plan), false);
        break;
    case Work::Kind::score_rig:
        install_rig(std::move(job.score_rig), true);
        break;
    default:
        break;
    }
    return true;
}

bool ScoreMode::install_tempo(Job &job, std::string *why)
{
    if (job.plan && plan_active_) {
        // Planned on the score under way, and in time (the plan clock has
        // not passed the first stroke that changes).
        if (!plan_ || plan_->score != job.based_on)
            return refuse(why, "tempo: the score changed while the new tempo was planned; send "
                               "it again");
        if (plan_time_s_ > job.valid_until_s)
            return refuse(why, "tempo: planned too late (the performance passed the stroke it "
                               "would change); send it again");
        install_plan(std::move(job.plan), false);
    }
    // The scale stays for the next plays of the score it was asked on, not
    // for a new score begun since (that plays at its own tempi).
    if ((plan_active_ ? plan_epoch_ : job.score_epoch) == score_epoch_)
        tempo_scale_ = job.new_tempo_scale;
    return true;
}

// ---- the physics step ------------------------------------------------------------

void ScoreMode::start_rest_move()
{
    perf_.set_grips(perf_.options_.grip_firmness);
    for (int s = 0; s < 2; ++s) {
        rest_from_m_[s] = rig_->tips.position_m[s];
        rest_from_direction_[s] =
            rig_->tips.has_direction ? rig_->tips.stick_direction[s] : Eigen::Vector3d::Zero();
    }
    rest_move_start_s_ = perf_.time_s();
}

// Each hand holds its stick as its note asks (ScoreNote::firmness, else the
// performance's), from halfway between the hand's previous beat and the
// note's to halfway to its next: the grip of a stroke holds through its
// strike and what follows it (a press).
void ScoreMode::apply_note_grips(double t)
{
    ScorePlan &ps = *plan_;
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
        const double held = down ? Performance::kDownStrokeGripFirmness
                            : ps.firmness[s][k] >= 0.0 && !before_press
                                ? ps.firmness[s][k]
                                : perf_.options_.grip_firmness;
        // The downswing (from halfway after the previous beat to the note's)
        // is thrown with at least kSwingGripFirmness: a looser hold lets the
        // stick lag the hand and ring on its fulcrum, and the note lands late.
        // A soft note soon after a loud one is thrown as a down stroke's next
        // (kDownStrokeGripFirmness), whatever grips the two notes give: the
        // loose stick thrown back up by the head would fall on it early. The
        // note's own grip rules from its strike, its contact and rebound,
        // unless the hand's next stroke follows within kReboundGrip_s (a
        // drag's first grace): the hand lifts the stick for it at once.
        const bool next_soon =
            k + 1 < beats.size() && beats[k + 1] - beats[k] < Performance::kReboundGrip_s;
        const double least = t < beats[k] && ps.after_loud[s][k]
                                 ? Performance::kDownStrokeGripFirmness
                             : t < beats[k] || next_soon ? Performance::kSwingGripFirmness
                                                         : 0.0;
        const double f = std::max(held, least);
        if (f != perf_.applied_firmness_[s]) {
            rig_->tracker->scene().set_grip_firmness(static_cast<Side>(s), f);
            perf_.applied_firmness_[s] = f;
        }
        ps.grip_note[s] = k;
    }
}

// Targets for the end of this step, time_advance_s ahead (the lag).
void ScoreMode::follow_plan(TipTargets &tips)
{
    const ScorePerformOptions &so = perf_.options_.score;
    plan_time_s_ += perf_.options_.scene.step_s;
    const ScorePlan &ps = *plan_;
    const Eigen::Vector3d &up = rig_->frame.up;
    const double t = plan_time_s_ + so.time_advance_s;
    // V^T by a central difference over one plan sample (1 ms): the plan is
    // piecewise linear between its samples.
    const double dt = 1.0 / so.plan.rate_hz;
    for (int s = 0; s < 2; ++s) {
        tips.position_m[s] = ps.target_at(s, t, so.rebound_s, up);
        tips.velocity_mps[s] = (ps.target_at(s, t + dt, so.rebound_s, up) -
                                ps.target_at(s, t - dt, so.rebound_s, up)) /
                               (2.0 * dt);
        tips.stick_direction[s] = ps.direction_at(s, t, rig_->frame);
    }
    tips.has_direction = true;
    for (int s = 0; s < 2; ++s)
        rig_->ahead_m[static_cast<size_t>(s)] =
            ps.target_at(s, t + ScoreRig::kReachLead_s, so.rebound_s, up);
    rig_->has_ahead = true;
    apply_note_grips(plan_time_s_);
    if (plan_time_s_ >= ps.plan.duration_s) {
        plan_active_ = false;
        perf_.playing_ = false;
        start_rest_move();
    }
}

// Between plans: a smooth move (0.6 s) to the rest tips, then hold.
void ScoreMode::follow_rest(TipTargets &tips)
{
    const ScoreRig &r = *rig_;
    const double move_s = perf_.options_.score.plan.return_time_s;
    const double x = (perf_.time_s() + perf_.options_.scene.step_s - rest_move_start_s_) / move_s;
    const double w = smoothstep(x);
    const double dw = x > 0.0 && x < 1.0 ? 6.0 * x * (1.0 - x) / move_s : 0.0;
    rig_->has_ahead = false; // no plan to look ahead in
    for (int s = 0; s < 2; ++s) {
        const Eigen::Vector3d d = r.frame.rest_tip_m[s] - rest_from_m_[s];
        tips.position_m[s] =
            x >= 1.0 ? r.frame.rest_tip_m[s] : Eigen::Vector3d(rest_from_m_[s] + w * d);
        tips.velocity_mps[s] = dw * d;
        const Eigen::Vector3d rest = rest_stick_direction(r.frame, s);
        const Eigen::Vector3d from = rest_from_direction_[s];
        const Eigen::Vector3d blend = (1.0 - w) * from + w * rest;
        tips.stick_direction[s] = x >= 1.0 || (from - rest).norm() < 1e-9 || blend.norm() < 1e-6
                                      ? rest
                                      : Eigen::Vector3d(blend.normalized());
    }
    tips.has_direction = true;
}

int ScoreMode::step(StrikeEvent out[kStepStrikes])
{
    ScoreRig &r = *rig_;
    if (plan_active_)
        follow_plan(r.tips);
    else
        follow_rest(r.tips);
    r.trunk_synergy();
    if (feet_[0])
        r.foot_on_pedal(Side::right, feet_[0]->pedal().footboard_angle_rad());
    if (feet_[1])
        r.foot_on_pedal(Side::left, feet_[1]->pedal().footboard_angle_rad());
    r.tracker->step(r.step_body, &r.tips, true);
    const long first_seq = perf_.detector_.strikes();
    int n = detect_strikes(perf_.detector_, r.tracker->scene(), out, perf_.time_offset_s_);
    for (auto &foot : feet_)
        if (foot)
            foot->advance(perf_.time_s());
    // The feet's contacts of this step, the earlier onset's first (its seq).
    const bool left_first =
        feet_[0] && feet_[1] && feet_[1]->next_onset_s() < feet_[0]->next_onset_s();
    for (int i = 0; i < 2; ++i)
        if (FootPlayer *foot = feet_[static_cast<size_t>(left_first ? 1 - i : i)].get()) {
            foot->take_contacts(perf_.detector_, first_seq);
            if (foot->take_end(out[n]))
                ++n;
        }
    r.tracker->scene().local_rotations(pose_scratch_);
    body_stats_.add_step(r.model, r.range_of_motion, r.lumbar, r.thorax, pose_scratch_);
    return n;
}

bool ScoreMode::take_foot_onset(StrikeEvent &out)
{
    for (auto &foot : feet_)
        if (foot && foot->take_onset(out))
            return true; // the other's, if any, at the next call
    return false;
}

// ---- the commands' score-mode parts ------------------------------------------------

bool ScoreMode::play(const Command &c, std::string *why)
{
    // Finished and planned by the worker (run) or here (render): a faulty
    // score is refused, nothing changes, nothing plays.
    auto job = plan_job(c, Work::Kind::play);
    job->start_bpm = start_bpm_;
    start_bpm_ = 0.0;
    play_pending_ = true; // until its plan is installed or refused
    return perf_.submit(std::move(job), why);
}

void ScoreMode::stop()
{
    // The performance ends; the sticks go back to their rest, the foot plays
    // no further kick.
    if (plan_active_)
        start_rest_move();
    plan_active_ = false;
    for (auto &foot : feet_)
        if (foot)
            foot->stop(perf_.time_s());
}

bool ScoreMode::tempo(const Command &c, std::string *why)
{
    // A live scale of the score's tempo map (docs/osc.md): under way, from
    // the first beat no hand has begun to play toward; stopped, the next
    // play starts at this tempo.
    if (!plan_active_ && !play_pending_) {
        start_bpm_ = c.value;
        return true;
    }
    auto job = plan_job(c, Work::Kind::tempo);
    job->bpm = c.value;
    job->plan_now_s = plan_active_ ? plan_time_s_ : 0.0;
    job->score_start_s = plan_ ? plan_->plan.score_start_s : perf_.options_.score.plan.lead_in_s;
    return perf_.submit(std::move(job), why);
}

bool ScoreMode::grip(const Command &c, std::string *why)
{
    // The character is rebuilt (by the worker, in run) in its current pose
    // with the sticks in the new grip, and takes over from the pose it is in
    // then; the plan, in tip space, goes on.
    auto job = std::make_unique<Job>(*this, Work::Kind::score_rig, c);
    job->options = perf_.options_;
    rig_->tracker->scene().local_rotations(job->pose);
    return perf_.submit(std::move(job), why);
}

bool ScoreMode::nuance(const Command &c, std::string *)
{
    // The nuance of the statements that follow and name none.
    default_nuance_ = nuance_from_string(c.text);
    builder_->set_default_nuance(default_nuance_);
    return true;
}

bool ScoreMode::mode(const Command &c, std::string *)
{
    PerformanceOptions &o = perf_.options_;
    o.score.mode = track_mode_from_string(c.text);
    rig_->tracker->set_mode(o.score.mode);
    return true;
}

bool ScoreMode::drum_changed(const Command &c, std::string *why)
{
    // The plan's frame follows the membrane, and a plan under way (or on its
    // way) is planned again on it and goes on from where it is (the notes
    // keep their times). No rebuild.
    const PerformanceOptions &o = perf_.options_;
    ScoreRig &r = *rig_;
    r.frame = frame_for(o.scene.drum, o.character.stick.tip_radius_m, r.frame.right,
                        r.frame.forward, &o.kit, &r.kit_drums, r.right_sole_m, &r.shoulder_m);
    if (plan_active_ || perf_.work_pending())
        return perf_.submit(plan_job(c, Work::Kind::replan), why);
    return true;
}

void ScoreMode::firmness_changed()
{
    // The notes without a firmness of their own take it at once.
    if (plan_active_) {
        perf_.applied_firmness_[0] = perf_.applied_firmness_[1] = -1.0;
        apply_note_grips(plan_time_s_);
    } else {
        perf_.set_grips(perf_.options_.grip_firmness);
    }
}

bool ScoreMode::score(const Command &c, std::string *why)
{
    if (c.kind == CommandKind::score) {
        // At most kMaxPendingStatements wait (a play copies them).
        if (builder_->parsed_statements() >= Performance::kMaxPendingStatements) {
            ++perf_.refused_statements_;
            return refuse(why, "score: " + std::to_string(Performance::kMaxPendingStatements) +
                                   " statements are waiting, the limit: send /ictus/score/clear "
                                   "(a longer score: ictusd run --score FILE)");
        }
        // The first statement since the start or a clear begins a new
        // score, which replaces the current one at the next play and plays
        // at its own tempi: a live tempo asked before it is dropped.
        if (builder_->statements() == 0)
            begin_new_score();
        // Parsed now (an error names the statement and column); played at
        // the next /ictus/play. A score with a faulty statement never plays.
        try {
            builder_->add_statement(c.text);
        } catch (const ScoreError &) {
            ++perf_.refused_statements_; // faulty: answered with its error, counted
            throw;
        }
        return true;
    }
    // A new score; the selected nuance still applies to the statements that
    // follow.
    builder_->reset();
    if (default_nuance_ != Nuance::legato)
        builder_->set_default_nuance(default_nuance_);
    begin_new_score();
    return true;
}

void ScoreMode::begin_new_score()
{
    tempo_scale_ = 1.0;
    start_bpm_ = 0.0;
    ++score_epoch_;
}

} // namespace ictus
