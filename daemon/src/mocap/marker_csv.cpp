// marker_csv.cpp -- CSV of tracked objects -> MarkerCapture (y up, metres).
#include "ictus/mocap/marker_csv.hpp"

#include "ictus/mocap/capture_bounds.hpp"
#include "text_lines.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>

namespace ictus
{

namespace
{

using detail::quote;

constexpr std::size_t kMaxFileBytes = std::size_t{512} << 20; // 512 MiB
constexpr int kMaxColumns = 100000;

// Components of an object's columns, in the order stored in Columns::index.
const char *const kComponents[7] = {"x", "y", "z", "qw", "qx", "qy", "qz"};

struct ObjectColumns {
    std::string name;
    int index[7] = {-1, -1, -1, -1, -1, -1, -1};
    bool has_orientation() const { return index[3] >= 0; }
};

std::vector<std::string> split_commas(const std::string &line)
{
    std::vector<std::string> cells;
    std::string cell;
    for (char c : line) {
        if (c == ',') {
            cells.push_back(detail::trim(cell));
            cell.clear();
        } else {
            cell.push_back(c);
        }
    }
    cells.push_back(detail::trim(cell));
    for (std::string &text : cells)
        if (text.size() >= 2 && text.front() == '"' && text.back() == '"')
            text = text.substr(1, text.size() - 2);
    return cells;
}

std::string lower(std::string text)
{
    for (char &c : text)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return text;
}

std::string number_text(double value)
{
    std::ostringstream text;
    text << value;
    return text.str();
}

bool is_comment_or_blank(const std::string &line)
{
    const std::string text = detail::trim(line);
    return text.empty() || text[0] == '#';
}

class CsvParser
{
  public:
    CsvParser(const std::vector<std::string> &lines, const std::string &source,
              const MarkerCsvOptions &options, MocapWarnings *warnings)
        : lines_(lines), source_(source), options_(options), warnings_(warnings)
    {
    }

    MarkerCapture parse()
    {
        check_options();
        std::size_t l = 0;
        while (l < lines_.size() && is_comment_or_blank(lines_[l]))
            ++l;
        if (l == lines_.size())
            throw MocapError(source_, static_cast<int>(lines_.size()),
                             "expected a header row (time or frame, NAME.x, NAME.y, NAME.z, ...), "
                             "got end of file");
        header_line_ = static_cast<int>(l) + 1;
        parse_header(split_commas(lines_[l]));
        for (++l; l < lines_.size(); ++l) {
            if (is_comment_or_blank(lines_[l]))
                continue;
            parse_row(split_commas(lines_[l]), static_cast<int>(l) + 1);
        }
        if (capture_.time_s.empty())
            throw MocapError(source_, static_cast<int>(lines_.size()),
                             "expected at least one data row, got none");
        for (std::size_t k = 0; k < objects_.size(); ++k)
            fill_gaps(k);
        check_time_bounds();
        convert_axes_and_units();
        return std::move(capture_);
    }

  private:
    void check_options() const
    {
        if (options_.max_gap_frames < 0)
            throw MocapError(source_, 0,
                             "expected MarkerCsvOptions::max_gap_frames >= 0, got " +
                                 std::to_string(options_.max_gap_frames));
    }

    [[noreturn]] void header_error(const std::string &expected, const std::string &got) const
    {
        throw MocapError(source_, header_line_, "expected " + expected + ", got " + got);
    }

