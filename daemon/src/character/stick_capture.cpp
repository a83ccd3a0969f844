// Stick-only captures: tip trajectories, placement, drum fit.
#include "ictus/character/stick_capture.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

namespace ictus
{

namespace
{
std::string lower(std::string s)
{
    for (char &c : s)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}
} // namespace

Eigen::Vector3d TipTrajectory::sample(int side, double t) const
{
    const std::vector<Eigen::Vector3d> &p = tip_m[side];
    const double at = time_s.front() + t;
    if (at <= time_s.front())
        return p.front();
    if (at >= time_s.back())
        return p.back();
    const auto it = std::upper_bound(time_s.begin(), time_s.end(), at);
    const size_t i = static_cast<size_t>(it - time_s.begin());
    const double w = (at - time_s[i - 1]) / (time_s[i] - time_s[i - 1]);
    return (1.0 - w) * p[i - 1] + w * p[i];
}

std::array<int, 2> find_stick_tracks(const MarkerCapture &capture, const std::string &left,
                                     const std::string &right)
{
    std::string names;
    for (const MarkerTrack &t : capture.tracks)
        names += (names.empty() ? "" : ", ") + t.name;
    std::array<int, 2> found = {-1, -1};
    const std::string given[2] = {left, right};
    const char *exact[2] = {"stick_l", "stick_r"};
    const char *part[2] = {"left", "right"};
    for (int s = 0; s < 2; ++s) {
        if (!given[s].empty()) {
            const std::string option = s == 0 ? "--left-stick" : "--right-stick";
            // The name as written, else the one object that matches it in another casing:
            // a capture's names are its maker's ("Stick_L", "STICK_L"), a user types one.
            found[s] = capture.find(given[s]);
            if (found[s] < 0) {
                std::vector<int> other; // the objects spelt so in another casing
                for (size_t i = 0; i < capture.tracks.size(); ++i)
                    if (lower(capture.tracks[i].name) == lower(given[s]))
                        other.push_back(static_cast<int>(i));
                if (other.size() > 1) {
                    std::string spelt;
                    for (int i : other)
                        spelt += (spelt.empty() ? "" : ", ") + capture.tracks[i].name;
                    throw CharacterError(option + ": no object '" + given[s] +
                                         "' in the capture, and several in other casings (" +
                                         spelt + "); give one as written");
                }
                if (other.size() == 1)
                    found[s] = other[0];
            }
            if (found[s] < 0)
                throw CharacterError(option + ": no object '" + given[s] +
                                     "' in the capture, in any casing (objects: " + names + ")");
            continue;
        }
        for (size_t i = 0; i < capture.tracks.size() && found[s] < 0; ++i)
            if (lower(capture.tracks[i].name) == exact[s])
                found[s] = static_cast<int>(i);
        for (size_t i = 0; i < capture.tracks.size() && found[s] < 0; ++i)
            if (lower(capture.tracks[i].name).find(part[s]) != std::string::npos)
                found[s] = static_cast<int>(i);
        if (found[s] < 0)
            throw CharacterError(std::string("no ") + (s == 0 ? "left" : "right") +
                                 " stick in the capture (expected an object named " + exact[s] +
                                 " or containing '" + part[s] + "', or give --" +
                                 (s == 0 ? "left" : "right") + "-stick NAME; objects: " + names +
                                 ")");
    }
    if (found[0] == found[1])
        throw CharacterError("the left and right sticks are the same object '" +
                             capture.tracks[found[0]].name + "'");
    return found;
}

TipTrajectory place_behind_sticks(const CharacterModel &model, const CharacterPose &pose,
                                  const MarkerCapture &capture, const std::array<int, 2> &tracks)
{
    BodyFrames frames;
    model.forward(pose, frames);
    const Eigen::Vector3d shoulder[2] = {frames.origin_m[model.body_index("l_upper_arm")],
                                         frames.origin_m[model.body_index("r_upper_arm")]};
    const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
    Eigen::Vector3d body_lateral = shoulder[0] - shoulder[1];
    body_lateral.y() = 0.0;
    body_lateral.normalize();
    const Eigen::Vector3d forward = body_lateral.cross(up); // left x up = forward
    const Eigen::Vector3d goal =
        0.5 * (shoulder[0] + shoulder[1]) + kStickForward_m * forward - kStickBelow_m * up;

    Eigen::Vector3d mean[2], lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
    for (int s = 0; s < 2; ++s) {
        mean[s].setZero();
        for (const Eigen::Vector3d &p : capture.tracks[tracks[s]].position_m) {
            mean[s] += p;
            lo = lo.cwiseMin(p);
            hi = hi.cwiseMax(p);
        }
        mean[s] /= std::max<size_t>(1, capture.tracks[tracks[s]].position_m.size());
    }
    Eigen::Vector3d capture_lateral = mean[0] - mean[1];
    capture_lateral.y() = 0.0;
    if (capture_lateral.norm() < 1e-6)
        throw CharacterError("stick capture: the left and right sticks have the same mean "
                             "position; cannot tell left from right");
    capture_lateral.normalize();
    // The rotation about the vertical taking the capture's lateral axis onto the body's.
    const double angle =
        std::atan2(capture_lateral.cross(body_lateral).dot(up), capture_lateral.dot(body_lateral));
    const Eigen::AngleAxisd turn(angle, up);
    const Eigen::Vector3d centre = 0.5 * (lo + hi);

    TipTrajectory tips;
    tips.time_s = capture.time_s;
    for (int s = 0; s < 2; ++s)
        for (const Eigen::Vector3d &p : capture.tracks[tracks[s]].position_m)
            tips.tip_m[s].push_back(goal + turn * (p - centre));
    return tips;
}

namespace
{
// The vertex of a turnaround at sample i of heights y (times t), see find_turnarounds.
void refine_vertex(const std::vector<double> &t, const std::vector<double> &y, size_t i,
                   double &t_out, double &y_out)
{
    t_out = t[i];
    y_out = y[i];
    const size_t n = y.size();
    if (i < 1 || i + 1 >= n)
        return;
    // Parabola through i-1, i, i+1 (Lagrange form, vertex where its derivative vanishes).
    double tp = t[i], yp = y[i];
    {
        const double t0 = t[i - 1], t1 = t[i], t2 = t[i + 1];
        const double y0 = y[i - 1], y1 = y[i], y2 = y[i + 1];
        const double d0 = (y1 - y0) / (t1 - t0), d1 = (y2 - y1) / (t2 - t1);
        const double a = (d1 - d0) / (t2 - t0); // half the second derivative
        if (a > 0.0) {
            tp = 0.5 * (t0 + t1) - d0 / (2.0 * a);
            tp = std::min(t2, std::max(t0, tp));
            yp = y1 + d0 * (tp - t1) + a * (tp - t0) * (tp - t1);
            yp = std::min(yp, y1);
        }
    }
    if (i < 2 || i + 2 >= n) {
        t_out = tp;
        y_out = yp;
        return;
    }
    // The V: the lines through (i-2, i-1) and (i+1, i+2).
    const double s_in = (y[i - 1] - y[i - 2]) / (t[i - 1] - t[i - 2]);
    const double s_out = (y[i + 2] - y[i + 1]) / (t[i + 2] - t[i + 1]);
    double tv = t[i], yv = y[i];
    bool v_ok = false;
    if (s_in < 0.0 && s_out > 0.0) {
        // y[i-1] + s_in (x - t[i-1]) = y[i+1] + s_out (x - t[i+1])
        tv = (y[i + 1] - y[i - 1] + s_in * t[i - 1] - s_out * t[i + 1]) / (s_in - s_out);
        if (tv >= t[i - 1] && tv <= t[i + 1]) {
            yv = y[i - 1] + s_in * (tv - t[i - 1]);
            v_ok = yv <= y[i];
        }
    }
    if (!v_ok) {
        t_out = tp;
        y_out = yp;
        return;
    }
    // Which model predicts the samples it was not fitted to: the V predicts y[i]
    // (the upper of its two lines there), the parabola y[i-2] and y[i+2].
    const double v_pred =
        std::max(y[i - 1] + s_in * (t[i] - t[i - 1]), y[i + 1] + s_out * (t[i] - t[i + 1]));
    const double r_v = std::abs(v_pred - y[i]);
    const double d0 = (y[i] - y[i - 1]) / (t[i] - t[i - 1]);
    const double d1 = (y[i + 1] - y[i]) / (t[i + 1] - t[i]);
    const double a = (d1 - d0) / (t[i + 1] - t[i - 1]);
    const auto parabola = [&](double x) {
        return y[i] + d0 * (x - t[i]) + a * (x - t[i - 1]) * (x - t[i]);
    };
    const double r_p =
        0.5 * (std::abs(parabola(t[i - 2]) - y[i - 2]) + std::abs(parabola(t[i + 2]) - y[i + 2]));
    if (r_v <= r_p) {
        t_out = tv;
        y_out = yv;
    } else {
        t_out = tp;
        y_out = yp;
    }
}
} // namespace

std::vector<StrokeTurnaround> find_turnarounds(const TipTrajectory &tips, int side,
                                               double min_drop_m, double min_speed_mps)
{
    std::vector<StrokeTurnaround> out;
    const std::vector<Eigen::Vector3d> &p = tips.tip_m[side & 1];
    const size_t n = std::min(p.size(), tips.time_s.size());
    if (n < 3)
        return out;
    std::vector<double> t(n), y(n);
    for (size_t i = 0; i < n; ++i) {
        t[i] = tips.time_s[i] - tips.time_s.front();
        y[i] = p[i].y();
    }
    double high = y[0];   // highest point since the last turnaround
    double fastest = 0.0; // fastest descent since then, m/s
    for (size_t i = 1; i + 1 < n; ++i) {
        high = std::max(high, y[i]);
        if (y[i] > high - 1e-12) // a new high: the descent starts again from here
            fastest = 0.0;
        fastest = std::max(fastest, (y[i - 1] - y[i]) / (t[i] - t[i - 1]));
        // A stroke: a local minimum, at least min_drop_m below the highest point since
        // the last turnaround, reached by a descent at kMinStrokeSpeed_mps or faster at
        // some point (a resting stick's wobble is neither).
        if (!(y[i] <= y[i - 1] && y[i] < y[i + 1] && high - y[i] >= min_drop_m &&
              fastest >= min_speed_mps))
            continue;
        StrokeTurnaround ta;
        double tv = t[i], yv = y[i];
        refine_vertex(t, y, i, tv, yv);
        ta.time_s = tv;
        // The horizontal position at the vertex time (linear between the samples).
        const size_t k = tv <= t[i] ? i - 1 : i;
        const double w = (tv - t[k]) / (t[k + 1] - t[k]);
        ta.position_m = (1.0 - w) * p[k] + w * p[k + 1];
        ta.position_m.y() = yv;
        ta.speed_in_mps = i >= 1 ? (y[i - 1] - y[i]) / (t[i] - t[i - 1]) : 0.0;
        if (i >= 2)
            ta.speed_in_mps =
                std::max(ta.speed_in_mps, (y[i - 2] - y[i - 1]) / (t[i - 1] - t[i - 2]));
        out.push_back(ta);
        high = y[i];
        fastest = 0.0;
    }
    return out;
}

DrumFit fit_drum_to_turnarounds(const TipTrajectory &tips, double tip_radius_m)
{
    std::array<std::vector<StrokeTurnaround>, 2> all = {find_turnarounds(tips, 0),
                                                        find_turnarounds(tips, 1)};
    if (all[0].empty() && all[1].empty()) // no stroke fast enough: any turnaround
        all = {find_turnarounds(tips, 0, 0.01, 0.0), find_turnarounds(tips, 1, 0.01, 0.0)};
    std::vector<double> heights;
    for (const auto &side : all)
        for (const StrokeTurnaround &ta : side)
            heights.push_back(ta.position_m.y());
    if (heights.empty())
        throw CharacterError("--drum auto: no strokes in the stick capture (no turnaround of tip "
                             "height with a descent of 1 cm or more)");
    std::vector<double> sorted = heights;
    std::sort(sorted.begin(), sorted.end());
    const double quartile = sorted[(sorted.size() - 1) / 4];
    const double top = quartile + kImpactBand_m;
    DrumFit fit;
    std::vector<double> impact_heights;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    int sticks = 0;
    for (int s = 0; s < 2; ++s) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (const StrokeTurnaround &ta : all[s])
            if (ta.position_m.y() <= top) {
                fit.impacts[s].push_back(ta);
                impact_heights.push_back(ta.position_m.y());
                sum += ta.position_m;
            }
        if (!fit.impacts[s].empty()) {
            centre += sum / static_cast<double>(fit.impacts[s].size());
            ++sticks;
        }
    }
    centre /= sticks; // each stick counts once, however many strokes it played
    const size_t m = impact_heights.size();
    std::sort(impact_heights.begin(), impact_heights.end());
    const double median =
        m % 2 ? impact_heights[m / 2] : 0.5 * (impact_heights[m / 2 - 1] + impact_heights[m / 2]);
    centre.y() = median - kImpactPitchFactor * tip_radius_m;
    fit.center_m = centre;
    return fit;
}

