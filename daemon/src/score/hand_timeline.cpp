// hand_timeline.cpp -- a hand's timeline: its units, the cross-fades between
// them, the moves across and between the pieces of a kit, lifted over what
// stands between (docs/score.md, "From score to motion"; docs/kit.md).
#include "hand_timeline.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace ictus
{
namespace score_detail
{

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

namespace
{

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

// The tip between two units of one hand at t in the move window: the units'
// cross-fade and the move to the next spot (as sample_hand makes it), without a lift.
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
    return p0 + (smoothstep5(x) - made) * w.shift;
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
// The bead's lowest point lies up to its radius below the stick's end (the
// tip the plan places): level, its centre is the end's height. A move across
// the edge of a head it plays keeps the end that high above it near the edge,
// and over the head it goes to: at the full kit the right hand's graces,
// planned low, grazed tom1's edge 5 mm under the end (`R on snare, L on tom1
// flam`) and touched the ride's bow 8 mm under it (`R on snare-rim flam, rest,
// L on ride-bell drag`), an extra strike 0.29 and 0.49 s before the grace.
constexpr double kBeadBelowEnd_m = StickParams{}.tip_radius_m;

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
                const double off_m = (rel - height * frame.up).norm();
                if (off_m > d.membrane_radius_m + opt.kit_margin_m)
                    continue;
                const bool played = static_cast<int>(k) == a.drum || static_cast<int>(k) == b.drum;
                if (played && kit_bump(x) < 0.5)
                    continue;
                // Crossing the edge of a head it plays, the bead (the tip, j < 0)
                // clears the edge: wherever the tip is within kit_margin_m of it in
                // plan, wider than the bead's reach, so that the move's points
                // (kPoints) need not fall within the bead's reach to keep it clear;
                // over the head it goes to, the head, before the stroke's own descent.
                const double bead_m =
                    j < 0 && (std::abs(off_m - d.membrane_radius_m) <= opt.kit_margin_m ||
                              static_cast<int>(k) == b.drum)
                        ? kBeadBelowEnd_m
                        : 0.0;
                short_m = std::max(short_m, (played ? bead_m : opt.kit_clearance_m) - height);
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

} // namespace

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
            // On one piece the move across its head (not the aims' depths); between
            // two pieces the whole move, their heights and aims too.
            const Eigen::Vector3d move = placed[k + 1].origin - it.origin;
            w.shift = it.drum != placed[k + 1].drum ? move : move - move.dot(frame.up) * frame.up;
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
// cross-faded with the next one inside a window, and the move to the next spot.
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
        // The move to the next spot: the units' blend makes it over
        // [begin, end]; it is made over [move_begin, move_end] instead
        // (smoothstep5 at both: C1 with the units).
        if (m < win.size() && t >= win[m].move_begin && win[m].move_end > win[m].move_begin) {
            const Window &mv = win[m];
            const double made = t < mv.begin ? 0.0
                                : t > mv.end ? 1.0
                                             : smoothstep5((t - mv.begin) / (mv.end - mv.begin));
            const double x = (t - mv.move_begin) / (mv.move_end - mv.move_begin);
            p0 += (smoothstep5(x) - made) * mv.shift + kit_bump(x, mv.lift_peak) * mv.lift;
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

} // namespace score_detail
} // namespace ictus