    void parse_header(const std::vector<std::string> &cells)
    {
        if (static_cast<int>(cells.size()) > kMaxColumns)
            header_error("at most " + std::to_string(kMaxColumns) + " columns",
                         std::to_string(cells.size()));
        column_count_ = cells.size();
        // A comma at the end of the header (as spreadsheets export) is an empty
        // last column, not data: each row must end with an empty cell too.
        trailing_empty_ = cells.size() > 1 && cells.back().empty();
        const std::size_t named = cells.size() - (trailing_empty_ ? 1 : 0);
        std::map<std::string, int> seen;
        std::map<std::string, std::size_t> object_of;
        for (std::size_t c = 0; c < named; ++c) {
            const std::string &name = cells[c];
            if (name.empty())
                header_error("a column name in column " + std::to_string(c + 1), "an empty cell");
            if (!seen.emplace(name, static_cast<int>(c)).second)
                header_error("each column name once", "a duplicate column " + quote(name));
            const std::string key = lower(name);
            // "Time (s)" (TrajOptDrums' exports): seconds, said in the name.
            if (key == "time" || key == "time (s)" || key == "time(s)") {
                time_column_ = static_cast<int>(c);
                continue;
            }
            if (key == "frame") {
                frame_column_ = static_cast<int>(c);
                continue;
            }
            const std::size_t dot = name.rfind('.');
            int component = -1;
            if (dot != std::string::npos && dot > 0)
                for (int k = 0; k < 7; ++k)
                    if (lower(name.substr(dot + 1)) == kComponents[k])
                        component = k;
            if (component < 0) {
                // Real exports carry extra columns (marker residuals, frame flags):
                // they are skipped with a warning rather than refusing the file.
                if (warnings_)
                    warnings_->push_back(source_ + ":" + std::to_string(header_line_) +
                                         ": column " + std::to_string(c + 1) + " " + quote(name) +
                                         " ignored (not time, frame or NAME.x|y|z|qw|qx|qy|qz)");
                continue;
            }
            const std::string object = name.substr(0, dot);
            auto found = object_of.find(object);
            if (found == object_of.end()) {
                found = object_of.emplace(object, objects_.size()).first;
                objects_.push_back(ObjectColumns{object});
            }
            objects_[found->second].index[component] = static_cast<int>(c);
        }
        if (named == 1 &&
            (cells[0].find(';') != std::string::npos || cells[0].find('\t') != std::string::npos))
            header_error("comma-separated columns",
                         std::string("one column holding ") +
                             (cells[0].find(';') != std::string::npos ? "';'" : "tabs") +
                             ": a file separated by another character (save it with commas)");
        if (time_column_ < 0 && frame_column_ < 0)
            header_error("a column named time or Time (s) (seconds), or frame (with --rate HZ)",
                         "neither");
        if (time_column_ < 0 && (!std::isfinite(options_.rate_hz) || options_.rate_hz <= 0.0))
            header_error("a frame rate (--rate HZ) for a file with a frame column and no time "
                         "column",
                         options_.rate_hz == 0.0 ? std::string("none")
                                                 : number_text(options_.rate_hz));
        if (objects_.empty())
            header_error("at least one object (NAME.x NAME.y NAME.z)", "none");
        for (const ObjectColumns &object : objects_) {
            for (int k = 0; k < 3; ++k)
                if (object.index[k] < 0)
                    header_error("column " + object.name + "." + kComponents[k] + " for object " +
                                     quote(object.name),
                                 "none");
            const bool any_q = object.index[3] >= 0 || object.index[4] >= 0 ||
                               object.index[5] >= 0 || object.index[6] >= 0;
            if (any_q)
                for (int k = 3; k < 7; ++k)
                    if (object.index[k] < 0)
                        header_error("all of " + object.name + ".qw .qx .qy .qz, or none",
                                     "no " + object.name + "." + kComponents[k]);
            MarkerTrack track;
            track.name = object.name;
            capture_.tracks.push_back(track);
        }
        missing_.resize(objects_.size());
    }

    // A number, or NaN for a gap (empty cell or NaN). Infinity is an error.
    double cell_value(const std::string &cell, int line, std::size_t column) const
    {
        if (cell.empty())
            return std::numeric_limits<double>::quiet_NaN();
        double value = 0.0;
        if (!detail::parse_double(cell, value))
            throw MocapError(source_, line,
                             "expected a number or an empty cell in column " +
                                 std::to_string(column + 1) + ", got " + quote(cell));
        if (std::isinf(value) || std::fabs(value) > 1e9) // absurd; could overflow later
            throw MocapError(source_, line,
                             "expected a finite number (|x| <= 1e9) in column " +
                                 std::to_string(column + 1) + ", got " + quote(cell));
        return value;
    }

