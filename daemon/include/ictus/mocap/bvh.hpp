// bvh.hpp -- Biovision Hierarchy (BVH) reader: skeleton + motion (motion.hpp).
//
// Accepts: any channel order per joint (Xposition..Zrotation in any order, 3 or
// 6 or any subset of the six, on any joint), any frame rate, CRLF/LF mixed line
// endings, End Site. Euler rotations are composed in the file's channel order,
// intrinsic (R = R_c1 * R_c2 * R_c3 for rotation channels listed c1 c2 c3),
// angles in degrees. Root world position = root OFFSET + position channels.
// World frame as in BVH: right-handed, y up. See docs/mocap.md.
#pragma once

#include "ictus/base/rotation.hpp" // axis_rotation, euler_angles: the BVH Euler composition
#include "ictus/mocap/mocap_error.hpp"
#include "ictus/mocap/motion.hpp"

#include <Eigen/Geometry>
#include <array>
#include <iosfwd>
#include <string>
#include <vector>

namespace ictus
{

// Metres per unit of the CMU Graphics Lab BVH files (cgspeed's conversion:
// (1/0.45) inch per unit), the default scale of every verb that reads BVH.
constexpr double kCmuBvhScale_m = 0.056444;

struct BvhOptions {
    // File length unit -> metres (the CMU files: kCmuBvhScale_m, often taken
    // as such, unverified; see the data README). Must be finite and > 0.
    double scale = 1.0;
    // Frames dropped from the start. The CMU/cgspeed files begin with a
    // converter's reference pose (frame 1), so use 1 for them. Default: keep all.
    int skip_frames = 0;
    // Refuse files that declare more frames than this (absurd sizes).
    long max_frames = 10000000;
    // The physical bounds of a capture (capture_bounds.hpp): Frame Time in
    // [kMinSampleInterval_s, kMaxSampleInterval_s], (Frames - 1) * Frame Time
    // <= kMaxCaptureDuration_s, every OFFSET coordinate and position channel
    // times `scale` within kMaxCoordinate_m. false: refused (MocapBoundError
    // at the value's line); true: read, with a warning (the first of each kind).
    bool accept_out_of_bounds = false;
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
// anything malformed, MocapBoundError on a value out of the physical bounds;
// appends warnings to *warnings when given. The skeleton keeps the file name
// and each OFFSET's line (Skeleton::source, SkeletonJoint::offset_line).
BvhFile read_bvh(const std::string &path, const BvhOptions &options = {},
                 MocapWarnings *warnings = nullptr);
// Same from a stream; `source_name` is used in messages.
BvhFile parse_bvh(std::istream &in, const std::string &source_name, const BvhOptions &options = {},
                  MocapWarnings *warnings = nullptr);

// Forward kinematics honouring non-root position channels (joint_translation_m).
std::vector<Eigen::Vector3d> bvh_forward_kinematics(const BvhFile &bvh, int frame);

const char *to_string(BvhChannel channel);

} // namespace ictus

// ---- BVH export (bvh_writer.cpp): the inverse of read_bvh ---------------------
namespace ictus
{

struct BvhWriteOptions {
    // File units per metre: 1 writes metres, 100 centimetres, 1 / 0.0254 inches.
    // Read the file back with BvhOptions::scale = 1 / units_per_m. Finite, > 0.
    double units_per_m = 1.0;
    // Rotation channels written on every joint (end sites have none), as axis
    // indices 0 = X, 1 = Y, 2 = Z, a permutation of {0, 1, 2}. The angles are
    // those that read_bvh composes back: q = R_o0(a0) * R_o1(a1) * R_o2(a2)
    // (intrinsic, file order). Default: Z Y X, the CMU order.
    std::array<int, 3> rotation_order{{2, 1, 0}};
    // Decimals of every number (9: 1e-9 degree, far below 1e-6 m of position).
    int decimals = 9;
};

// Writes HIERARCHY (OFFSETs, CHANNELS: "Xposition Yposition Zposition" + the
// rotation channels on the root, the rotation channels on every other joint,
// end sites as "End Site") and MOTION (Frames, Frame Time = 1 / frame_rate_hz,
// one line per frame). The root's position channels hold root_position_m minus
// the root's OFFSET, so that read_bvh gives root_position_m back. Joints are
// written depth first, children in index order: a skeleton read by read_bvh is
// written in its own order. Local rotations of end sites are not written (BVH
// has no channels there). Throws MocapError naming `source_name` and the frame
// or joint on bad input (size mismatch, non-finite value, rate <= 0, an end
// site with children, no root).
void write_bvh(std::ostream &out, const Skeleton &skeleton, const Motion &motion,
               const BvhWriteOptions &options = {}, const std::string &source_name = "<bvh>");
// Same into a file; throws MocapError naming the path when it cannot be written.
void write_bvh(const std::string &path, const Skeleton &skeleton, const Motion &motion,
               const BvhWriteOptions &options = {});

} // namespace ictus
