// marker_csv.hpp -- CSV of tracked objects (optical rigid bodies / markers).
//
// Header row: a `time` column (s) or a `frame` column (then options.rate_hz is
// required), and per object NAME.x NAME.y NAME.z, optionally NAME.qw NAME.qx
// NAME.qy NAME.qz. Comma separated; empty cells, NaN or nan mark gaps. A
// comma ending the header and every row (an empty last column) is ignored.
// Output: MarkerCapture in metres, right-handed, y up. Values out of the
// physical bounds of a capture (capture_bounds.hpp) throw MocapBoundError
// unless accepted. See docs/mocap.md.
#pragma once

#include "ictus/mocap/mocap_error.hpp"
#include "ictus/mocap/motion.hpp"

#include <iosfwd>
#include <string>

namespace ictus
{

struct MarkerCsvOptions {
    // Frame rate for files with a `frame` column (ignored with `time`).
    double rate_hz = 0.0;
    enum class Units { mm, m };
    Units units = Units::m; // the file's length unit
    enum class Up { y, z };
    // The file's up axis. z-up (x, y, z) becomes y-up (x, z, -y): a rotation of
    // -90 deg about x, so handedness is kept. Orientations are pre-multiplied by
    // the same rotation (body-local coordinates unchanged).
    Up up = Up::y;
    // Fill interior gaps of at most max_gap_frames frames (positions linearly,
    // orientations by slerp) with a warning; longer gaps, or gaps touching the
    // first or last frame, are errors. With interpolate_gaps = false any gap is
    // an error.
    bool interpolate_gaps = true;
    int max_gap_frames = 20;
    // Refuse files with more data rows than this.
    long max_frames = 10000000;
    // The physical bounds of a capture (capture_bounds.hpp): the median time
    // step in [kMinSampleInterval_s, kMaxSampleInterval_s] (a time column in
    // ms or us fails it), last - first time <= kMaxCaptureDuration_s, every
    // NAME.x|y|z within kMaxCoordinate_m (in m after `units`). false: refused
    // (MocapBoundError at the row of the offending value); true: read, with a
    // warning (the first of each kind). Checked after the gaps.
    bool accept_out_of_bounds = false;
};

MarkerCapture read_marker_csv(const std::string &path, const MarkerCsvOptions &options = {},
                              MocapWarnings *warnings = nullptr);
MarkerCapture parse_marker_csv(std::istream &in, const std::string &source_name,
                               const MarkerCsvOptions &options = {},
                               MocapWarnings *warnings = nullptr);

} // namespace ictus