    void parse_row(const std::vector<std::string> &cells, int line)
    {
        if (cells.size() != column_count_)
            throw MocapError(source_, line,
                             "expected " + std::to_string(column_count_) +
                                 " cells (as the header), got " + std::to_string(cells.size()));
        if (trailing_empty_ && !cells.back().empty())
            throw MocapError(source_, line,
                             "expected an empty cell in column " + std::to_string(cells.size()) +
                                 " (the header ends with a comma), got " + quote(cells.back()));
        if (static_cast<long>(capture_.time_s.size()) >= options_.max_frames)
            throw MocapError(source_, line,
                             "expected at most " + std::to_string(options_.max_frames) +
                                 " data rows, got more");
        double time_s = 0.0;
        if (time_column_ >= 0) {
            time_s = cell_value(cells[static_cast<std::size_t>(time_column_)], line,
                                static_cast<std::size_t>(time_column_));
            if (std::isnan(time_s))
                throw MocapError(source_, line, "expected a time (s), got an empty cell or NaN");
        } else {
            const double frame = cell_value(cells[static_cast<std::size_t>(frame_column_)], line,
                                            static_cast<std::size_t>(frame_column_));
            if (std::isnan(frame) || frame != std::floor(frame))
                throw MocapError(source_, line,
                                 "expected a whole frame number, got " +
                                     quote(cells[static_cast<std::size_t>(frame_column_)]));
            time_s = frame / options_.rate_hz;
        }
        if (!capture_.time_s.empty() && !(time_s > capture_.time_s.back()))
            throw MocapError(source_, line,
                             "expected time to increase (previous row " +
                                 std::to_string(capture_.time_s.back()) + " s), got " +
                                 std::to_string(time_s) + " s");
        capture_.time_s.push_back(time_s);
        row_lines_.push_back(line);
        for (std::size_t k = 0; k < objects_.size(); ++k) {
            const ObjectColumns &object = objects_[k];
            MarkerTrack &track = capture_.tracks[k];
            double v[7];
            bool gap = false;
            const int used = object.has_orientation() ? 7 : 3;
            for (int c = 0; c < used; ++c) {
                const auto column = static_cast<std::size_t>(object.index[c]);
                v[c] = cell_value(cells[column], line, column);
                gap = gap || std::isnan(v[c]);
                if (c < 3 && std::fabs(v[c]) * unit_m() > kMaxCoordinate_m)
                    out_of_bounds(line, "coordinate",
                                  "expected |coordinate| <= " + number_text(kMaxCoordinate_m) +
                                      " m (" + number_text(kMaxCoordinate_m / unit_m()) + " " +
                                      unit_name() + ") in column " + std::to_string(column + 1) +
                                      " (" + object.name + "." + kComponents[c] + "), got " +
                                      quote(cells[column]) + " " + unit_name());
            }
            missing_[k].push_back(gap);
            const double nan = std::numeric_limits<double>::quiet_NaN();
            track.position_m.push_back(gap ? Eigen::Vector3d::Constant(nan)
                                           : Eigen::Vector3d(v[0], v[1], v[2]));
            if (!object.has_orientation())
                continue;
            Eigen::Quaterniond q(v[3], v[4], v[5], v[6]);
            if (!gap) {
                const double norm = q.norm();
                if (!(norm > 1e-6))
                    throw MocapError(source_, line,
                                     "expected a non-zero quaternion for " + object.name +
                                         ", got norm " + std::to_string(norm));
                q.coeffs() /= norm;
            }
            track.orientation.push_back(q);
        }
    }

