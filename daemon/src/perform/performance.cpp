// The physics side of `ictusd run` and `ictusd render` (performance.hpp): the
// motion source (a clip, clip_mode.cpp; a score, score_mode.cpp), the strike
// detector watching the stick tips against the drum, the commands applied
// between steps, the runaway guard, and the background work handed to the
// planning worker (planning_worker.hpp).
#include "ictus/perform/performance.hpp"
#include "membrane.h"

#include "clip_mode.hpp"
#include "ictus/perform/perform_error.hpp"
#include "planning_worker.hpp"
#include "score_mode.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace ictus
{

namespace
{
// The lists of verdicts found after apply() (refusals, confirmations): at most
// kMaxLater, the oldest dropped when nobody reads them; their room is reserved
// at construction, so the physics thread never allocates for them.
constexpr std::size_t kMaxLater = 64;

template <typename T> void push_later(std::vector<T> &list, const T &item)
{
    if (list.size() >= kMaxLater)
        list.erase(list.begin()); // nobody reads them: keep the newest
    list.push_back(item);
}

template <typename T> bool pop_later(std::vector<T> &list, T &out)
{
    if (list.empty())
        return false;
    out = list.front();
    list.erase(list.begin());
    return true;
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
    // At most 4 mm (strokes over 3.1 m/s): deeper, the hand follows through into
    // the head during a loud stroke's contact, the stick turns in the grip and
    // its damper presses the bead back into the head, which lengthens loud
    // contacts (the tom ladder's log-log slope of contact against speed:
    // -0.073 uncapped, the contact law's -0.112). docs/contact.md.
    plan.strike_aim_max_m = 0.004;
    // The bead meets the head 2.2 mm before the held tip's target does: a
    // stroke at v landed 2.2 mm / v early (10.9 ms at 0.2 m/s, 4.6 ms at
    // 0.48 m/s, 0.4 ms at 5.9 m/s; docs/gestures.md, "Dynamics rule"), so each
    // unit is placed that much later.
    plan.contact_lead_m = 0.0022;
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

PlanOptions ScorePerformOptions::plan_for(TrackMode m) const
{
    PlanOptions p = plan;
    if (m == TrackMode::joint && p.contact_lead_m > 0.0)
        p.contact_lead_m += joint_contact_lead_m;
    return p;
}

Performance::Performance(const PerformanceOptions &options)
    : options_(options), detector_(MembraneGeometry{}, options.strikes)
{
    refusals_.reserve(kMaxLater);
    confirmations_.reserve(kMaxLater);
    // The head's film is as thick as its density says (membrane~'s head: Mylar), for
    // its stretching under the stick (DrumParams::stretch_n_per_m3).
    options_.scene.drum.head_thickness_m = options_.drum_density_kg_per_m2 / MEMBRANE_MYLAR_RHO;
    validate(options_.scene);
    if (!(options_.clip_bpm > 0.0 && std::isfinite(options_.clip_bpm)))
        throw PerformError("clip tempo: expected a finite value > 0 bpm");
    if (!(options_.tempo_bpm >= 20.0 && options_.tempo_bpm <= 400.0))
        throw PerformError("tempo: expected 20 to 400 bpm");
    if (!options_.kit.empty()) {
        if (!score_mode())
            throw PerformError("kit: a kit is played from a score (not with a clip)");
        validate_kit(options_.kit);
        const KitDrum &first = options_.kit.drums.front();
        options_.scene.drum.radius_m = first.radius_m;
        options_.scene.drum.tension_n_per_m = first.tension_n_per_m;
        options_.scene.drum.shell_depth_m = first.shell_depth_m;
    }
    if (score_mode()) {
        auto mode = std::make_unique<ScoreMode>(*this);
        score_ = mode.get();
        mode_ = std::move(mode);
        skeleton_ = default_skeleton();
    } else {
        auto mode = std::make_unique<ClipMode>(*this);
        clip_ = mode.get();
        mode_ = std::move(mode);
        skeleton_ = clip_->skeleton();
    }
    mode_->begin();
}

Performance::~Performance()
{
    worker_.reset(); // joined before what it reads goes
}

const CharacterModel &Performance::model() const
{
    return mode_->model();
}

const Scene &Performance::scene() const
{
    return mode_->scene();
}

double Performance::time_s() const
{
    return time_offset_s_ + scene().time_s();
}

double Performance::clip_duration_s() const
{
    if (clip_)
        return clip_->duration_s();
    const GesturePlan *p = plan();
    return p ? p->duration_s : 0.0;
}

int Performance::divergences() const
{
    return divergences_before_ + scene().divergences();
}

int Performance::step(StrikeEvent out[kStepStrikes])
{
    take_results();
    StrikeEvent ended[kStepStrikes];
    const int k = mode_->step(ended);
    // Strikes a rebuild ended go first (their onsets came earlier); what
    // does not fit in this step's two waits for the next.
    for (int i = 0; i < k; ++i) {
        if (held_ends_n_ == static_cast<int>(held_ends_.size()))
            break; // eight strikes waiting: cannot happen (a step ends <= 2, a rebuild <= 2)
        held_ends_[static_cast<size_t>(held_ends_n_++)] = ended[i];
    }
    int n = 0;
    while (n < kStepStrikes && held_ends_n_ > 0) {
        out[n++] = held_ends_[0];
        std::copy(held_ends_.begin() + 1, held_ends_.begin() + held_ends_n_, held_ends_.begin());
        --held_ends_n_;
    }
    n = guard_runaway(n, out);
    for (int i = 0; i < n; ++i)
        mark_pedal(out[i]);
    return n;
}

int Performance::take_onsets(StrikeEvent out[kStepStrikes])
{
    int n = 0;
    StrikeEvent taken[2 * kStepStrikes];
    for (int i = 0; i < held_onsets_n_; ++i)
        taken[n++] = held_onsets_[static_cast<size_t>(i)];
    held_onsets_n_ = 0;
    for (int hand = 0; hand < 2; ++hand)
        if (detector_.take_onset(hand, taken[n]))
            ++n;
    for (int foot = 0; foot < 2 && mode_->take_foot_onset(taken[n]); ++foot)
        ++n;
    int kept = 0;
    for (int i = 0; i < n; ++i) {
        if (withheld(taken[i]))
            continue;
        if (kept < kStepStrikes) {
            out[kept] = taken[i];
            mark_pedal(out[kept++]);
        } else if (held_onsets_n_ < kStepStrikes) // for the next call
            held_onsets_[static_cast<size_t>(held_onsets_n_++)] = taken[i];
    }
    return kept;
}

bool Performance::flush(StrikeEvent &out)
{
    for (;;) {
        if (held_ends_n_ > 0) {
            out = held_ends_[0];
            std::copy(held_ends_.begin() + 1, held_ends_.begin() + held_ends_n_,
                      held_ends_.begin());
            --held_ends_n_;
        } else if (!detector_.flush(out)) {
            return false;
        }
        if (!withheld(out)) {
            mark_pedal(out);
            return true;
        }
    }
}

void Performance::mark_pedal(StrikeEvent &e) const
{
    const GesturePlan *p = plan();
    const PerformerFrame &f = performer_frame();
    if (!p || e.drum <= 0 || e.drum >= static_cast<int>(f.drums.size()) ||
        !f.drums[static_cast<size_t>(e.drum)].pedal)
        return;
    // The left foot's chick closes the hi-hat (docs/pedal.md).
    e.pedal_openness =
        e.hand == kFootLeft ? kHihatClosed : strike_pedal_openness(p->notes, e, plan_origin_s());
}

bool Performance::withheld(const StrikeEvent &e) const
{
    // The guard watches the sticks: a foot's strike (its pedal's own model)
    // is never held back by it.
    if (e.hand >= 2)
        return false;
    if (e.time_s >= quiet_from_s_ && e.time_s < quiet_until_s_)
        return true;
    for (const QuietWindow &w : whip_windows_[e.hand])
        if (e.time_s >= w.from_s && e.time_s < w.until_s)
            return true;
    return false;
}

void Performance::hold_open_contacts()
{
    // The onsets not taken yet, then the contacts themselves, ended at their
    // last sample: each strike keeps its onset, its end and its row.
    for (int hand = 0; hand < 2 && held_onsets_n_ < 2; ++hand)
        if (detector_.take_onset(hand, held_onsets_[static_cast<size_t>(held_onsets_n_)]))
            ++held_onsets_n_;
    StrikeEvent e;
    while (held_ends_n_ < static_cast<int>(held_ends_.size()) && detector_.flush(e))
        held_ends_[static_cast<size_t>(held_ends_n_++)] = e;
}

namespace
{
// A refusal whose reason is formatted (printf).
template <typename... Values>
bool refuse_with(std::string *why, const char *format, Values... values)
{
    if (why) {
        char buf[256];
        std::snprintf(buf, sizeof buf, format, values...);
        *why = buf;
    }
    return false;
}

} // namespace

bool Performance::check_gains(const double scale[2], std::string *why) const
{
    const std::vector<JointGains> &base = mode_->base_gains();
    double rate = 0.0; // the largest kp / kd after scaling, 1/s
    for (const JointGains &g : base)
        rate = std::max(rate, g.kp_nm_per_rad * scale[0] / (g.kd_nm_s_per_rad * scale[1]));
    const double h = options_.scene.step_s;
    const double zeta0 = options_.gains.damping_ratio;
    const double zeta = zeta0 * scale[1] / std::sqrt(scale[0]);
    const double zeta_min = std::min(kMinDampingRatio, zeta0);
    if (zeta < zeta_min * (1.0 - 1e-9)) // rounding of the scales aside
        return refuse_with(why,
                           "gains: stiffness x%g with damping x%g leaves a damping ratio of %.2f, "
                           "under %.2f (the joints would ring, the controller is unstable): "
                           "raise the damping to x%.3g or more",
                           scale[0], scale[1], zeta, zeta_min,
                           zeta_min / zeta0 * std::sqrt(scale[0]));
    if (rate * h <= kMaxPdRateStep)
        return true;
    return refuse_with(why,
                       "gains: stiffness x%g with damping x%g gives a PD rate kp/kd of %.0f/s, "
                       "unstable at the %g ms step (at most %.0f/s): raise the damping to x%.3g "
                       "or more",
                       scale[0], scale[1], rate, 1e3 * h, kMaxPdRateStep / h,
                       scale[1] * rate * h / kMaxPdRateStep);
}

void Performance::apply_gains()
{
    scale_gains(mode_->base_gains(), gain_scale_, mode_->gains());
    mode_->scene().set_gains(mode_->gains());
}

void Performance::set_grips(double firmness)
{
    Scene &scene = mode_->scene();
    for (int s = 0; s < 2; ++s) {
        scene.set_grip_firmness(static_cast<Side>(s), firmness);
        applied_firmness_[s] = firmness;
    }
}

void Performance::took_over(double previous_time_s)
{
    // The drum may have changed while the rig was built: the live one wins.
    mode_->scene().set_drum(options_.scene.drum);
    apply_gains();
    set_grips(options_.grip_firmness);
    time_offset_s_ = previous_time_s;
    // The new scene has no contact history: the contacts under way end now.
    hold_open_contacts();
    load_membranes(detector_, scene());
}

int Performance::guard_runaway(int k, StrikeEvent out[kStepStrikes])
{
    double tip_mps[2], speed = 0.0;
    for (int s = 0; s < 2; ++s) {
        tip_mps[s] = scene().tip_velocity(static_cast<Side>(s)).norm();
        speed = std::max(speed, tip_mps[s]);
    }
    const GainOptions built_in;
    const bool whip = score_mode() && gain_scale_[0] == 1.0 && gain_scale_[1] == 1.0 &&
                      options_.gains.natural_frequency_hz == built_in.natural_frequency_hz &&
                      options_.gains.damping_ratio == built_in.damping_ratio &&
                      options_.scene.limit_stops;
    bool runaway = false;
    for (int s = 0; s < 2; ++s) {
        if (!(tip_mps[s] > kRunawayTipSpeed_mps))
            continue;
        if (!whip) {
            runaway = true;
            continue;
        }
        // The built-in controller: a hand's move threw its stick. That hand
        // is quiet while it is this fast and kWhipSettle_s after, unless the
        // flight lasts or comes again (then a runaway, below).
        if (time_s() >= whip_windows_[s][whip_newest_[s]].until_s) {
            runaway |= time_s() - last_whip_s_ < kRunawayQuiet_s;
            ++whips_;
            last_whip_s_ = time_s();
            whip_newest_[s] = (whip_newest_[s] + 1) % kWhipWindows;
            whip_windows_[s][whip_newest_[s]].from_s = time_s();
        } else {
            runaway |= time_s() - whip_windows_[s][whip_newest_[s]].from_s > kWhipLongest_s;
        }
        whip_windows_[s][whip_newest_[s]].until_s = time_s() + kWhipSettle_s;
    }
    if (runaway && time_s() >= quiet_until_s_) {
        // No human stroke moves a stick tip this fast: the controller has
        // gone unstable. Default gains back, strikes held back meanwhile.
        ++runaways_;
        const bool scaled = gain_scale_[0] != 1.0 || gain_scale_[1] != 1.0;
        char cause[120];
        if (scaled)
            std::snprintf(cause, sizeof cause, "with the gains at x%g x%g (/ictus/gains)",
                          gain_scale_[0], gain_scale_[1]);
        else if (options_.gains.natural_frequency_hz != built_in.natural_frequency_hz ||
                 options_.gains.damping_ratio != built_in.damping_ratio)
            std::snprintf(cause, sizeof cause,
                          "with the controller's gains at %g Hz, damping ratio %g",
                          options_.gains.natural_frequency_hz, options_.gains.damping_ratio);
        else if (clip_)
            std::snprintf(cause, sizeof cause,
                          "with the built-in gains, the clip at x%.3g (tempo %g bpm, clip %g "
                          "bpm), %s grip",
                          options_.tempo_bpm / options_.clip_bpm, options_.tempo_bpm,
                          options_.clip_bpm, to_string(options_.character.grip));
        else
            std::snprintf(cause, sizeof cause,
                          "with the built-in gains: a stick thrown for over %g ms or twice "
                          "within %g s",
                          1e3 * kWhipLongest_s, kRunawayQuiet_s);
        gain_scale_[0] = gain_scale_[1] = 1.0;
        apply_gains();
        char buf[240];
        std::snprintf(buf, sizeof buf,
                      "runaway guard: the %s stick's tip at %.1f m/s (over %g m/s) %s; %sno strike "
                      "sent for %g s",
                      tip_mps[1] >= tip_mps[0] ? "right" : "left", speed, kRunawayTipSpeed_mps,
                      cause, scaled ? "gains back to 1 1, " : "", kRunawayQuiet_s);
        // Reported as the refusal of the /ictus/gains that scaled the gains;
        // else no command caused it (no address; the last peer is told).
        Command origin;
        if (scaled)
            origin = last_gains_;
        refuse_later(origin, buf);
        quiet_from_s_ = time_s();
        quiet_until_s_ = time_s() + kRunawayQuiet_s;
    }
    // A strike whose onset fell in the quiet time is held back whole (its
    // onset was not sent either); one begun before it ends as it began.
    int n = 0;
    for (int i = 0; i < k; ++i) {
        if (withheld(out[i]))
            ++withheld_;
        else
            out[n++] = out[i];
    }
    return n;
}

bool Performance::apply(const Command &c, std::string *why)
{
    deferred_ = false;
    try {
        switch (c.kind) {
        case CommandKind::play:
            return mode_->play(c, why);
        case CommandKind::stop:
            playing_ = false;
            stops_.fetch_add(1, std::memory_order_release); // plays not installed yet: cancelled
            mode_->stop();
            return true;
        case CommandKind::tempo:
            return mode_->tempo(c, why);
        case CommandKind::grip:
            options_.character.grip = grip_from_string(c.text);
            return mode_->grip(c, why);
        case CommandKind::nuance:
            return mode_->nuance(c, why);
        case CommandKind::mode:
            return mode_->mode(c, why);
        case CommandKind::gains:
            return apply_gains_command(c, why);
        case CommandKind::drum_radius:
        case CommandKind::drum_tension:
            return apply_drum_command(c, why);
        case CommandKind::drum_density:
            // The membrane's density changes its modes (membrane~), not the
            // contact stiffness 2 pi T / ln(R / r): nothing to rebuild.
            options_.drum_density_kg_per_m2 = c.value;
            return true;
        case CommandKind::grip_firmness:
            options_.grip_firmness = c.value;
            mode_->firmness_changed();
            return true;
        case CommandKind::humanize:
            // The controller's noise at once; the plan's from the next play.
            options_.score.plan.humanize = c.value;
            mode_->scene().set_motor_noise(c.value, options_.score.plan.seed);
            return true;
        case CommandKind::score:
        case CommandKind::score_clear:
            return mode_->score(c, why);
        }
    } catch (const std::exception &e) {
        return refuse(why, e.what());
    }
    return refuse(why, "unknown command");
}

bool Performance::apply_gains_command(const Command &c, std::string *why)
{
    const double scale[2] = {c.value, c.value2};
    if (!check_gains(scale, why))
        return false;
    gain_scale_[0] = c.value;
    gain_scale_[1] = c.value2;
    last_gains_ = c;
    apply_gains();
    return true;
}

bool Performance::apply_drum_command(const Command &c, std::string *why)
{
    DrumParams drum = options_.scene.drum;
    if (c.kind == CommandKind::drum_radius) {
        if (!(c.value > options_.character.stick.tip_radius_m * 2.0))
            return refuse(why, "drum radius: must exceed the stick tip's diameter");
        drum.radius_m = c.value;
    } else {
        drum.tension_n_per_m = c.value;
    }
    mode_->scene().set_drum(drum); // throws naming the value: nothing changed
    options_.scene.drum = drum;
    // At once on the live scene (its contact law) and the detector; the
    // mode follows (score mode: the plan's frame).
    detector_.set_membrane(membrane_of(scene()));
    return mode_->drum_changed(c, why);
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

// ---- score mode ------------------------------------------------------------------

double Performance::tempo_bpm() const
{
    return score_ ? score_->tempo_bpm() : options_.tempo_bpm;
}

double Performance::tempo_scale() const
{
    return score_ ? score_->tempo_scale() : 1.0;
}

const BodyStats &Performance::body_stats() const
{
    static const BodyStats none;
    return score_ ? score_->body_stats() : none;
}

const GesturePlan *Performance::plan() const
{
    return score_ ? score_->plan() : nullptr;
}

bool Performance::plan_active() const
{
    return score_ && score_->plan_active();
}

double Performance::plan_origin_s() const
{
    return score_ ? score_->plan_origin_s() : 0.0;
}

double Performance::plan_time_s() const
{
    return score_ ? score_->plan_time_s() : 0.0;
}

const KickPedal *Performance::kick_pedal() const
{
    return score_ ? score_->kick_pedal() : nullptr;
}

Eigen::Vector3d Performance::foot_piece_center_m() const
{
    for (const PerformerFrame::Drum &d : performer_frame().drums)
        if (d.foot)
            return d.membrane_center_m;
    return Eigen::Vector3d::Zero();
}

const PerformerFrame &Performance::performer_frame() const
{
    static const PerformerFrame none;
    return score_ ? score_->frame() : none;
}

TrackMode Performance::mode() const
{
    return score_ ? score_->track_mode() : TrackMode::joint;
}

Eigen::Vector3d Performance::tip_target(int hand) const
{
    return score_ ? score_->tip_target(hand) : tip_position(hand);
}

Eigen::Vector3d Performance::tip_position(int hand) const
{
    return scene().tip_position(static_cast<Side>(hand & 1));
}

double Performance::planned_impact_speed_mps(size_t note) const
{
    return score_ ? score_->planned_impact_speed_mps(note) : 0.0;
}

void Performance::start_score()
{
    if (!score_)
        throw PerformError("play: not in score mode");
    score_->start_score();
}

void Performance::check_score() const
{
    if (!score_)
        throw PerformError("play: not in score mode");
    score_->check_score();
}

// ---- background work -----------------------------------------------------------

bool Performance::submit(std::unique_ptr<Work> job, std::string *why)
{
    if (!worker_) {
        job->run();
        return install(std::move(job), why);
    }
    if (job->kind == Work::Kind::play || job->kind == Work::Kind::clip_rig) {
        job->stop_count = &stops_;
        job->stops = stops_.load(std::memory_order_relaxed);
    }
    if (!worker_->submit(std::move(job)))
        return refuse(why, "busy: 64 changes are waiting to be planned; send fewer");
    deferred_ = true;
    return true;
}

bool Performance::install(std::unique_ptr<Work> work, std::string *why)
{
    mode_->returned(*work);
    const bool ok = work->error.empty() ? mode_->install(*work, why) : refuse(why, work->error);
    discard(std::move(work));
    return ok;
}

void Performance::discard(std::unique_ptr<Work> old)
{
    if (worker_)
        worker_->discard(std::move(old));
}

void Performance::take_results()
{
    if (!worker_)
        return;
    while (std::unique_ptr<Work> r = worker_->take()) {
        const Command origin = r->origin;
        std::string why;
        if (!install(std::move(r), &why))
            refuse_later(origin, why);
        else if (origin.peer_port != 0)
            push_later(confirmations_, origin);
    }
}

void Performance::refuse_later(const Command &origin, const std::string &why)
{
    Refusal f;
    f.peer_ipv4 = origin.peer_ipv4;
    f.peer_port = origin.peer_port;
    std::snprintf(f.address, sizeof f.address, "%s", origin.address);
    std::snprintf(f.why, sizeof f.why, "%s", why.c_str());
    push_later(refusals_, f);
}

bool Performance::pop_confirmation(Command &out)
{
    return pop_later(confirmations_, out);
}

bool Performance::pop_refusal(Refusal &out)
{
    return pop_later(refusals_, out);
}

void Performance::set_background_work(bool on)
{
    if (on && !worker_)
        worker_ = std::make_unique<PlanningWorker>();
    else if (!on)
        worker_.reset();
}

bool Performance::work_pending() const
{
    return worker_ && worker_->pending();
}

} // namespace ictus
