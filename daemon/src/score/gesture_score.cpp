// gesture_score.cpp -- a score into stick-tip targets (docs/score.md, "From
// score to motion"). Per hand, the notes' gesture units are
//  1. made C1 curves: cubic Hermite through the unit's samples, in two pieces
//     split at the strike (the impact reverses the velocity there);
//  2. time-warped around their strike: unit time u = P + sigma(tau), tau the
//     plan time from the note's beat, sigma(0) = 0 and sigma'(0) = 1, so the
//     strike lands on the beat with the unit's own impact velocity; the
//     preparation and the lift are compressed (quadratic sigma) only when the
//     time to the neighbouring strikes is shorter than they are;
//  3. placed: rotated from the performer frame into the world and moved onto
//     the note's spot of the head;
//  4. co-articulated: consecutive units (and the rest tip, when the hand is
//     idle) are cross-faded with a quintic smoothstep weight over a window
//     strictly between two strikes. Both curves are C1 and the weight has zero
//     slope at the window's ends, so the blend is C1; outside the windows a
//     single unit rules, so the strikes are untouched.
// The paper plans Figure 5 this way in spirit ("co-articulation between
// successive motion units" in the Cartesian space); the warping and blending
// are the classic motion-editing tools (Witkin & Popovic 1995 motion warping,
// Kovar & Gleicher 2003 registration curves, cross-fades with ease curves).
#include "ictus/score/gesture_score.hpp"

#include "ictus/base/motor_noise.hpp"
#include "kit_notes.hpp"
#include "plan_inputs.hpp"
#include "plan_timing.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <tuple>

namespace ictus
{

namespace
{

constexpr double kPi = 3.14159265358979323846;
// A unit's end state is extended beyond the unit by a motion that stops
// within this time (constant deceleration): C1 at the unit's ends.
constexpr double kStopTime_s = 0.05;
// A stroke's period when nothing sets it: gesture.hpp's nominal 0.5 s (120 bpm).
constexpr double kNominalPeriod_s = 0.5;
// Cubic Hermite tangents of samples p[first..last] (spacing h): central
// differences inside, second-order one-sided differences at the ends.
std::vector<Eigen::Vector3d> hermite_tangents(const std::vector<Eigen::Vector3d> &p, int first,
                                              int last, double h)
{
    const int n = last - first + 1;
    std::vector<Eigen::Vector3d> m(static_cast<size_t>(n));
    if (n == 2) {
        m[0] = m[1] = (p[last] - p[first]) / h;
        return m;
    }
    for (int i = 1; i + 1 < n; ++i)
        m[i] = (p[first + i + 1] - p[first + i - 1]) / (2.0 * h);
    m[0] = (-3.0 * p[first] + 4.0 * p[first + 1] - p[first + 2]) / (2.0 * h);
    m[n - 1] = (3.0 * p[last] - 4.0 * p[last - 1] + p[last - 2]) / (2.0 * h);
    return m;
}

// A gesture unit as a C1 curve in unit time u in [0, prep_s + lift_s],
// performer frame, relative to the strike point.
class UnitCurve
{
  public:
    explicit UnitCurve(const GestureUnit &unit) : p_(unit.tip_m), dir_(unit.stick_dir)
    {
        const int n = static_cast<int>(p_.size());
        const std::string name = "gesture unit '" + unit.source + "' (" + to_string(unit.grip) +
                                 " " + to_string(unit.nuance) + ")";
        if (!(unit.rate_hz > 0.0) || !std::isfinite(unit.rate_hz))
            throw std::invalid_argument(name + ": rate_hz must be > 0");
        if (n < 3 || unit.strike_index < 1 || unit.strike_index > n - 2)
            throw std::invalid_argument(name + ": needs samples before and after its strike (" +
                                        std::to_string(n) + " samples, strike at " +
                                        std::to_string(unit.strike_index) + ")");
        if (dir_.empty())
            dir_.assign(p_.size(), kDefaultStickDirection);
        if (dir_.size() != p_.size())
            throw std::invalid_argument(name + ": stick_dir and tip_m differ in length");
        for (int i = 0; i < n; ++i)
            if (!p_[i].allFinite() || !dir_[i].allFinite() || dir_[i].norm() < 1e-9)
                throw std::invalid_argument(name + ": sample " + std::to_string(i) +
                                            " is not finite (or a null stick direction)");
        h_ = 1.0 / unit.rate_hz;
        strike_ = unit.strike_index;
        prep_s = strike_ * h_;
        lift_s = (n - 1 - strike_) * h_;
        prep_tangent_ = hermite_tangents(p_, 0, strike_, h_);
        lift_tangent_ = hermite_tangents(p_, strike_, n - 1, h_);
    }

    double prep_s = 0.0; // start (top before) to the strike
    double lift_s = 0.0; // strike to the end (top after)

    void eval(double u, Eigen::Vector3d &pos, Eigen::Vector3d &vel) const
    {
        u = std::clamp(u, 0.0, prep_s + lift_s);
        int i0;                                      // first sample of the segment
        const std::vector<Eigen::Vector3d> *tangent; // of the piece
        int piece_first;
        double x; // segment coordinate in samples from piece_first
        if (u <= prep_s) {
            piece_first = 0;
            tangent = &prep_tangent_;
            x = u / h_;
            i0 = std::min(static_cast<int>(x), strike_ - 1);
        } else {
            piece_first = strike_;
            tangent = &lift_tangent_;
            x = (u - prep_s) / h_;
            const int last = static_cast<int>(p_.size()) - 1 - strike_;
            i0 = std::min(static_cast<int>(x), last - 1);
        }
        const double s = x - i0;
        const Eigen::Vector3d &a = p_[piece_first + i0], &b = p_[piece_first + i0 + 1];
        const Eigen::Vector3d ma = (*tangent)[i0] * h_, mb = (*tangent)[i0 + 1] * h_;
        const double s2 = s * s, s3 = s2 * s;
        pos = (2 * s3 - 3 * s2 + 1) * a + (s3 - 2 * s2 + s) * ma + (-2 * s3 + 3 * s2) * b +
              (s3 - s2) * mb;
        vel = ((6 * s2 - 6 * s) * a + (3 * s2 - 4 * s + 1) * ma + (-6 * s2 + 6 * s) * b +
               (3 * s2 - 2 * s) * mb) /
              h_;
    }

