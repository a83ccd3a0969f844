// segment.cpp -- captured stick-tip trajectories to gesture units: the strike
// rule, the cut at the maxima between strikes, the performer frame; import
// from BVH and marker CSV; the TrajOptDrums reader. docs/gestures.md,
// "Segmentation" and "Import".
#include "ictus/gesture/gesture.hpp"

#include "ictus/mocap/bvh.hpp"
#include "ictus/mocap/marker_csv.hpp"
#include "ictus/character/stick_capture.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace ictus
{

namespace
{

// Linear resampling of a series onto t0 + k / rate.
std::vector<Eigen::Vector3d> resample_linear(const std::vector<double> &time_s,
                                             const std::vector<Eigen::Vector3d> &v, double rate,
                                             int count)
{
    std::vector<Eigen::Vector3d> out(count);
    size_t j = 0;
    for (int k = 0; k < count; ++k) {
        const double t = time_s.front() + k / rate;
        while (j + 2 < time_s.size() && time_s[j + 1] <= t)
            ++j;
        const double a = std::clamp((t - time_s[j]) / (time_s[j + 1] - time_s[j]), 0.0, 1.0);
        out[k] = (1.0 - a) * v[j] + a * v[j + 1];
    }
    return out;
}

} // namespace

std::vector<GestureUnit> segment_strokes(const std::vector<double> &time_s,
                                         const std::vector<Eigen::Vector3d> &tip_world_m,
                                         const Eigen::Vector3d &performer_right_world, Grip g,
                                         Nuance n, Side h)
{
    return segment_strokes(time_s, tip_world_m, performer_right_world, g, n, h, SegmentOptions{},
                           nullptr);
}

namespace
{

// The input of segment_strokes: as many times as samples (and directions),
// at least 3, finite, times strictly increasing; a positive output rate.
void check_samples(const std::vector<double> &time_s,
                   const std::vector<Eigen::Vector3d> &tip_world_m, const SegmentOptions &opts,
                   const std::vector<Eigen::Vector3d> *stick_dir_world)
{
    if (time_s.size() != tip_world_m.size())
        throw GestureError("segment_strokes: " + std::to_string(time_s.size()) + " times but " +
                           std::to_string(tip_world_m.size()) + " tip positions");
    if (stick_dir_world && stick_dir_world->size() != time_s.size())
        throw GestureError("segment_strokes: stick directions and times differ in length");
    if (time_s.size() < 3)
        throw GestureError("segment_strokes: need at least 3 samples, got " +
                           std::to_string(time_s.size()));
    if (!(opts.rate_hz > 0.0) || !std::isfinite(opts.rate_hz))
        throw GestureError("segment_strokes: rate_hz must be > 0");
    for (size_t i = 0; i < time_s.size(); ++i) {
        if (!std::isfinite(time_s[i]) || !tip_world_m[i].allFinite())
            throw GestureError("segment_strokes: sample " + std::to_string(i) + " is not finite");
        if (i > 0 && !(time_s[i] > time_s[i - 1]))
            throw GestureError("segment_strokes: time not strictly increasing at sample " +
                               std::to_string(i));
    }
}

// The performer frame's axes in the world (a reflection of it).
struct PerformerAxes {
    Eigen::Vector3d right, up, forward;
};

PerformerAxes performer_axes(const Eigen::Vector3d &performer_right_world)
{
    Eigen::Vector3d right(performer_right_world.x(), 0.0, performer_right_world.z());
    if (!right.allFinite() || right.norm() < 1e-9)
        throw GestureError("segment_strokes: the performer's right has no horizontal direction");
    right.normalize();
    const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
    return {right, up, up.cross(right)};
}

// The strike rule (docs/gestures.md): a local minimum of height, deep
// enough (within the lowest depth_fraction of the height range, or
// min_depth_window_m of the lowest point), approached fast enough (mean
// downward speed over approach_window_s), and separated from the previous
// strike by a rise of at least min_rise_m (else the lower one is kept:
// bounces and jitter). The strikes' sample indices; a GestureError when none.
std::vector<int> find_strikes(const std::vector<Eigen::Vector3d> &tip, double rate,
                              const SegmentOptions &opts)
{
    const int count = static_cast<int>(tip.size());
    double lo = tip[0].y(), hi = tip[0].y();
    for (const auto &p : tip) {
        lo = std::min(lo, p.y());
        hi = std::max(hi, p.y());
    }
    const double depth = std::max(opts.min_depth_window_m, opts.depth_fraction * (hi - lo));
    const int window = std::max(1, static_cast<int>(std::lround(opts.approach_window_s * rate)));
    std::vector<int> strikes;
    for (int k = 1; k + 1 < count; ++k) {
        const double y = tip[k].y();
        if (!(y <= tip[k - 1].y() && y < tip[k + 1].y()))
            continue;
        if (y > lo + depth)
            continue;
        const int k0 = std::max(0, k - window);
        if (k0 == k || (tip[k0].y() - y) * rate / (k - k0) < opts.min_approach_mps)
            continue;
        if (!strikes.empty()) {
            double peak = y;
            for (int j = strikes.back(); j <= k; ++j)
                peak = std::max(peak, tip[j].y());
            const double rise = peak - std::max(y, tip[strikes.back()].y());
            if (rise < opts.min_rise_m) {
                if (y < tip[strikes.back()].y())
                    strikes.back() = k;
                continue;
            }
        }
        strikes.push_back(k);
    }
    if (strikes.empty())
        throw GestureError("segment_strokes: no strike found (no local minimum of tip height "
                           "within " +
                           std::to_string(depth) + " m of the lowest point approached at >= " +
                           std::to_string(opts.min_approach_mps) + " m/s)");
    return strikes;
}

} // namespace

std::vector<GestureUnit> segment_strokes(const std::vector<double> &time_s,
                                         const std::vector<Eigen::Vector3d> &tip_world_m,
                                         const Eigen::Vector3d &performer_right_world, Grip g,
                                         Nuance n, Side h, const SegmentOptions &opts,
                                         const std::vector<Eigen::Vector3d> *stick_dir_world)
{
    check_samples(time_s, tip_world_m, opts, stick_dir_world);
    const PerformerAxes axes = performer_axes(performer_right_world);
    const double rate = opts.rate_hz;
    if ((time_s.back() - time_s.front()) * rate > 1e8)
        throw GestureError("segment_strokes: more than 1e8 samples at the output rate");
    const int count =
        1 + static_cast<int>(std::floor((time_s.back() - time_s.front()) * rate + 1e-9));
    if (count < 3)
        throw GestureError("segment_strokes: trajectory shorter than 3 samples at the output rate");
    const std::vector<Eigen::Vector3d> tip = resample_linear(time_s, tip_world_m, rate, count);
    std::vector<Eigen::Vector3d> dir;
    if (stick_dir_world)
        dir = resample_linear(time_s, *stick_dir_world, rate, count);
    const std::vector<int> strikes = find_strikes(tip, rate, opts);

    // Cuts at the highest sample between strikes (and before the first, after the last).
    auto argmax = [&](int a, int b) {
        int best = a;
        for (int j = a; j <= b; ++j)
            if (tip[j].y() > tip[best].y())
                best = j;
        return best;
    };
    std::vector<GestureUnit> units;
    const double period_guess =
        strikes.size() > 1 ? (strikes.back() - strikes.front()) / rate / (strikes.size() - 1) : 0.5;
    for (size_t i = 0; i < strikes.size(); ++i) {
        const int s = strikes[i];
        const int a = argmax(i == 0 ? 0 : strikes[i - 1], s);
        const int b = argmax(s, i + 1 < strikes.size() ? strikes[i + 1] : count - 1);
        GestureUnit u;
        u.grip = g;
        u.nuance = n;
        u.hand = h;
        u.rate_hz = rate;
        u.strike_index = s - a;
        u.period_s = period_guess;
        u.source = "capture";
        u.capture_time_s = time_s.front() + a / rate;
        const Eigen::Vector3d origin = tip[s];
        for (int j = a; j <= b; ++j) {
            const Eigen::Vector3d d = tip[j] - origin;
            u.tip_m.emplace_back(d.dot(axes.right), d.dot(axes.up), d.dot(axes.forward));
            if (!dir.empty()) {
                const Eigen::Vector3d sd = dir[j].normalized();
                u.stick_dir.emplace_back(sd.dot(axes.right), sd.dot(axes.up), sd.dot(axes.forward));
            }
        }
        units.push_back(std::move(u));
    }
    // Dynamics: the representative level is not known from a capture alone;
    // units keep 0.6 (mf), the level instantiate() scales from.
    return units;
}

const GestureUnit &representative_unit(const std::vector<GestureUnit> &units)
{
    if (units.empty())
        throw GestureError("no strokes to choose from");
    std::vector<std::pair<double, size_t>> speeds;
    for (size_t i = 0; i < units.size(); ++i)
        speeds.emplace_back(units[i].impact_speed_mps(), i);
    std::sort(speeds.begin(), speeds.end());
    return units[speeds[(speeds.size() - 1) / 2].second];
}

namespace
{

bool ends_with(const std::string &s, const std::string &suffix)
{
    if (s.size() < suffix.size())
        return false;
    std::string tail = s.substr(s.size() - suffix.size());
    std::transform(tail.begin(), tail.end(), tail.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return tail == suffix;
}

std::string base_name(const std::string &path)
{
    const auto slash = path.find_last_of('/');
    return slash == std::string::npos ? path : path.substr(slash + 1);
}

} // namespace

std::vector<GestureUnit> import_capture(const std::string &path, Grip g, Nuance n, Side h,
                                        const ImportOptions &opts)
{
    std::vector<double> time_s;
    std::vector<Eigen::Vector3d> tip, dir;
    Eigen::Vector3d right = Eigen::Vector3d::Zero();
    try {
        if (ends_with(path, ".bvh")) {
            BvhOptions bo;
            bo.scale = opts.bvh_scale;
            bo.skip_frames = opts.bvh_skip_frames;
            const BvhFile bvh = read_bvh(path, bo);
            CharacterOptions co;
            co.grip = g;
            const CharacterModel model = CharacterModel::from_skeleton(bvh.skeleton, co);
            const int hb = model.hand_body(h);
            const int ls = model.body_index("l_upper_arm"), rs = model.body_index("r_upper_arm");
            BodyFrames frames;
            for (int f = 0; f < bvh.motion.frames(); ++f) {
                const CharacterPose pose = model.pose_from_motion(bvh.motion, f);
                model.forward(pose, frames);
                time_s.push_back(f / bvh.motion.frame_rate_hz);
                tip.push_back(model.tip_position(h, frames.origin_m[hb], frames.rotation[hb]));
                dir.push_back(frames.rotation[hb] * model.stick(h).axis);
                if (ls >= 0 && rs >= 0)
                    right += frames.origin_m[rs] - frames.origin_m[ls];
            }
        } else if (ends_with(path, ".csv")) {
            const MarkerCapture cap = read_marker_csv(path, opts.csv);
            const auto tracks = find_stick_tracks(cap, opts.left_stick, opts.right_stick);
            time_s = cap.time_s;
            tip = cap.tracks[tracks[static_cast<int>(h)]].position_m;
            for (size_t f = 0; f < cap.time_s.size(); ++f)
                right += cap.tracks[tracks[1]].position_m[f] - cap.tracks[tracks[0]].position_m[f];
        } else {
            throw GestureError(path + ": unknown capture type (expected .bvh or .csv)");
        }
    } catch (const MocapError &e) {
        throw GestureError(e.what());
    } catch (const CharacterError &e) {
        // The skeleton's errors name the file (and the OFFSET's line) already.
        const std::string what = e.what();
        throw GestureError(what.rfind(path, 0) == 0 ? what : path + ": " + what);
    }
    std::vector<GestureUnit> units;
    try {
        units = segment_strokes(time_s, tip, right, g, n, h, opts.segment,
                                dir.empty() ? nullptr : &dir);
    } catch (const GestureError &e) {
        throw GestureError(path + ": " + e.what());
    }
    for (auto &u : units)
        u.source = base_name(path);
    return units;
}

// ---------------------------------------------------------------------------
// TrajOptDrums: two CSV files with a header row "Time (s),Shoulder Joint,...,
// Drum Bead,..." and rows of numbers (cm); trailing empty columns allowed.

namespace
{

void read_trajopt_column(const std::string &path, std::vector<double> &time_s,
                         std::vector<double> &value_m)
{
    std::ifstream in(path);
    if (!in)
        throw GestureError(path + ":0: cannot open");
    std::string line;
    int line_no = 0;
    int time_col = -1, bead_col = -1;
    while (std::getline(in, line)) {
        ++line_no;
        if (!line.empty() && line.back() == '\r')
            line.pop_back();
        std::vector<std::string> cells;
        std::stringstream ss(line);
        std::string cell;
        while (std::getline(ss, cell, ','))
            cells.push_back(cell);
        if (line_no == 1) {
            for (size_t i = 0; i < cells.size(); ++i) {
                if (cells[i].rfind("Time", 0) == 0)
                    time_col = static_cast<int>(i);
                if (cells[i] == "Drum Bead")
                    bead_col = static_cast<int>(i);
            }
            if (time_col < 0 || bead_col < 0)
                throw GestureError(path + ":1: expected a header with \"Time (s)\" and "
                                          "\"Drum Bead\" columns");
            continue;
        }
        if (line.find_first_not_of(" \t,") == std::string::npos)
            continue;
        auto number = [&](int col, const char *what) {
            if (col >= static_cast<int>(cells.size()))
                throw GestureError(path + ":" + std::to_string(line_no) + ": missing " + what +
                                   " column");
            const std::string &c = cells[col];
            char *end = nullptr;
            const double v = std::strtod(c.c_str(), &end);
            if (c.empty() || end == c.c_str() || *end != '\0' || !std::isfinite(v))
                throw GestureError(path + ":" + std::to_string(line_no) +
                                   ": expected a number for " + what + ", got '" + c + "'");
            return v;
        };
        const double t = number(time_col, "Time (s)");
        if (!time_s.empty() && !(t > time_s.back()))
            throw GestureError(path + ":" + std::to_string(line_no) +
                               ": time not strictly increasing");
        time_s.push_back(t);
        value_m.push_back(0.01 * number(bead_col, "Drum Bead"));
    }
    if (time_s.size() < 3)
        throw GestureError(path + ":" + std::to_string(line_no) + ": fewer than 3 data rows");
}

} // namespace

SagittalRecording read_trajoptdrums(const std::string &dir)
{
    SagittalRecording r;
    std::vector<double> ty;
    read_trajopt_column(dir + "/JointCenters_XPose_cm.csv", r.time_s, r.forward_m);
    read_trajopt_column(dir + "/JointCenters_YPose_cm.csv", ty, r.up_m);
    if (ty.size() != r.time_s.size())
        throw GestureError(dir + "/JointCenters_YPose_cm.csv:0: " + std::to_string(ty.size()) +
                           " rows, the X file has " + std::to_string(r.time_s.size()));
    for (size_t i = 0; i < ty.size(); ++i)
        if (std::abs(ty[i] - r.time_s[i]) > 1e-6)
            throw GestureError(dir + "/JointCenters_YPose_cm.csv:" + std::to_string(i + 2) +
                               ": time differs from the X file's");
    return r;
}

} // namespace ictus
