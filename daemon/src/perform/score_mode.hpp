// score_mode.hpp -- a Performance of a score (private to src/perform): the
// score planned into stick-tip targets (score_plan.hpp) and performed by the
// default body (score_rig.hpp), Cartesian mode by default; statements,
// tempo, grip and drum changes live (docs/perform.md, docs/osc.md).
#pragma once

#include "foot_player.hpp"
#include "perform_mode.hpp"
#include "score_plan.hpp"
#include "score_rig.hpp"

#include <array>
#include <memory>

namespace ictus
{

class ScoreMode final : public PerformMode
{
  public:
    // Reads the gesture database and the score (Performance's options);
    // throws PerformError on bad placement options, ScoreError on a bad
    // score. A score whose options give no grip sets the performance's grip
    // from its first note.
    explicit ScoreMode(Performance &performance);
    void begin() override;

    bool play(const Command &c, std::string *why) override;
    void stop() override;
    bool tempo(const Command &c, std::string *why) override;
    bool grip(const Command &c, std::string *why) override;
    bool nuance(const Command &c, std::string *why) override;
    bool mode(const Command &c, std::string *why) override;
    bool drum_changed(const Command &c, std::string *why) override;
    void firmness_changed() override;
    bool score(const Command &c, std::string *why) override;
    void returned(const Work &work) override;
    bool install(Work &work, std::string *why) override;
    // The tips follow the plan under way, else move to their rest and hold.
    int step(StrikeEvent out[kStepStrikes]) override;
    bool take_foot_onset(StrikeEvent &out) override;

    // Performance's score-mode queries (performance.hpp).
    const GesturePlan *plan() const { return plan_ ? &plan_->plan : nullptr; }
    bool plan_active() const { return plan_active_; }
    double plan_origin_s() const { return plan_origin_s_; }
    double plan_time_s() const { return plan_time_s_; }
    double tempo_bpm() const;
    double tempo_scale() const { return tempo_scale_; }
    double planned_impact_speed_mps(size_t note) const;
    const PerformerFrame &frame() const { return rig_->frame; }
    TrackMode track_mode() const { return rig_->tracker->mode(); }
    const Eigen::Vector3d &tip_target(int hand) const { return rig_->tips.position_m[hand & 1]; }
    const BodyStats &body_stats() const { return body_stats_; }
    const KickPedal *kick_pedal() const { return feet_[0] ? &feet_[0]->pedal() : nullptr; }
    // Plans the current score and starts it now.
    void start_score();
    // Plans the current score and drops the plan: throws what start_score() would.
    void check_score() const;

  private:
    class Job;
    // A job that plans the score (play: with the statements received so far).
    std::unique_ptr<Job> plan_job(const Command &origin, Work::Kind kind);
    void run(Job &job); // the worker thread, or inline
    void run_play(Job &job);
    void run_tempo(Job &job);
    bool install_tempo(Job &job, std::string *why);
    void install_rig(std::unique_ptr<ScoreRig> rig, bool keep_pose);
    void install_plan(std::unique_ptr<ScorePlan> plan, bool start_now);
    void start_rest_move();
    // Statements begin a new score: the live tempo is dropped.
    void begin_new_score();
    void follow_plan(TipTargets &tips);
    void follow_rest(TipTargets &tips);
    void apply_note_grips(double plan_time_s);

    Performance &perf_;
    std::unique_ptr<ScoreRig> rig_;
    // The database (read only after construction), the statements received
    // (physics thread), the current score (only run() touches it: the
    // worker's, or inline) and the plan performed.
    std::unique_ptr<GestureDatabase> db_;
    std::unique_ptr<ScoreBuilder> builder_;
    std::shared_ptr<const Score> score_;
    std::shared_ptr<const Score> played_;    // score_ at its tempo scale (run() only)
    double tempo_scale_ = 1.0;               // the physics thread's (Job::new_tempo_scale)
    double start_bpm_ = 0.0;                 // > 0: the next play starts at this tempo
    bool play_pending_ = false;              // a play handed to the worker, not back yet
    double score_first_bpm_ = 120.0;         // the current score's own first tempo
    // Counts the new scores begun (statements after the start or a clear); a
    // live tempo is kept only for the score it was asked on.
    unsigned score_epoch_ = 0, plan_epoch_ = 0; // plan_epoch_: of the plan installed
    Nuance default_nuance_ = Nuance::legato; // /ictus/nuance: of the statements that follow
    std::unique_ptr<ScorePlan> plan_;        // nullptr before the first
    bool plan_active_ = false;
    double plan_origin_s_ = 0.0, plan_time_s_ = 0.0;
    // Between plans the tips move to (and hold) the rest tips, and the sticks
    // turn from their directions at the plan's end (a stop) to the rest
    // direction over the same move: turned at once, a stick just lifted from
    // its stroke was thrown back on the head.
    std::array<Eigen::Vector3d, 2> rest_from_m_;
    std::array<Eigen::Vector3d, 2> rest_from_direction_ = {Eigen::Vector3d::Zero(),
                                                           Eigen::Vector3d::Zero()};
    double rest_move_start_s_ = -1e9;
    BodyStats body_stats_;
    // The feet: [0] the right on the kit's kick, [1] the left on its hi-hat's
    // pedal (none without one).
    std::array<std::unique_ptr<FootPlayer>, 2> feet_;
    std::vector<Eigen::Quaterniond> pose_scratch_;
};

} // namespace ictus