    Eigen::Vector3d dir(double u) const
    {
        const double x = std::clamp(u / h_, 0.0, static_cast<double>(dir_.size() - 1));
        const size_t i = std::min(static_cast<size_t>(x), dir_.size() - 2);
        const double w = x - static_cast<double>(i);
        return ((1.0 - w) * dir_[i] + w * dir_[i + 1]).normalized();
    }

    // The tip velocity just before the strike (the preparation's end).
    Eigen::Vector3d impact_velocity() const { return prep_tangent_.back(); }

  private:
    std::vector<Eigen::Vector3d> p_, dir_;
    std::vector<Eigen::Vector3d> prep_tangent_, lift_tangent_;
    double h_ = 0.004;
    int strike_ = 0;
};

// One piece of a hand's timeline: a placed, warped unit or the rest tip.
struct Item {
    bool rest = true;
    Eigen::Vector3d rest_pos = Eigen::Vector3d::Zero();
    Eigen::Vector3d rest_dir = Eigen::Vector3d::UnitZ();

    const UnitCurve *curve = nullptr;
    Eigen::Matrix3d to_world = Eigen::Matrix3d::Identity(); // performer -> world
    Eigen::Vector3d origin = Eigen::Vector3d::Zero();       // tip target at the strike
    double strike_t = 0.0;
    double prep_t = 0.0, lift_t = 0.0; // plan time given to the preparation and the lift
    double c = 0.0, d = 0.0;           // warp coefficients, sigma = tau + c tau^2 (tau < 0)
    Eigen::Vector3d start_pos = Eigen::Vector3d::Zero(), start_vel = Eigen::Vector3d::Zero();
    Eigen::Vector3d end_pos = Eigen::Vector3d::Zero(), end_vel = Eigen::Vector3d::Zero();
    Eigen::Vector3d start_dir = Eigen::Vector3d::UnitZ(), end_dir = Eigen::Vector3d::UnitZ();
    int drum = 0; // the note's drum of a kit
    // The turn of the unit about the vertical toward its piece (piece_yaw_rad).
    double yaw_rad = 0.0;

    // The warped unit inside its own time span [strike - prep_t, strike + lift_t].
    void warped(double tau, Eigen::Vector3d &pos, Eigen::Vector3d &vel) const
    {
        const double k = tau <= 0.0 ? c : d;
        const double sigma = tau + k * tau * tau;
        const double rate = 1.0 + 2.0 * k * tau; // d sigma / d tau, 1 at the strike
        Eigen::Vector3d p, v;
        curve->eval(curve->prep_s + sigma, p, v);
        pos = origin + to_world * p;
        vel = to_world * v * rate;
    }

    void prepare()
    {
        // sigma(-prep_t) = -prep_s and sigma(lift_t) = lift_s.
        c = (prep_t - curve->prep_s) / (prep_t * prep_t);
        d = (curve->lift_s - lift_t) / (lift_t * lift_t);
        warped(-prep_t, start_pos, start_vel);
        warped(lift_t, end_pos, end_vel);
        start_dir = (to_world * curve->dir(0.0)).normalized();
        end_dir = (to_world * curve->dir(curve->prep_s + curve->lift_s)).normalized();
    }

    void eval(double t, Eigen::Vector3d &pos, Eigen::Vector3d &dir) const
    {
        if (rest) {
            pos = rest_pos;
            dir = rest_dir;
            return;
        }
        const double tau = t - strike_t;
        // Beyond the unit: its end velocity brought to rest in kStopTime_s.
        auto stop = [](double s) {
            return s < kStopTime_s ? s - s * s / (2.0 * kStopTime_s) : 0.5 * kStopTime_s;
        };
        if (tau < -prep_t) {
            pos = start_pos - start_vel * stop(-prep_t - tau);
            dir = start_dir;
        } else if (tau > lift_t) {
            pos = end_pos + end_vel * stop(tau - lift_t);
            dir = end_dir;
        } else {
            Eigen::Vector3d vel;
            warped(tau, pos, vel);
            const double k = tau <= 0.0 ? c : d;
            dir = (to_world * curve->dir(curve->prep_s + tau + k * tau * tau)).normalized();
        }
    }
};

// Cross-fade between items[j] and items[j + 1] over [begin, end].
struct Window {
    double begin = 0.0, end = 0.0;
    // The move across the head between the two units' spots (zero for a
    // window to or from the rest tip), spread over [move_begin, move_end].
    Eigen::Vector3d across = Eigen::Vector3d::Zero();
    double move_begin = 0.0, move_end = 0.0;
    // A move between two drums of a kit: lifted by lift times kit_bump()
    // over [move_begin, move_end], highest at lift_peak of it (kit_lift()).
    Eigen::Vector3d lift = Eigen::Vector3d::Zero();
    double lift_peak = 0.5;
    // A turn of the stick's heading made apart from the units' cross-fade:
    // the second unit's heading less the first's (rad, within +-pi) about
    // `up`, over [turn_begin, turn_end] (within the move window); 0 where the
    // cross-fade makes it (turn_for_window()).
    double turn_rad = 0.0, turn_begin = 0.0, turn_end = 0.0;
    Eigen::Vector3d up = Eigen::Vector3d::UnitY();
};

// Quintic smoothstep: 0 -> 1 with zero slope and curvature at both ends.
double smoothstep5(double x)
{
    x = std::clamp(x, 0.0, 1.0);
    return x * x * x * (10.0 + x * (-15.0 + 6.0 * x));
}

// The lift's shape over a move between drums: 0 -> 1 -> 0 with zero slope at
// both ends (C1 with the units), 1 at `peak` (the middle unless given; the
// halves on either side stretched to it, so the slope stays 0 there: C1, its
// curvature jumps at the peak unless it is the middle).
double kit_bump(double x, double peak = 0.5)
{
    x = std::clamp(x, 0.0, 1.0);
    peak = std::clamp(peak, 0.05, 0.95);
    x = x < peak ? 0.5 * x / peak : 0.5 + 0.5 * (x - peak) / (1.0 - peak);
    return 16.0 * x * x * (1.0 - x) * (1.0 - x);
}

} // namespace

namespace
{

// Units are shared by notes with the same grip, nuance, hand, dynamics
// and periods. The parametric model's units are made at the hand's own
// periods (the downswing for the time since its previous strike, the lift
// for the time to its next one: gesture.hpp's stroke_model), so the warp
// has little to do; imported units come from instantiate() and are warped.
class UnitCache
{
  public:
    explicit UnitCache(const GestureDatabase &db) : db_(db) {}

