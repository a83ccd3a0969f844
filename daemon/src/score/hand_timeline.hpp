// hand_timeline.hpp -- a hand's gesture units placed on its strokes and the
// moves between them: the timeline the planner samples (private to src/score;
// docs/score.md, "From score to motion"; docs/kit.md, "Playing it").
#pragma once

#include "ictus/score/gesture_score.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictus
{
namespace score_detail
{

// A unit's end state is extended beyond the unit by a motion that stops
// within this time (constant deceleration): C1 at the unit's ends.
inline constexpr double kStopTime_s = 0.05;
// Cubic Hermite tangents of samples p[first..last] (spacing h): central
// differences inside, second-order one-sided differences at the ends.
std::vector<Eigen::Vector3d> hermite_tangents(const std::vector<Eigen::Vector3d> &p, int first,
                                              int last, double h);

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
    // The move from the first unit's strike target to the second's, made over
    // [move_begin, move_end] instead of the cross-fade (zero for a window to or
    // from the rest tip): on one piece the move across its head (not the aims'
    // depths), between two pieces the whole move, their heights and aims too.
    // Over the cross-fade alone, the floor tom to the ride in a 16th at 120 bpm
    // rose 0.22 m at 6.6 m/s at its peak and the arm overshot by 16 cm.
    Eigen::Vector3d shift = Eigen::Vector3d::Zero();
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

// One hand's strokes on their way to the timeline: the units placed on
// their notes, and which gaps go through the rest tip (note k -> k+1).
struct HandStrokes {
    std::vector<Item> placed;
    std::vector<bool> via_rest;
};

// A hand's timeline: rest, unit, [rest,] unit, ..., rest, and the
// cross-fade windows between consecutive items.
struct HandTimeline {
    std::vector<Item> items;
    std::vector<Window> windows;
};

// The timeline of a hand with strokes; returns the end of its last motion.
double build_timeline(const HandStrokes &h, const PerformerFrame &frame, int s,
                      const PlanOptions &opt, HandTimeline &line);
// A hand's tip and stick direction at every sample time: the ruling item,
// cross-faded with the next one inside a window, and the move to the next spot.
void sample_hand(const std::vector<double> &times, const HandTimeline &line,
                 std::vector<Eigen::Vector3d> &tip, std::vector<Eigen::Vector3d> &dir);

} // namespace score_detail
} // namespace ictus
