// capture_bounds.hpp -- the physical bounds of a capture of a human performer.
//
// The file formats allow any number; a capture does not. A value outside these
// bounds is almost always a unit or export mistake (a time column in ms, a
// Frame Time field holding the rate, millimetres read as metres) that would
// otherwise become an hours-long run or a drum kilometres away. The readers
// refuse such values with MocapBoundError at the offending line, or, when the
// caller accepts them (BvhOptions / MarkerCsvOptions::accept_out_of_bounds,
// `--force` on the command line), read them with a warning. docs/mocap.md.
#pragma once

namespace ictus
{

// Sampling interval (BVH Frame Time, a CSV's median time step), s: 2 kHz to
// 2 Hz. Optical systems record at up to 2 kHz at full resolution; slower than
// 2 frames a second cannot show a drum stroke (0.1 to 0.5 s long). The upper
// bound also catches a time column in ms (steps >= 0.5 "s" below 2 kHz) or us.
constexpr double kMinSampleInterval_s = 1.0 / 2000.0;
constexpr double kMaxSampleInterval_s = 0.5;

// Length of one capture (last time - first time), s: 3 hours, longer than
// any take of one performance (a concert) and far shorter than a ms clock
// read as seconds (a 3-minute take in ms "lasts" 50 hours).
constexpr double kMaxCaptureDuration_s = 3.0 * 3600.0;

// |coordinate| of a position (BVH OFFSET and position channels times the
// scale, a CSV's NAME.x|y|z in its units), m: the drum may stand at most
// 100 m from the origin (`--drum-pos`), and capture volumes are tens of
// metres at most; 1e9 mm read as metres would be 1e6 km.
constexpr double kMaxCoordinate_m = 100.0;

} // namespace ictus