    const UnitCurve &unit_for(Grip g, Nuance n, Side s, double dynamics, double prep_period_s,
                              double lift_period_s)
    {
        const long prep_us = std::lround(prep_period_s * 1e6);
        const long lift_us = std::lround(lift_period_s * 1e6);
        const auto key = std::make_tuple(static_cast<int>(g), static_cast<int>(n),
                                         static_cast<int>(s), dynamics, prep_us, lift_us);
        auto it = units_.find(key);
        if (it == units_.end()) {
            const GestureUnit *stored = db_.find(g, n, s);
            const GestureUnit unit =
                !stored || stored->source == "model"
                    ? stroke_model(g, n, s, dynamics, prep_us * 1e-6, lift_us * 1e-6)
                    : db_.instantiate(g, n, s, dynamics);
            it = units_.emplace(key, std::make_unique<UnitCurve>(unit)).first;
        }
        return *it->second;
    }

  private:
    const GestureDatabase &db_;
    std::map<std::tuple<int, int, int, double, long, long>, std::unique_ptr<UnitCurve>> units_;
};

using score_detail::foot_note;
using score_detail::note_openness;
using score_detail::plan_duration;
using score_detail::sample_times;

using HandNotes = std::array<std::vector<size_t>, 2>; // each hand's notes, indices into plan.notes

// The notes, timed by the tempo map, into plan.notes (score order); a score that
// asks a hand to play faster than one hand plays is a ScoreError. The timing noise
// of `humanize` never does: it is clipped where it would bring a stroke closer
// than that to the hand's previous one (a hand cannot play faster when it errs).
HandNotes time_notes(const Score &score, const PerformerFrame &frame, const PlanOptions &opt,
                     GesturePlan &plan)
{
    HandNotes by_hand;
    const double amount = humanize_amount(score, opt);
    std::array<double, 2> score_time_prev = {0.0, 0.0};   // each hand's last note, without noise
    std::array<double, 2> foot_written_prev = {0.0, 0.0}; // each foot's, likewise
    std::array<long, 2> foot_prev = {-1, -1};             // each foot's last, in plan.foot_notes
    for (size_t k = 0; k < score.notes.size(); ++k) {
        const ScoreNote &n = score.notes[k];
        if (n.foot) {
            // As a hand's: a kick (a chick) closer to the foot's last than its
            // pedal plays is refused; the noise of `humanize` never brings it closer.
            PlannedFootNote f = foot_note(score, n, k, frame, opt);
            const double written = opt.lead_in_s + score.note_time_s(n);
            const size_t s = f.side == Side::right ? 0 : 1;
            const double min_s = s == 0 ? opt.min_foot_interval_s : opt.min_chick_interval_s;
            if (foot_prev[s] >= 0) {
                const PlannedFootNote &prev = plan.foot_notes[static_cast<size_t>(foot_prev[s])];
                if (written - foot_written_prev[s] < min_s - 1e-9) {
                    std::ostringstream m;
                    m << "this " << (s == 0 ? "kick" : "chick") << " comes "
                      << (written - foot_written_prev[s]) * 1000.0
                      << " ms after the previous one (line " << prev.line << "), faster than the "
                      << (s == 0 ? "right foot plays its pedal" : "left foot plays the hi-hat's")
                      << " (minimum " << min_s * 1000.0 << " ms)";
                    throw ScoreError(score.source, n.line, n.column, m.str());
                }
                f.time_s = std::max(f.time_s, prev.time_s + min_s);
            }
            foot_written_prev[s] = written;
            foot_prev[s] = static_cast<long>(plan.foot_notes.size());
            plan.foot_notes.push_back(f);
            continue;
        }
        PlannedNote p;
        const double score_time = opt.lead_in_s + score.note_time_s(n);
        p.time_s = score_time;
        p.hand = n.hand;
        p.nuance = n.nuance;
        p.grip = n.grip;
        p.dynamics = n.dynamics;
        if (amount > 0.0) {
            // Note k's own stream: a replan (a tempo change) draws the same.
            MotorNoise noise(opt.seed, k + 1);
            p.time_s += amount * kHumanizeTimingSd_s * noise.normal();
            const double scale = 1.0 + amount * kHumanizeForceCv * noise.normal();
            p.dynamics = std::clamp(n.dynamics * scale, 0.0, 1.0);
        }
        p.beats = n.beats;
        p.tempo_bpm = score.tempo.tempo_at_beat(n.beat);
        p.r_over_a = n.r_over_a;
        p.theta_deg = n.theta_deg;
        p.firmness = n.firmness;
        p.drum = score_detail::note_drum_spot(score, n, frame, p.r_over_a, p.theta_deg);
        if (p.drum < static_cast<int>(frame.drums.size()) &&
            frame.drums[static_cast<size_t>(p.drum)].foot)
            throw ScoreError(score.source, n.drum_line, n.drum_column,
                             "drum '" + frame.drums[static_cast<size_t>(p.drum)].name +
                                 "' is played by the right foot on its pedal: write 'RF'");
        p.openness = note_openness(score, n, frame, p.drum);
        p.strike_point_m = membrane_point(frame, p.r_over_a, p.theta_deg, p.drum);
        p.tip_target_m = p.strike_point_m - opt.strike_depth_m * frame.up;
        p.line = n.line;
        p.column = n.column;
        p.grace = n.grace;
        const std::vector<size_t> &same = by_hand[static_cast<int>(n.hand)];
        if (!same.empty()) {
            const PlannedNote &prev = plan.notes[same.back()];
            const double written = score_time - score_time_prev[static_cast<int>(n.hand)];
            if (amount > 0.0 && written >= opt.min_stroke_interval_s - 1e-9)
                p.time_s = std::max(p.time_s, prev.time_s + opt.min_stroke_interval_s);
            if (written < opt.min_stroke_interval_s - 1e-9) {
                auto what = [](const PlannedNote &q) {
                    return q.grace == Grace::none
                               ? std::string()
                               : std::string(", a ") + to_string(q.grace) + "'s grace stroke";
                };
                std::ostringstream m;
                m << "this " << (n.hand == Side::right ? "right" : "left") << "-hand stroke"
                  << (n.grace == Grace::none
                          ? std::string()
                          : std::string(" (the ") + to_string(n.grace) + "'s grace stroke)")
                  << " comes " << written * 1000.0 << " ms after the previous one (line "
                  << prev.line << what(prev) << "), faster than one hand plays (minimum "
                  << opt.min_stroke_interval_s * 1000.0
                  << " ms): give it to the other hand or slow down";
                throw ScoreError(score.source, n.line, n.column, m.str());
            }
        }
        score_time_prev[static_cast<int>(n.hand)] = score_time;
        by_hand[static_cast<int>(n.hand)].push_back(plan.notes.size());
        plan.notes.push_back(p);
    }
    return by_hand;
}

// One hand's strokes on their way to the timeline: the units placed on
// their notes, and which gaps go through the rest tip (note k -> k+1).
struct HandStrokes {
    std::vector<Item> placed;
    std::vector<bool> via_rest;
};

// The units at their notes' targets and strikes. A long gap goes through the
// rest tip: when it is longer than idle_return_s and leaves room for a
// nominal lift, two moves and a nominal preparation.
HandStrokes place_strokes(const std::vector<size_t> &idx, const GesturePlan &plan,
                          const PerformerFrame &frame, const PlanOptions &opt,
                          const Eigen::Matrix3d &to_world)
{
    const size_t n = idx.size();
    HandStrokes h{std::vector<Item>(n), std::vector<bool>(n, false)};
    for (size_t k = 0; k < n; ++k) {
        const PlannedNote &p = plan.notes[idx[k]];
        Item &it = h.placed[k];
        it.rest = false;
        it.yaw_rad = piece_yaw_rad(frame, static_cast<int>(p.hand), p.strike_point_m, p.drum);
        it.to_world = Eigen::AngleAxisd(it.yaw_rad, frame.up).toRotationMatrix() * to_world;
        it.origin = p.tip_target_m;
        it.strike_t = p.time_s;
        it.drum = p.drum;
    }
    const double tr = opt.return_time_s;
    for (size_t k = 0; k + 1 < n; ++k) {
        const double gap = h.placed[k + 1].strike_t - h.placed[k].strike_t;
        h.via_rest[k] = gap > opt.idle_return_s && gap > 2.0 * kNominalPeriod_s + 2.0 * tr + 0.2;
    }
    return h;
}

// The unit of each stroke, made at its periods: the downswing's from the
// hand's previous strike, else nominal (the first stroke, or one after a
// rest, is a whole stroke); the lift's to its next strike, else from the
// previous one, else nominal (a lone stroke).
void choose_units(HandStrokes &h, const std::vector<size_t> &idx, const GesturePlan &plan,
                  UnitCache &units)
{
    std::vector<Item> &placed = h.placed;
    const size_t n = placed.size();
    for (size_t k = 0; k < n; ++k) {
        const bool has_prev = k > 0 && !h.via_rest[k - 1];
        const bool has_next = k + 1 < n && !h.via_rest[k];
        const double before =
            has_prev ? placed[k].strike_t - placed[k - 1].strike_t : kNominalPeriod_s;
        const double after = has_next ? placed[k + 1].strike_t - placed[k].strike_t
                                      : (has_prev ? before : kNominalPeriod_s);
        const PlannedNote &p = plan.notes[idx[k]];
        placed[k].curve = &units.unit_for(p.grip, p.nuance, p.hand, p.dynamics, before, after);
    }
}

// Each unit placed later by the contact lead over its downward impact speed
// (PlanOptions::contact_lead_m), keeping the hand's strokes in order.
void delay_for_contact(HandStrokes &h, const PlanOptions &opt, const PerformerFrame &frame,
                       const Eigen::Matrix3d &to_world)
{
    if (opt.contact_lead_m <= 0.0)
        return;
    for (Item &it : h.placed) {
        const double down = -(to_world * it.curve->impact_velocity()).dot(frame.up);
        it.strike_t += std::min(opt.contact_lead_m / std::max(down, 0.05), 0.02);
    }
}

// Each unit's warp: its preparation and lift fit the time to the
// neighbouring strikes; the target aimed below the head by the impact speed.
void warp_units(HandStrokes &h, const std::vector<size_t> &idx, const PerformerFrame &frame,
                const PlanOptions &opt, const Eigen::Matrix3d &to_world, GesturePlan &plan)
{
    std::vector<Item> &placed = h.placed;
    const size_t n = placed.size();
    const double beta = opt.blend_margin;
    for (size_t k = 0; k < n; ++k) {
        Item &it = placed[k];
        // Time before the strike: back to the previous strike (direct
        // link) or to the plan's start (first note); unlimited after a rest.
        double before = std::numeric_limits<double>::infinity();
        if (k == 0)
            before = it.strike_t;
        else if (!h.via_rest[k - 1])
            before = it.strike_t - placed[k - 1].strike_t;
        double after = std::numeric_limits<double>::infinity();
        if (k + 1 < n && !h.via_rest[k])
            after = placed[k + 1].strike_t - it.strike_t;
        it.prep_t = std::min(it.curve->prep_s, (1.0 - beta) * before);
        it.lift_t = std::min(it.curve->lift_s, (1.0 - beta) * after);
        const Eigen::Vector3d impact = to_world * it.curve->impact_velocity();
        const double aim =
            opt.strike_aim_s * std::max(0.0, -impact.dot(frame.up) - opt.strike_aim_from_mps);
        it.origin -= std::min(aim, opt.strike_aim_max_m) * frame.up;
        plan.notes[idx[k]].tip_target_m = it.origin;
        it.prepare();
        plan.notes[idx[k]].impact_velocity_mps = to_world * it.curve->impact_velocity();
    }
}

// The tip between two units of one hand at t in the move window: the units'
// cross-fade and the move across (as sample_hand makes it), without a lift.
Eigen::Vector3d pair_position(const Item &a, const Item &b, const Window &w, double t)
{
    Eigen::Vector3d p0, d0;
    a.eval(t, p0, d0);
    if (t >= w.begin && w.end > w.begin) {
        Eigen::Vector3d p1, d1;
        b.eval(t, p1, d1);
        const double wt = t > w.end ? 1.0 : smoothstep5((t - w.begin) / (w.end - w.begin));
        p0 = (1.0 - wt) * p0 + wt * p1;
    }
    const double made = t < w.begin ? 0.0
                        : t > w.end ? 1.0
                                    : smoothstep5((t - w.begin) / (w.end - w.begin));
    const double x = (t - w.move_begin) / (w.move_end - w.move_begin);
    return p0 + (smoothstep5(x) - made) * w.across;
}

// Two units' stick directions cross-faded by weight w (0: d0, 1: d1), unit;
// of two opposite ones, the nearer.
Eigen::Vector3d blend_directions(const Eigen::Vector3d &d0, const Eigen::Vector3d &d1, double w)
{
    const Eigen::Vector3d blended = (1.0 - w) * d0 + w * d1;
    return blended.norm() > 1e-9 ? blended.normalized() : (w < 0.5 ? d0 : d1);
}

// The stick's direction at t in window w between two units of one hand, d0 and
// d1 theirs at t: the units' cross-fade over [begin, end]; with a turn, the
// second's shape taken into the first's heading for the fade and the heading
// turned over [turn_begin, turn_end] (turn_for_window()).
Eigen::Vector3d window_direction(const Window &w, double t, const Eigen::Vector3d &d0,
                                 const Eigen::Vector3d &d1)
{
    const double fade = t < w.begin || !(w.end > w.begin) ? 0.0
                        : t > w.end                       ? 1.0
                                    : smoothstep5((t - w.begin) / (w.end - w.begin));
    if (w.turn_rad == 0.0 || !(w.turn_end > w.turn_begin))
        return fade == 0.0 ? d0 : blend_directions(d0, d1, fade);
    const Eigen::Vector3d shape =
        blend_directions(d0, Eigen::AngleAxisd(-w.turn_rad, w.up) * d1, fade);
    const double turned = smoothstep5((t - w.turn_begin) / (w.turn_end - w.turn_begin));
    return Eigen::AngleAxisd(turned * w.turn_rad, w.up) * shape;
}

// The stick's direction between two units of one hand at t in the move
// window, as sample_hand makes it.
Eigen::Vector3d pair_direction(const Item &a, const Item &b, const Window &w, double t)
{
    Eigen::Vector3d p0, d0, p1, d1;
    a.eval(t, p0, d0);
    b.eval(t, p1, d1);
    return window_direction(w, t, d0, d1);
}

// Points of the stick behind its tip that a move keeps above the heads as it
// keeps the tip (m along the stick, to the butt of the default 0.406 m stick:
// character.hpp's StickParams). A hand moving from the snare to the crash
// carries its stick's shaft through the hi-hat's edge when only the tip is
// lifted over it.
constexpr double kShaftPoints_m[] = {0.1, 0.2, 0.3, 0.4};

// The hand round the grip, kGrip_m from the tip (the default stick's, 0.276 m
// of its 0.406 m: character.hpp's StickParams): its palm reaches
// kPalmBelowGrip_m below the stick's axis (its midplane 3.7-4.1 cm below on
// the kit's renders, and half its 3.3 cm thickness) and kPalmHalfBreadth_m to
// either side. A hi-hat's rod
// stands kHihatRodAbove_m above its plates, to the clutch, kHihatRodRadius_m
// about their centre (as tests/ and python/ictus_tools/limb_clearance.py
// measure it): a left hand going to the crash after a fill sweeps its palm
// over it, and a move keeps the grip above the rod's top by the palm.
constexpr double kGrip_m = StickParams{}.length_m - StickParams{}.grip_from_butt_m;
constexpr double kPalmBelowGrip_m = 0.057;
constexpr double kPalmHalfBreadth_m = 0.045;
constexpr double kHihatRodAbove_m = 0.10;
constexpr double kHihatRodRadius_m = 0.0125;
constexpr double kStick_m = StickParams{}.length_m;
constexpr double kStickRadius_m = StickParams{}.shaft_radius_m;

// How far a move from drum a.drum to b.drum must rise (m): wherever the tip
// is over a drum's disk (its radius plus kit_margin_m, in plan), it must be
// above that head, and kit_clearance_m above it for a drum it does not play
// here. The lift is applied as kit_bump(), so it is the largest shortfall
// over kit_bump at 48 points of the move (kit_bump taken as >= 0.05 near the
// ends, where the tip is over its own drums' heads). Over the two drums it
// plays, only the middle of the move counts (kit_bump >= 0.5, x within
// 0.15-0.85, whatever the lift's peak): near its ends
// the tip belongs to the strokes, which may press it into their head (a buzz's
// press, the strike's aim below the surface), and a lift there would be
// divided by a vanishing bump into a leap of tens of cm. For the same reason a
// shortfall the strokes themselves leave at the move's ends (the right stick
// laid over the hi-hat to reach the crash) is not made up there: each point's
// shortfall counts above the line between the two ends'.
double kit_lift(const Item &a, const Item &b, const Window &w, const PerformerFrame &frame,
                const PlanOptions &opt, double &peak, bool cymbals_only = false)
{
    peak = 0.5;
    if (!(w.move_end > w.move_begin) || frame.drums.size() < 2)
        return 0.0;
    // A move to or from rest passes over the cymbals and over any head that
    // stands within kit_clearance_m of the lower rest tip, or above it (the
    // full kit's rack toms, raised over its kick).
    const double rest_y =
        std::min(frame.rest_tip_m[0].dot(frame.up), frame.rest_tip_m[1].dot(frame.up));
    // The shortfall at point x of the move.
    auto shortfall = [&](double x) {
        const double t = w.move_begin + x * (w.move_end - w.move_begin);
        const Eigen::Vector3d tip = pair_position(a, b, w, t);
        const Eigen::Vector3d dir = pair_direction(a, b, w, t);
        double short_m = 0.0;
        for (int j = -1; j < static_cast<int>(std::size(kShaftPoints_m)); ++j) {
            const Eigen::Vector3d p = j < 0 ? tip : Eigen::Vector3d(tip - kShaftPoints_m[j] * dir);
            for (size_t k = 0; k < frame.drums.size(); ++k) {
                const PerformerFrame::Drum &d = frame.drums[k];
                if (d.foot || (cymbals_only && !d.cymbal &&
                               d.membrane_center_m.dot(frame.up) < rest_y - opt.kit_clearance_m))
                    continue;
                const Eigen::Vector3d rel = p - d.membrane_center_m;
                const double height = rel.dot(frame.up);
                if ((rel - height * frame.up).norm() > d.membrane_radius_m + opt.kit_margin_m)
                    continue;
                const bool played = static_cast<int>(k) == a.drum || static_cast<int>(k) == b.drum;
                if (played && kit_bump(x) < 0.5)
                    continue;
                short_m = std::max(short_m, (played ? 0.0 : opt.kit_clearance_m) - height);
            }
        }
        const Eigen::Vector3d grip = tip - kGrip_m * dir;
        for (size_t k = 0; k < frame.drums.size(); ++k) {
            const PerformerFrame::Drum &d = frame.drums[k];
            const bool played = static_cast<int>(k) == a.drum || static_cast<int>(k) == b.drum;
            if (!d.pedal || (played && kit_bump(x) < 0.5))
                continue;
            const Eigen::Vector3d rel = grip - d.membrane_center_m;
            const double height = rel.dot(frame.up);
            if ((rel - height * frame.up).norm() <=
                kHihatRodRadius_m + kPalmHalfBreadth_m + opt.kit_margin_m)
                short_m = std::max(short_m, kHihatRodAbove_m + kPalmBelowGrip_m - height);
            // The stick, wherever it is within reach of the rod in plan (the
            // chord of tip - s dir, s in [0, length], inside that circle:
            // its height is linear in s, so its ends), stays above the rod's top.
            const Eigen::Vector3d from = tip - d.membrane_center_m;
            const Eigen::Vector3d from_plan = from - from.dot(frame.up) * frame.up;
            const Eigen::Vector3d dir_plan = dir - dir.dot(frame.up) * frame.up;
            const double reach = kHihatRodRadius_m + kStickRadius_m + opt.kit_margin_m;
            const double qa = dir_plan.squaredNorm(), qb = from_plan.dot(dir_plan);
            const double qc = from_plan.squaredNorm() - reach * reach;
            const bool upright = !(qa > 1e-12);
            const double disc = qb * qb - qa * qc, root = std::sqrt(std::max(disc, 0.0));
            const double s0 = upright ? 0.0 : std::max(0.0, (qb - root) / qa);
            const double s1 = upright ? kStick_m : std::min(kStick_m, (qb + root) / qa);
            if ((upright ? qc <= 0.0 : disc >= 0.0) && s0 <= s1)
                for (const double s_at : {s0, s1})
                    short_m = std::max(short_m, kHihatRodAbove_m + kStickRadius_m -
                                                    (from - s_at * dir).dot(frame.up));
        }
        return short_m;
    };
    // What the strokes themselves leave short (a stick laid over the hi-hat
    // to reach the crash) the move need not make up at its ends: it is
    // measured against the line between the two ends' shortfalls.
    // The lift's peak is the one of 0.3, 0.4, ..., 0.7 and the largest
    // shortfall's place (kept within them) that asks the least lift, that
    // place first among equals: a hand lifted over the hi-hat on its way to
    // the crash comes down again before the crash's stroke rises.
    const double short_begin = shortfall(0.0), short_end = shortfall(1.0);
    constexpr int kPoints = 48;
    double rel[kPoints] = {}, most = 0.0, at_most = 0.5;
    for (int i = 1; i < kPoints; ++i) {
        const double x = static_cast<double>(i) / kPoints;
        rel[i] = shortfall(x) - ((1.0 - x) * short_begin + x * short_end);
        if (rel[i] > most) {
            most = rel[i];
            at_most = std::clamp(x, 0.3, 0.7);
        }
    }
    auto lift_for = [&rel](double p) {
        double lift = 0.0;
        for (int i = 1; i < kPoints; ++i)
            lift = std::max(lift,
                            rel[i] / std::max(kit_bump(static_cast<double>(i) / kPoints, p), 0.05));
        return lift;
    };
    peak = at_most;
    double lift = lift_for(peak);
    for (const double p : {0.3, 0.4, 0.5, 0.6, 0.7})
        if (const double l = lift_for(p); l < lift) {
            lift = l;
            peak = p;
        }
    return lift;
}

// A move between a stroke and the hand's rest tip (window w, from a to b),
// lifted as a move between drums is over the kit's cymbals on its way, and
// over any head near or above the rest tips: the rest tips stand above most
// heads and below the cymbals, so that a hand going back to rest from a
// hi-hat would come down on its plate, and one from a raised rack tom through
// its neighbour. Unchanged (no move window) when nothing is in the way.
void lift_rest_move(const Item &a, const Item &b, Window &w, const PerformerFrame &frame,
                    const PlanOptions &opt)
{
    Window m = w;
    m.move_begin = w.begin;
    m.move_end = w.end;
    const double lift = kit_lift(a, b, m, frame, opt, m.lift_peak, true);
    if (lift > 0.0) {
        m.lift = lift * frame.up;
        w = m;
    }
}

// A hand's timeline: rest, unit, [rest,] unit, ..., rest, and the
// cross-fade windows between consecutive items.
struct HandTimeline {
    std::vector<Item> items;
    std::vector<Window> windows;
};

// The heading's turn between two strokes (turn rad) in window w: over the
// cross-fade, as the units' blend makes it, while its peak rate there
// (smoothstep5's, 15/8 of the mean) is within max_turn_rate_rad_s; else over
// a span widened from the cross-fade toward the move window as far as brings
// the peak down to it (the whole move window at most). A hand crossing from
// the ride to the hi-hat turns its stick 100 degrees: over the cross-fade
// (the middle half of the gap) the shoulder could not follow at 120 bpm.
void turn_for_window(double turn, const PerformerFrame &frame, const PlanOptions &opt, Window &w)
{
    const double fade_s = w.end - w.begin, move_s = w.move_end - w.move_begin;
    const double needed_s = 1.875 * std::abs(turn) / opt.max_turn_rate_rad_s;
    if (!(needed_s > fade_s) || !(move_s > fade_s))
        return;
    const double widen = std::min(1.0, (needed_s - fade_s) / (move_s - fade_s));
    w.turn_rad = turn;
    w.turn_begin = w.begin + widen * (w.move_begin - w.begin);
    w.turn_end = w.end + widen * (w.move_end - w.end);
    w.up = frame.up;
}

// The timeline of a hand with strokes; returns the end of its last motion.
double build_timeline(const HandStrokes &h, const PerformerFrame &frame, int s,
                      const PlanOptions &opt, HandTimeline &line)
{
    const std::vector<Item> &placed = h.placed;
    const size_t n = placed.size();
    const double beta = opt.blend_margin, tr = opt.return_time_s;
    double last_motion_end = 0.0;
    Item rest;
    rest.rest_pos = frame.rest_tip_m[s];
    rest.rest_dir = rest_stick_direction(frame, s);
    rest.drum = -1; // no drum: the rest tip
    line.items.push_back(rest);
    const double first_start = placed[0].strike_t - placed[0].prep_t;
    line.windows.push_back({std::max(0.0, first_start - tr), first_start});
    lift_rest_move(rest, placed[0], line.windows.back(), frame, opt);
    for (size_t k = 0; k < n; ++k) {
        line.items.push_back(placed[k]);
        const Item &it = placed[k];
        if (k + 1 == n || h.via_rest[k]) {
            Item back;
            back.rest_pos = frame.rest_tip_m[s];
            back.rest_dir = rest_stick_direction(frame, s);
            back.drum = -1;
            const double lift_end = it.strike_t + it.lift_t;
            line.windows.push_back({lift_end, lift_end + tr});
            lift_rest_move(it, back, line.windows.back(), frame, opt);
            last_motion_end = std::max(last_motion_end, lift_end + tr);
            line.items.push_back(back);
            if (k + 1 < n) {
                const double next_start = placed[k + 1].strike_t - placed[k + 1].prep_t;
                line.windows.push_back({next_start - tr, next_start});
                lift_rest_move(back, placed[k + 1], line.windows.back(), frame, opt);
            }
        } else {
            const double gap = placed[k + 1].strike_t - it.strike_t;
            Window w{it.strike_t + beta * gap, placed[k + 1].strike_t - beta * gap};
            // The move across the head (not the strike aim's depth).
            const Eigen::Vector3d move = placed[k + 1].origin - it.origin;
            w.across = move - move.dot(frame.up) * frame.up;
            w.move_begin = it.strike_t + opt.move_margin_after * gap;
            w.move_end = placed[k + 1].strike_t - opt.move_margin_before * gap;
            turn_for_window(std::remainder(placed[k + 1].yaw_rad - it.yaw_rad, 2.0 * M_PI), frame,
                            opt, w);
            if (it.drum != placed[k + 1].drum)
                w.lift = kit_lift(it, placed[k + 1], w, frame, opt, w.lift_peak) * frame.up;
            line.windows.push_back(w);
        }
    }
    return last_motion_end;
}

// A hand's tip and stick direction at every sample time: the ruling item,
// cross-faded with the next one inside a window, and the move across the head.
void sample_hand(const std::vector<double> &times, const HandTimeline &line,
                 std::vector<Eigen::Vector3d> &tip, std::vector<Eigen::Vector3d> &dir)
{
    tip.resize(times.size());
    dir.resize(times.size());
    const std::vector<Item> &its = line.items;
    const std::vector<Window> &win = line.windows;
    size_t j = 0, m = 0;
    for (size_t i = 0; i < times.size(); ++i) {
        const double t = times[i];
        while (j < win.size() && t > win[j].end)
            ++j;
        while (m < win.size() && t > win[m].move_end)
            ++m;
        Eigen::Vector3d p0, d0;
        its[j].eval(t, p0, d0);
        if (j < win.size() && t >= win[j].begin && win[j].end > win[j].begin) {
            Eigen::Vector3d p1, d1;
            its[j + 1].eval(t, p1, d1);
            const double w = smoothstep5((t - win[j].begin) / (win[j].end - win[j].begin));
            p0 = (1.0 - w) * p0 + w * p1;
            d0 = blend_directions(d0, d1, w);
        }
        // The move across the head: the units' blend makes it over
        // [begin, end]; it is made over [move_begin, move_end] instead
        // (smoothstep5 at both: C1 with the units).
        if (m < win.size() && t >= win[m].move_begin && win[m].move_end > win[m].move_begin) {
            const Window &mv = win[m];
            const double made = t < mv.begin ? 0.0
                                : t > mv.end ? 1.0
                                             : smoothstep5((t - mv.begin) / (mv.end - mv.begin));
            const double x = (t - mv.move_begin) / (mv.move_end - mv.move_begin);
            p0 += (smoothstep5(x) - made) * mv.across + kit_bump(x, mv.lift_peak) * mv.lift;
            if (mv.turn_rad != 0.0) {
                Eigen::Vector3d pa, da, pb, db;
                its[m].eval(t, pa, da);
                its[m + 1].eval(t, pb, db);
                d0 = window_direction(mv, t, da, db);
            }
        }
        tip[i] = p0;
        dir[i] = d0;
    }
}

} // namespace

double humanize_amount(const Score &score, const PlanOptions &options)
{
    return options.humanize >= 0.0 ? options.humanize : std::max(0.0, score.humanize);
}

GesturePlan plan_performance(const Score &score, const GestureDatabase &db,
                             const PerformerFrame &frame, const PlanOptions &opt)
{
    score_detail::validate_plan_inputs(frame, opt);
    Eigen::Matrix3d to_world;
    to_world.col(0) = frame.right;
    to_world.col(1) = frame.up;
    to_world.col(2) = frame.forward;

    GesturePlan plan;
    plan.score_start_s = opt.lead_in_s;
    UnitCache units(db); // the timelines' items point into it
    const HandNotes by_hand = time_notes(score, frame, opt, plan);
    for (const ScoreMeter &m : score.meters)
        plan.meters.push_back(
            {opt.lead_in_s + score.tempo.time_at_beat(m.beat), m.beat, m.numerator, m.denominator});

    std::array<HandTimeline, 2> timelines;
    double last_motion_end = 0.0;
    for (int s = 0; s < 2; ++s) {
        const std::vector<size_t> &idx = by_hand[s];
        if (idx.empty()) {
            // A hand with nothing to play holds its stick at rest.
            Item rest;
            rest.rest_pos = frame.rest_tip_m[s];
            rest.rest_dir = rest_stick_direction(frame, s);
            timelines[s].items.push_back(rest);
            continue;
        }
        HandStrokes strokes = place_strokes(idx, plan, frame, opt, to_world);
        choose_units(strokes, idx, plan, units);
        delay_for_contact(strokes, opt, frame, to_world);
        warp_units(strokes, idx, frame, opt, to_world, plan);
        last_motion_end =
            std::max(last_motion_end, build_timeline(strokes, frame, s, opt, timelines[s]));
    }

    plan.duration_s = plan_duration(score, opt, last_motion_end);
    sample_times(opt, plan);
    for (int s = 0; s < 2; ++s)
        sample_hand(plan.tips.time_s, timelines[s], plan.tips.tip_m[s], plan.stick_dir[s]);
    std::stable_sort(
        plan.notes.begin(), plan.notes.end(),
        [](const PlannedNote &a, const PlannedNote &b) { return a.time_s < b.time_s; });
    std::stable_sort(
        plan.foot_notes.begin(), plan.foot_notes.end(),
        [](const PlannedFootNote &a, const PlannedFootNote &b) { return a.time_s < b.time_s; });
    return plan;
}

} // namespace ictus
