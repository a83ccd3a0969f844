// stick_capture.hpp -- stick-only captures for the Cartesian mode: the two
// stick tips' trajectories (e.g. two rigid bodies or tip markers from an
// optical system), a default body to drive with them, the placement of the
// body behind the sticks and the drum under the strokes.
#pragma once

#include "ictus/character/character.hpp"
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
// when not empty (exact names), else the first object whose name, case-
// insensitively, is stick_l / stick_r, or else contains "left" / "right".
// Throws CharacterError naming the missing object and listing the names.
std::array<int, 2> find_stick_tracks(const MarkerCapture &capture, const std::string &left,
                                     const std::string &right);

// A body with the CMU joint names and round-number dimensions (1.75 m), for
// captures that have only the sticks.
Skeleton default_skeleton();

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

// The drum membrane fitted to the lowest points of the strokes: per stick, the
// local minima of tip height that lie within the lowest 25 % of that stick's
// height range are the strike points; the membrane centre (x, z) is the mean
// over the sticks of each stick's mean strike point (each stick counts once),
// its height the median strike height minus one tip radius.
// Throws CharacterError when there are no minima.
Eigen::Vector3d fit_drum_to_strokes(const TipTrajectory &tips, double tip_radius_m);

} // namespace ictus