TipTrajectory with_impact_vertices(const TipTrajectory &tips,
                                   const std::array<std::vector<StrokeTurnaround>, 2> &impacts)
{
    struct Insert {
        double t;
        int side;
        Eigen::Vector3d p;
    };
    std::vector<Insert> inserts;
    for (int s = 0; s < 2; ++s)
        for (const StrokeTurnaround &ta : impacts[s])
            inserts.push_back({ta.time_s, s, ta.position_m});
    std::sort(inserts.begin(), inserts.end(),
              [](const Insert &a, const Insert &b) { return a.t < b.t; });
    TipTrajectory out;
    const double t0 = tips.time_s.empty() ? 0.0 : tips.time_s.front();
    size_t k = 0;
    for (size_t i = 0; i < tips.time_s.size(); ++i) {
        const double t = tips.time_s[i] - t0;
        for (; k < inserts.size() && inserts[k].t < t - 1e-9; ++k) {
            if (!out.time_s.empty() && inserts[k].t + t0 <= out.time_s.back() + 1e-9)
                continue; // coincides with the previous sample (or two impacts at once)
            out.time_s.push_back(inserts[k].t + t0);
            for (int s = 0; s < 2; ++s)
                out.tip_m[s].push_back(s == inserts[k].side ? inserts[k].p
                                                            : tips.sample(s, inserts[k].t));
        }
        out.time_s.push_back(tips.time_s[i]);
        for (int s = 0; s < 2; ++s)
            out.tip_m[s].push_back(tips.tip_m[s][i]);
    }
    return out;
}

