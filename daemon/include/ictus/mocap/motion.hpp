// motion.hpp -- motion capture in memory: a skeleton and its motion, or marker tracks.
// Readers (bvh.hpp, marker_csv.hpp) fill these; the character and the joint-limit
// learners read them. All lengths in metres, angles as unit quaternions, time in s.
#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace ictus
{

// One joint of a mocap skeleton. The root has parent == -1. `offset_m` is the
// joint's position in its parent's frame at the rest pose (BVH OFFSET, scaled).
// End sites are kept as joints with no channels and `end_site == true`.
struct SkeletonJoint {
    std::string name;
    int parent = -1;
    Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();
    bool end_site = false;
    // Line of the joint's OFFSET in `Skeleton::source` (1-based), 0 when the
    // skeleton was not read from a file: errors about a segment point there.
    int offset_line = 0;
};

struct Skeleton {
    std::vector<SkeletonJoint> joints;
    // The file the skeleton was read from ("" when built in code).
    std::string source;
    // Index of a joint by exact name, or -1.
    int find(const std::string &name) const;
};

// Motion of a skeleton: per frame, the root's position (world, m) and every
// joint's local rotation relative to its parent (identity for end sites).
// World frame: right-handed, y up (readers convert other conventions).
struct Motion {
    double frame_rate_hz = 0.0;
    std::vector<Eigen::Vector3d> root_position_m;                // [frame]
    std::vector<std::vector<Eigen::Quaterniond>> local_rotation; // [frame][joint]
    int frames() const { return static_cast<int>(root_position_m.size()); }
};

// World positions of every joint at one frame (forward kinematics).
std::vector<Eigen::Vector3d> forward_kinematics(const Skeleton &skeleton, const Motion &motion,
                                                int frame);
// World orientations of every joint at one frame.
std::vector<Eigen::Quaterniond> world_rotations(const Skeleton &skeleton, const Motion &motion,
                                                int frame);

// Tracked objects from an optical system (CSV): per object a position and,
// optionally, an orientation, per frame. NaN marks a missing sample before
// gap filling.
struct MarkerTrack {
    std::string name;
    std::vector<Eigen::Vector3d> position_m;     // [frame]
    std::vector<Eigen::Quaterniond> orientation; // [frame] or empty
};

struct MarkerCapture {
    std::vector<double> time_s; // [frame], strictly increasing
    std::vector<MarkerTrack> tracks;
    int find(const std::string &name) const;
};

// Resamples a motion to a new rate (positions linearly, rotations by slerp).
Motion resample(const Motion &motion, double rate_hz);
// Resamples marker tracks onto a uniform grid at rate_hz from time_s.front().
MarkerCapture resample(const MarkerCapture &capture, double rate_hz);

} // namespace ictus
