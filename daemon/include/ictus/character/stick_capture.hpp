// stick_capture.hpp -- stick-only captures for the Cartesian mode: the two
// stick tips' trajectories (e.g. two rigid bodies or tip markers from an
// optical system), the placement of the default body (default_skeleton.hpp)
// behind the sticks and the drum under the strokes.
#pragma once

#include "ictus/character/character.hpp"
#include "ictus/character/default_skeleton.hpp" // the body a stick-only capture drives
#include "ictus/mocap/motion.hpp"

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace ictus
{

// Stick-tip targets X^T over time (world, m), sampled linearly.
struct TipTrajectory {
    std::vector<double> time_s;                        // strictly increasing
    std::array<std::vector<Eigen::Vector3d>, 2> tip_m; // [side][frame]
    double duration_s() const { return time_s.empty() ? 0.0 : time_s.back() - time_s.front(); }
    // At time t from the first sample (clamped to the ends).
    Eigen::Vector3d sample(int side, double t) const;
};

// The tracked objects used as the left and right stick tips: `left`/`right`
// when not empty (the object of that exact name, else the one object of that
// name in another casing; several such are an error naming them), else the
// first object whose name, case-insensitively, is stick_l / stick_r, or else
// contains "left" / "right". Throws CharacterError naming the missing object
// and listing the names.
std::array<int, 2> find_stick_tracks(const MarkerCapture &capture, const std::string &left,
                                     const std::string &right);

// Moves the capture's tips into the character's frame (a rotation about the
// vertical and a translation; the motion itself is untouched): the capture's
// left-right axis (mean left tip minus mean right tip, horizontal) onto the
// character's, and the centre of the tips' bounding box to a point
// kStickForward_m in front of the midpoint of the shoulders and kStickBelow_m
// below it, where a seated drummer's sticks play.
constexpr double kStickForward_m = 0.40;
constexpr double kStickBelow_m = 0.35;
TipTrajectory place_behind_sticks(const CharacterModel &model, const CharacterPose &pose,
                                  const MarkerCapture &capture, const std::array<int, 2> &tracks);

// A stroke's turnaround: where a stick tip moving down turns back up (at the
// drum, its impact). Found per stick as a local minimum of the height whose
// descent from the highest point since the previous turnaround is at least
// `min_drop_m` and that came down at kMinStrokeSpeed_mps or faster; the vertex is refined between
// the samples (a capture at 250 Hz samples an 8 m/s impact every 32 mm): by the intersection of the
// incoming and outgoing lines (two samples each side: an impact's V) or by the parabola through the
// three lowest samples (a smooth turn), whichever predicts the remaining samples better
// (docs/mocap.md, "Drum placement").
constexpr double kMinStrokeSpeed_mps = 0.3;
struct StrokeTurnaround {
    double time_s = 0.0;                                  // from the first sample
    Eigen::Vector3d position_m = Eigen::Vector3d::Zero(); // the refined vertex
    double speed_in_mps = 0.0;                            // downward, before the turn
};
std::vector<StrokeTurnaround> find_turnarounds(const TipTrajectory &tips, int side,
                                               double min_drop_m = 0.01,
                                               double min_speed_mps = kMinStrokeSpeed_mps);

// The drum under the strokes' turnarounds (`--drum auto`): the turnarounds of
// both sticks pooled (when none came down at kMinStrokeSpeed_mps, any); the impacts are those at
// most kImpactBand_m above the lowest quartile of their heights (turnarounds in the air, higher,
// are not impacts); the membrane height is the median impact height minus one tip radius (the
// bead's centre is a radius above the membrane at contact), its centre (x, z) the mean over the
// sticks of each stick's mean impact point.
constexpr double kImpactBand_m = 0.02;
// The tracked point is the stick's end; its bead (radius r) touches the membrane
// with the end r (1 + d_y) above it, d the stick's unit direction (butt to tip):
// r for a horizontal stick, 0 for a vertical one. A stick-only capture does not
// say d, so the membrane goes r / 2 below the impacts (a stick 30 degrees below
// the horizontal): at most r / 2 (3.5 mm for the default bead) off at any pitch.
constexpr double kImpactPitchFactor = 0.5;
// How far below the membrane plane a stick-only capture's X^T asks the stick's
// end at an impact's vertex (`ictusd track`, docs/ik.md, "Stick-only captures"):
// the dent of a strike at `speed_mps` in a membrane of stiffness k, for the
// stick's mass m alone: v / omega = v sqrt(m / k) (2.9 mm per m/s for the
// default 50 g stick on the default snare, k = 5.8 kN/m).
// 0 for a non-finite or non-positive input.
double impact_press_depth_m(double speed_mps, double stick_mass_kg, double stiffness_n_per_m);
struct DrumFit {
    Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
    std::array<std::vector<StrokeTurnaround>, 2> impacts; // [side], in time order
};
// Throws CharacterError when no stick has a turnaround.
DrumFit fit_drum_to_turnarounds(const TipTrajectory &tips, double tip_radius_m);
// `tips` with each impact's refined vertex inserted as a sample (its stick at the
// vertex, the other stick interpolated there as before): linear interpolation
// between the capture's samples cuts an impact's V short (at 250 Hz, up to 16 mm
// at 8 m/s), so the stick would be asked to turn above the drum.
TipTrajectory with_impact_vertices(const TipTrajectory &tips,
                                   const std::array<std::vector<StrokeTurnaround>, 2> &impacts);
// The drum of `--drum auto` (stick-only and full-body captures alike;
// docs/mocap.md, "Drum placement"): the membrane at the strokes' turnarounds
// (fit_drum_to_turnarounds), unless the captured tips pass through that drum --
// more than kDrumThroughFraction of either stick's samples within the drum's
// radius of its axis and more than kDrumClearance_m below its membrane, as when
// a drum-kit capture's strokes for the other drums cross the place of the one
// simulated drum. Then the drum goes under the lowest tips, out of the
// strokes' way (`at_turnarounds` false). Throws CharacterError when no stick
// has a turnaround.
constexpr double kDrumThroughFraction = 0.01;
constexpr double kDrumClearance_m = kImpactBand_m;
struct DrumPlacement {
    Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
    bool at_turnarounds = true;
    // The larger of the two sticks' fractions of samples inside the drum at the turnarounds.
    double through_fraction = 0.0;
    DrumFit fit; // the turnarounds and impacts (the contact windows), in either case
};
DrumPlacement place_drum(const TipTrajectory &tips, double tip_radius_m, double drum_radius_m);
// The fraction of stick `side`'s samples inside a drum of radius `radius_m` whose
// membrane centre is `center_m`: within the radius of its vertical axis and more
// than `clearance_m` below the membrane.
double fraction_through_drum(const TipTrajectory &tips, int side, const Eigen::Vector3d &center_m,
                             double radius_m, double clearance_m = kDrumClearance_m);
// A drum under the lowest tips: (x, z) the mean of the two sticks' lowest
// points, the membrane kImpactPitchFactor tip radii below the lower of them.
Eigen::Vector3d drum_under_lowest_tips(const TipTrajectory &tips, double tip_radius_m);
// fit_drum_to_turnarounds(tips, tip_radius_m).center_m.
Eigen::Vector3d fit_drum_to_strokes(const TipTrajectory &tips, double tip_radius_m);

} // namespace ictus
