// bvh.hpp -- Biovision Hierarchy (BVH) reader: skeleton + motion (motion.hpp).
//
// Accepts: any channel order per joint (Xposition..Zrotation in any order, 3 or
// 6 or any subset of the six, on any joint), any frame rate, CRLF/LF mixed line
// endings, End Site. Euler rotations are composed in the file's channel order,
// intrinsic (R = R_c1 * R_c2 * R_c3 for rotation channels listed c1 c2 c3),
// angles in degrees. Root world position = root OFFSET + position channels.
// World frame as in BVH: right-handed, y up. See docs/mocap.md.
#pragma once

#include "ictus/mocap_error.hpp"
#include "ictus/motion.hpp"

#include <Eigen/Geometry>
#include <iosfwd>
#include <string>
#include <vector>

namespace ictus
{

struct BvhOptions {
    // File length unit -> metres (the CMU files: often taken as 0.056444,
    // unverified; see the data README). Must be finite and > 0.
    double scale = 1.0;
    // Frames dropped from the start. The CMU/cgspeed files begin with a
    // converter's reference pose (frame 1), so use 1 for them. Default: keep all.
    int skip_frames = 0;
    // Refuse files that declare more frames than this (absurd sizes).
    long max_frames = 10000000;
};

// One BVH channel, in file order.
enum class BvhChannel { Xposition, Yposition, Zposition, Xrotation, Yrotation, Zrotation };

struct BvhFile {
    Skeleton skeleton;
    Motion motion; // frame_rate_hz = 1 / Frame Time
    // Channels of every joint (index as skeleton.joints), file order; empty for
    // end sites and channel-less joints.
    std::vector<std::vector<BvhChannel>> channels;
    // Only when some non-root joint has position channels: [frame][joint]
    // translation replacing that joint's OFFSET (m); empty otherwise.
    // forward_kinematics(Skeleton, Motion) ignores it; use bvh_forward_kinematics.
    std::vector<std::vector<Eigen::Vector3d>> joint_translation_m;
    double frame_time_s = 0.0;
    int channel_count = 0;         // total channels per motion line
    int channelled_joints() const; // joints with at least one channel
};

// Reads a BVH file. Throws MocapError (file, line, what was expected) on
// anything malformed; appends warnings to *warnings when given.
BvhFile read_bvh(const std::string &path, const BvhOptions &options = {},
                 MocapWarnings *warnings = nullptr);
// Same from a stream; `source_name` is used in messages.
BvhFile parse_bvh(std::istream &in, const std::string &source_name, const BvhOptions &options = {},
                  MocapWarnings *warnings = nullptr);

// Forward kinematics honouring non-root position channels (joint_translation_m).
std::vector<Eigen::Vector3d> bvh_forward_kinematics(const BvhFile &bvh, int frame);

// Rotation about x, y or z by angle_rad (right-handed); the building block of
// the BVH Euler composition.
Eigen::Quaterniond axis_rotation(int axis, double angle_rad);

const char *to_string(BvhChannel channel);

} // namespace ictus