    // Interior gaps of at most max_gap_frames: linear / slerp in time; else error.
    void fill_gaps(std::size_t k)
    {
        const std::vector<bool> &missing = missing_[k];
        MarkerTrack &track = capture_.tracks[k];
        const std::size_t frames = missing.size();
        std::size_t i = 0;
        while (i < frames) {
            if (!missing[i]) {
                ++i;
                continue;
            }
            std::size_t end = i; // gap is [i, end)
            while (end < frames && missing[end])
                ++end;
            const std::string where = "object " + quote(track.name) + " frames " +
                                      std::to_string(i) + "-" + std::to_string(end - 1) +
                                      " (lines " + std::to_string(row_lines_[i]) + "-" +
                                      std::to_string(row_lines_[end - 1]) + ")";
            const int line = row_lines_[i];
            if (i == 0 || end == frames)
                throw MocapError(source_, line,
                                 "expected samples on both sides of every gap, got a gap at the " +
                                     std::string(i == 0 ? "start" : "end") + ": " + where);
            const auto length = static_cast<int>(end - i);
            if (!options_.interpolate_gaps)
                throw MocapError(source_, line,
                                 "expected no gaps (interpolate_gaps is off), got " + where);
            if (length > options_.max_gap_frames)
                throw MocapError(source_, line,
                                 "expected gaps of at most " +
                                     std::to_string(options_.max_gap_frames) + " frames, got " +
                                     std::to_string(length) + ": " + where);
            const std::size_t before = i - 1;
            const double t0 = capture_.time_s[before];
            const double t1 = capture_.time_s[end];
            for (std::size_t f = i; f < end; ++f) {
                const double u = (capture_.time_s[f] - t0) / (t1 - t0);
                track.position_m[f] =
                    (1.0 - u) * track.position_m[before] + u * track.position_m[end];
                if (!track.orientation.empty())
                    track.orientation[f] =
                        track.orientation[before].slerp(u, track.orientation[end]).normalized();
            }
            if (warnings_)
                warnings_->push_back(source_ + ":" + std::to_string(line) + ": interpolated " +
                                     std::to_string(length) + " missing frame(s) of " + where);
            i = end;
        }
    }

    double unit_m() const { return options_.units == MarkerCsvOptions::Units::mm ? 1e-3 : 1.0; }
    const char *unit_name() const
    {
        return options_.units == MarkerCsvOptions::Units::mm ? "mm" : "m";
    }

    // A value out of the physical bounds of a capture (capture_bounds.hpp):
    // refused, or read with a warning (the first of each kind) when accepted.
    void out_of_bounds(int line, const std::string &kind, const std::string &message)
    {
        bounds_.out_of_bounds(line, kind, message);
    }

    // The clock: the median step (robust to dropped frames) within the
    // sampling bounds, the whole capture within kMaxCaptureDuration_s. Errors
    // point at the first row whose step, or whose time, is out of bounds.
    // The likely fault behind a clock out of bounds: a time column's unit, or the
    // rate that times a frame column (there is no unit to blame then).
    std::string clock_hint(bool too_slow) const
    {
        if (time_column_ < 0)
            return "; is rate_hz " + number_text(options_.rate_hz) + " the capture's frame rate?";
        return too_slow ? "; a time column in ms or us?" : "; a time column in minutes or hours?";
    }

