// character.hpp -- the virtual percussionist as a kinematic and inertial model:
// 20 rigid bodies (pelvis + 19) joined by 19 three-DoF joints (57 DoF), segment
// lengths from a mocap skeleton, masses and inertia from de Leva (1996), two
// drumsticks held in the hands with a French or German grip. No ODE here: the
// Scene (scene.hpp) builds the physical character from this model, and the
// Cartesian mode can run forward kinematics on it. See docs/character.md.
#pragma once

#include "ictus/mocap/motion.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictus
{

// Any problem building the character or its reference motion (missing joint,
// bad option value). what() names the thing and the value.
class CharacterError : public std::runtime_error
{
  public:
    using std::runtime_error::runtime_error;
};

// French: thumbs up, palms facing; German: palms down (paper, "Results").
enum class Grip { french, german };
const char *to_string(Grip grip);
Grip grip_from_string(const std::string &text); // throws CharacterError

// A snare drumstick. Defaults: a 5A stick (16 in, ~50 g, 14.5 mm shaft).
struct StickParams {
    double length_m = 0.406;
    double mass_kg = 0.050;
    double tip_radius_m = 0.007;     // the bead at the far end
    double shaft_radius_m = 0.00725; // 14.5 mm diameter
    double grip_from_butt_m = 0.13;  // fulcrum: about a third of the length
    // Angle between the stick and the finger axis, towards the thumb (German)
    // or towards the palm normal (French): the stick leaves the fist between
    // thumb and index finger, pointing inwards.
    double grip_angle_rad = 0.5236; // 30 degrees
};

struct CharacterOptions {
    double body_mass_kg = 70.0;
    StickParams stick;
    Grip grip = Grip::french; // the paper's recorded gestures used the French grip
};

// The segments a body is built from, against the bounds of a human body
// (docs/character.md), m. Limbs (upper arm, forearm, thigh, shank), whose
// inertia m (r L)^2 scales with their captured length L, are at least
// kMinLimbLength_m long: shorter than any human limb (a newborn's forearm is
// about 7 cm), and at L = 0 the body is a point mass that ODE refuses by
// aborting the process. No segment, and no joint's distance from its parent
// joint, is longer than kMaxSegmentLength_m: the longest human segment, the
// shank (0.43 m at de Leva's 1.74 m), is under 0.7 m even at 2.7 m stature.
// The other bodies (pelvis, trunk, neck, head, hand, foot) may be 0 long:
// their inertia comes from de Leva's lengths (the neck's and clavicles' from
// at least 2 cm), as for the CMU pelvis (Hips to LowerBack: OFFSET 0), and
// joints that carry no body (Spine1, LHipJoint, fingers, end sites) may be 0.
constexpr double kMinLimbLength_m = 0.05;
constexpr double kMaxSegmentLength_m = 1.0;

enum class Side { left = 0, right = 1 };

// One rigid body and the joint that attaches it to its parent.
struct BodySpec {
    std::string name;       // body: "thorax", "l_forearm"
    std::string joint_name; // joint to the parent: "thorax", "l_elbow"; "" for the pelvis
    std::string source;     // the mocap joint whose frame this body's frame is
    // Mocap joints (indices in the source skeleton) whose local rotations are
    // composed, parent-most first, into this joint's local rotation.
    std::vector<int> source_path;
    int parent = -1;                                         // body index, -1 for the pelvis
    Eigen::Vector3d offset_m = Eigen::Vector3d::Zero();      // joint centre in the parent frame
    Eigen::Vector3d distal_m = Eigen::Vector3d::Zero();      // distal end in this frame (rest)
    double length_m = 0.0;                                   // |distal_m|, from the mocap
    double mass_kg = 0.0;                                    // segment only (no stick)
    Eigen::Vector3d com_m = Eigen::Vector3d::Zero();         // in this body's frame
    Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero(); // about com_m, body frame
};

// Stick pose in its hand's body frame; the stick's axis points from the butt to the tip.
struct StickInHand {
    Eigen::Vector3d grip_m = Eigen::Vector3d::Zero(); // fulcrum point
    Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  // unit, butt -> tip
    // The fulcrum's hinge axis (unit, normal to the stick): the stick rocks
    // in the plane the hand strikes in. German grip (palm down): across the
    // palm (thumb to little finger); French (thumb up): along the palm
    // normal, the stick rocking between thumb and index finger
    // (docs/character.md, "The fulcrum").
    Eigen::Vector3d fulcrum_axis = Eigen::Vector3d::UnitZ();
    Eigen::Vector3d butt_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d tip_m = Eigen::Vector3d::Zero(); // the stick's end point
    Eigen::Vector3d com_m = Eigen::Vector3d::Zero();
    Eigen::Matrix3d inertia_kg_m2 = Eigen::Matrix3d::Zero(); // about com_m, hand frame
};

// A configuration of the character: pelvis in the world, local rotation of each
// of the 19 joints relative to its parent body (joint j moves body j + 1).
struct CharacterPose {
    Eigen::Vector3d pelvis_position_m = Eigen::Vector3d::Zero();
    Eigen::Quaterniond pelvis_rotation = Eigen::Quaterniond::Identity();
    std::vector<Eigen::Quaterniond> local; // [joint]
};

// World frames of all bodies: joint centre (body frame origin) and orientation.
struct BodyFrames {
    std::vector<Eigen::Vector3d> origin_m;    // [body]
    std::vector<Eigen::Quaterniond> rotation; // [body]
};

class CharacterModel
{
  public:
    static constexpr int kJoints = 19;
    static constexpr int kBodies = kJoints + 1;

    // Builds the character from a CMU-style skeleton (joint names as in the CMU
    // BVH files, see docs/character.md for the mapping). Throws CharacterError
    // naming a missing joint, a bad option, or a segment out of the bounds
    // above ("FILE:LINE: joint 'LeftHand': expected ..." at its OFFSET when
    // the skeleton was read from a file); every body it builds has a mass > 0
    // and a positive-definite inertia (checked: never a degenerate ODE body).
    static CharacterModel from_skeleton(const Skeleton &skeleton,
                                        const CharacterOptions &options = {});

    const std::vector<BodySpec> &bodies() const { return bodies_; }
    const BodySpec &joint_body(int joint) const { return bodies_[joint + 1]; }
    const std::string &joint_name(int joint) const { return bodies_[joint + 1].joint_name; }
    int body_index(const std::string &body_name) const;   // -1 when absent
    int joint_index(const std::string &joint_name) const; // -1 when absent
    int hand_body(Side side) const { return hand_body_[static_cast<int>(side)]; }
    const StickInHand &stick(Side side) const { return stick_[static_cast<int>(side)]; }
    const CharacterOptions &options() const { return options_; }
    double total_mass_kg() const;

    // The character's pose at one frame of a motion of the source skeleton.
    CharacterPose pose_from_motion(const Motion &motion, int frame) const;
    // The rest pose (all local rotations identity) at the given pelvis frame.
    CharacterPose rest_pose() const;

    // Forward kinematics of the character (not of the source skeleton: joints
    // merged into others move with them, see docs/character.md).
    void forward(const CharacterPose &pose, BodyFrames &frames) const;
    // World position of a stick's end point in a given pose of its hand.
    Eigen::Vector3d tip_position(Side side, const Eigen::Vector3d &hand_origin_m,
                                 const Eigen::Quaterniond &hand_rotation) const;

    // Inertia of everything carried by a joint (its subtree, sticks included)
    // about the joint centre, at the given pose: the scalar mean of the
    // diagonal, kg m^2, and the subtree's mass. Used to scale PD gains.
    struct SubtreeInertia {
        double inertia_kg_m2;
        double mass_kg;
    };
    SubtreeInertia subtree_inertia(int joint, const CharacterPose &pose) const;

    // Mass and inertia of a body with its stick merged in (hands), as used by
    // the physics: centre of mass in the body frame, inertia about it.
    void merged_mass(int body, double &mass_kg, Eigen::Vector3d &com_m,
                     Eigen::Matrix3d &inertia_kg_m2) const;

  private:
    std::vector<BodySpec> bodies_;
    std::array<int, 2> hand_body_{{-1, -1}};
    std::array<StickInHand, 2> stick_;
    CharacterOptions options_;
};

// The reference (target) motion in the character's joint space: per frame the
// 19 local rotations, pelvis held at the first frame's pose. Sampled at any
// time by slerp; past the end the motion plays backwards and forwards again
// (ping-pong), so that long runs have no jump at the seam.
// Clean-up of captured rotations before they become PD targets. Captured
// joint angles carry one-frame spikes and jitter that no human (and no
// torque-limited PD) follows: differentiated twice at 120 Hz they ask for
// thousands of rad/s^2 (docs/character.md).
struct ReferenceFilter {
    // A frame further than this from the midpoint of its two neighbours,
    // while the neighbours are closer than it to each other, is replaced by
    // that midpoint (one-frame spikes). 0 disables.
    double spike_threshold_rad = 5.0 * EIGEN_PI / 180.0; // 5 degrees
    // 0: the threshold holds at any frame rate. > 0 (track_reference_filter:
    // 120 Hz): it holds at this rate and above and grows as (this rate / the
    // motion's rate)^2 below: a real turn of angular acceleration a lies
    // a h^2 / 2 off its neighbours' midpoint (h the frame interval), so a
    // stroke's turn 3 degrees off at 120 Hz is 48 degrees off at 30 Hz, and a
    // fixed 5 degrees takes every stroke's turn of a 30 Hz capture for a spike.
    double spike_reference_rate_hz = 0.0;
    // Zero-phase low-pass smoothing in each frame's tangent space. 0 disables.
    double smooth_cutoff_hz = 10.0;
    // Its kernel. gaussian: sigma = 1 / (2 pi cutoff), response
    // exp(-f^2 / (2 cutoff^2)) (0.61 at the cutoff, but already 0.92 at 4 Hz: it
    // takes 8 % of a drummer's 4 Hz strokes). butterworth: the zero-phase
    // response of a 2nd-order Butterworth low-pass run forward and backward,
    // 1 / (1 + (f / cutoff)^4) (0.5 at the cutoff, 0.97 at 0.4 cutoff: the
    // biomechanics standard, Winter 2009, sect. 3.4.4), as a symmetric FIR
    // kernel (the inverse Fourier transform of that response, truncated where
    // its taps fall below 1e-3 of the centre tap).
    enum class Kernel { gaussian, butterworth };
    Kernel kernel = Kernel::gaussian;
};
// "gaussian" / "butterworth"; throws CharacterError naming the text otherwise.
ReferenceFilter::Kernel reference_kernel_from_string(const std::string &text);
const char *to_string(ReferenceFilter::Kernel kernel);
// The kernel's taps w[0..half] (w[-k] = w[k]), summing to 1 over -half..half.
std::vector<double> reference_kernel_taps(ReferenceFilter::Kernel kernel, double cutoff_hz,
                                          double frame_rate_hz);

class ReferenceMotion
{
  public:
    // Without a filter: the motion's rotations as they are.
    ReferenceMotion(const CharacterModel &model, const Motion &motion);
    ReferenceMotion(const CharacterModel &model, const Motion &motion,
                    const ReferenceFilter &filter);
    // Number of one-frame spikes replaced by the filter.
    int spikes_removed() const { return spikes_removed_; }
    double frame_rate_hz() const { return frame_rate_hz_; }
    int frames() const { return static_cast<int>(frames_.size()); }
    double duration_s() const;
    const CharacterPose &frame(int f) const { return frames_[f]; }
    // Pose at time t (s); local rotations only are interpolated.
    void sample(double time_s, CharacterPose &pose) const;

  private:
    // What Eigen's slerp computes from the two ends alone, per frame and
    // joint (the angle's acos and sine), so that sample() takes two sines per
    // joint instead of three and an acos; the same arithmetic, bit for bit.
    struct SlerpSpan {
        double theta = 0.0, sin_theta = 1.0;
        bool linear = true, negative = false;
    };
    void prepare_spans();
    double frame_rate_hz_ = 0.0;
    std::vector<CharacterPose> frames_;
    std::vector<SlerpSpan> spans_; // [frame * kJoints + joint], frames - 1 of them
    int spikes_removed_ = 0;
};

} // namespace ictus