double impact_press_depth_m(double speed_mps, double stick_mass_kg, double stiffness_n_per_m)
{
    if (!(std::isfinite(speed_mps) && std::isfinite(stick_mass_kg) &&
          std::isfinite(stiffness_n_per_m) && speed_mps > 0.0 && stick_mass_kg > 0.0 &&
          stiffness_n_per_m > 0.0))
        return 0.0;
    return speed_mps * std::sqrt(stick_mass_kg / stiffness_n_per_m);
}

double fraction_through_drum(const TipTrajectory &tips, int side, const Eigen::Vector3d &center_m,
                             double radius_m, double clearance_m)
{
    const std::vector<Eigen::Vector3d> &p = tips.tip_m[side & 1];
    if (p.empty())
        return 0.0;
    size_t inside = 0;
    for (const Eigen::Vector3d &q : p)
        inside += std::hypot(q.x() - center_m.x(), q.z() - center_m.z()) < radius_m &&
                  q.y() < center_m.y() - clearance_m;
    return static_cast<double>(inside) / static_cast<double>(p.size());
}

Eigen::Vector3d drum_under_lowest_tips(const TipTrajectory &tips, double tip_radius_m)
{
    std::array<Eigen::Vector3d, 2> lowest;
    lowest.fill(Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()));
    for (int s = 0; s < 2; ++s)
        for (const Eigen::Vector3d &p : tips.tip_m[s])
            if (p.y() < lowest[s].y())
                lowest[s] = p;
    if (!(lowest[0].allFinite() && lowest[1].allFinite()))
        throw CharacterError("--drum auto: the capture has no tip positions");
    Eigen::Vector3d c = 0.5 * (lowest[0] + lowest[1]);
    c.y() = std::min(lowest[0].y(), lowest[1].y()) - kImpactPitchFactor * tip_radius_m;
    return c;
}

DrumPlacement place_drum(const TipTrajectory &tips, double tip_radius_m, double drum_radius_m)
{
    DrumPlacement out;
    out.fit = fit_drum_to_turnarounds(tips, tip_radius_m);
    out.center_m = out.fit.center_m;
    for (int s = 0; s < 2; ++s)
        out.through_fraction = std::max(
            out.through_fraction, fraction_through_drum(tips, s, out.center_m, drum_radius_m));
    if (out.through_fraction > kDrumThroughFraction) {
        out.at_turnarounds = false;
        out.center_m = drum_under_lowest_tips(tips, tip_radius_m);
    }
    return out;
}

Eigen::Vector3d fit_drum_to_strokes(const TipTrajectory &tips, double tip_radius_m)
{
    return fit_drum_to_turnarounds(tips, tip_radius_m).center_m;
}

} // namespace ictus