    void check_time_bounds()
    {
        const std::vector<double> &t = capture_.time_s;
        if (t.size() < 2)
            return;
        const std::string clock = time_column_ >= 0
                                      ? std::string("time column (s)")
                                      : "frame column / rate_hz " + number_text(options_.rate_hz);
        std::vector<double> steps(t.size() - 1);
        for (std::size_t i = 0; i + 1 < t.size(); ++i)
            steps[i] = t[i + 1] - t[i];
        std::vector<double> sorted = steps;
        const auto middle = sorted.begin() + static_cast<std::ptrdiff_t>((sorted.size() - 1) / 2);
        std::nth_element(sorted.begin(), middle, sorted.end());
        const double median = *middle;
        // A step is the difference of two printed times: a relative 1e-6 of
        // rounding is allowed (at 2 kHz, k/2000 - (k-1)/2000 can be 1 ulp short).
        const double fastest = kMinSampleInterval_s * (1.0 - 1e-6);
        const double slowest = kMaxSampleInterval_s * (1.0 + 1e-6);
        const bool too_slow = median > slowest;
        if (too_slow || median < fastest) {
            std::size_t i = 0;
            while (i + 1 < steps.size() && (too_slow ? steps[i] <= slowest : steps[i] >= fastest))
                ++i;
            out_of_bounds(row_lines_[i + 1], "time step",
                          "expected a median time step in [" + number_text(kMinSampleInterval_s) +
                              ", " + number_text(kMaxSampleInterval_s) +
                              "] s (a capture at 2 Hz to 2 kHz) from the " + clock + ", got " +
                              number_text(median) + " s (this row: " + number_text(steps[i]) +
                              " s after the previous" + clock_hint(too_slow) + ")");
        }
        const double duration = t.back() - t.front();
        if (duration > kMaxCaptureDuration_s) {
            std::size_t i = 1;
            while (i + 1 < t.size() && t[i] - t.front() <= kMaxCaptureDuration_s)
                ++i;
            out_of_bounds(row_lines_[i], "duration",
                          "expected a capture of at most " + number_text(kMaxCaptureDuration_s) +
                              " s (3 h) from the " + clock + ", got " + number_text(duration) +
                              " s (this row is " + number_text(t[i] - t.front()) +
                              " s after the first)");
        }
    }

    void convert_axes_and_units()
    {
        const double scale = unit_m();
        // z up -> y up: a -90 deg rotation about x maps (x, y, z) to (x, z, -y),
        // a proper rotation, so the frame stays right-handed.
        const bool z_up = options_.up == MarkerCsvOptions::Up::z;
        const Eigen::Quaterniond z_to_y(std::sqrt(0.5), -std::sqrt(0.5), 0.0, 0.0);
        for (MarkerTrack &track : capture_.tracks) {
            for (Eigen::Vector3d &p : track.position_m) {
                p *= scale;
                if (z_up)
                    p = Eigen::Vector3d(p.x(), p.z(), -p.y()); // = z_to_y * p, exactly
            }
            if (z_up)
                for (Eigen::Quaterniond &q : track.orientation)
                    q = (z_to_y * q).normalized();
        }
    }

    const std::vector<std::string> &lines_;
    const std::string &source_;
    const MarkerCsvOptions &options_;
    MocapWarnings *warnings_;
    MarkerCapture capture_;
    std::vector<ObjectColumns> objects_;
    std::vector<std::vector<bool>> missing_; // [object][frame]
    std::vector<int> row_lines_;             // [frame] -> file line
    std::size_t column_count_ = 0;
    bool trailing_empty_ = false; // the header's last cell is empty (a trailing comma)
    int header_line_ = 0;
    int time_column_ = -1;
    int frame_column_ = -1;
    BoundsReport bounds_{source_, options_.accept_out_of_bounds, warnings_};
};

} // namespace

MarkerCapture parse_marker_csv(std::istream &in, const std::string &source_name,
                               const MarkerCsvOptions &options, MocapWarnings *warnings)
{
    const std::vector<std::string> lines = detail::read_lines(in, source_name, kMaxFileBytes);
    CsvParser parser(lines, source_name, options, warnings);
    return parser.parse();
}

MarkerCapture read_marker_csv(const std::string &path, const MarkerCsvOptions &options,
                              MocapWarnings *warnings)
{
    std::ifstream in = detail::open_capture(path, "CSV");
    return parse_marker_csv(in, path, options, warnings);
}

} // namespace ictus
