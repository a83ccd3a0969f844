// kinematic_chain.hpp -- kinematic chains of ball joints (torso -> clavicle -> shoulder -> elbow
// -> wrist -> stick tip): forward kinematics and the geometric Jacobian of the tip that the
// Cartesian tracking mode inverts (paper eq. 2, Algorithm 2). Lengths in metres, rotations
// as unit quaternions, angular quantities in radians. Fixed capacity: nothing here allocates.
#pragma once

#include "ictus/base/rotation.hpp"
#include "ictus/character/joint_limit_ref.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>

namespace ictus
{

// World frames of a chain after forward kinematics: per joint its centre and orientation,
// then the tip (stick tip) position and the stick's unit direction.
struct ChainFrames {
    static constexpr int kMaxJoints = 8;
    std::array<Eigen::Vector3d, kMaxJoints> joint_position_m;
    std::array<Eigen::Quaterniond, kMaxJoints> joint_rotation;
    Eigen::Vector3d tip_position_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d stick_direction = Eigen::Vector3d::UnitX();
};

// A serial chain of up to kMaxJoints spherical (3-DoF) joints hanging from a base frame.
// Joint j sits at `offset_m` in the frame of joint j-1 (of the base for j = 0) and turns its
// child by `rotation` (local, relative to the parent). The tip (stick tip) sits at
// `tip_offset_m` in the last joint's frame; `stick_axis` is the stick's direction there.
// A chain holds only values and JointLimitRef pointers, so copying it is cheap and safe.
class KinematicChain
{
  public:
    static constexpr int kMaxJoints = ChainFrames::kMaxJoints;
    static constexpr int kMaxDofs = 3 * kMaxJoints;

    // Appends a joint; returns its index, or -1 when the chain is full or an input is not
    // finite (the rotation is normalised; a zero quaternion is refused).
    int add_joint(const Eigen::Vector3d &offset_m,
                  const Eigen::Quaterniond &rotation = Eigen::Quaterniond::Identity(),
                  JointLimitRef limit = JointLimitRef());
    int joints() const { return joint_count_; }
    int dofs() const { return 3 * joint_count_; }

    // World pose of the chain root (e.g. the simulated torso body).
    void set_base(const Eigen::Vector3d &position_m, const Eigen::Quaterniond &rotation);
    const Eigen::Vector3d &base_position() const { return base_position_m_; }
    const Eigen::Quaterniond &base_rotation() const { return base_rotation_; }

    // Stick tip in the last joint's frame; `stick_axis` (normalised here) defaults to the
    // direction of `tip_offset_m` when zero.
    void set_tip(const Eigen::Vector3d &tip_offset_m,
                 const Eigen::Vector3d &stick_axis = Eigen::Vector3d::Zero());
    const Eigen::Vector3d &tip_offset() const { return tip_offset_m_; }
    const Eigen::Vector3d &stick_axis() const { return stick_axis_; }

    const Eigen::Vector3d &offset(int joint) const { return offset_m_[joint]; }
    const Eigen::Quaterniond &rotation(int joint) const { return rotation_[joint]; }
    void set_rotation(int joint, const Eigen::Quaterniond &rotation)
    {
        rotation_[joint] = rotation;
    }
    // Copies joints() rotations (e.g. a solver's output, or the simulated state).
    void set_rotations(const Eigen::Quaterniond *rotations);
    const JointLimitRef &limit(int joint) const { return limit_[joint]; }
    void set_limit(int joint, JointLimitRef limit) { limit_[joint] = limit; }

    // Longest distance from joint 0's centre to the tip (all segments aligned).
    double reach_m() const;

    // Forward kinematics with the chain's own rotations, or with `rotations` (joints() of
    // them) in their place -- the solver iterates on its own copy without touching the chain.
    void forward(ChainFrames *frames) const;
    void forward(const Eigen::Quaterniond *rotations, ChainFrames *frames) const;
    Eigen::Vector3d tip_position() const;

    // Geometric Jacobian of the tip position with respect to the joints' angular velocities
    // expressed in the world frame (3 columns per ball joint): v_tip = sum_j w_j x (p_tip - p_j),
    // so block j is -[p_tip - p_j]_x. `jacobian` gets dofs() columns.
    template <class Derived>
    static void tip_jacobian(const ChainFrames &frames, int joints,
                             const Eigen::MatrixBase<Derived> &jacobian);

  private:
    int joint_count_ = 0;
    std::array<Eigen::Vector3d, kMaxJoints> offset_m_;
    std::array<Eigen::Quaterniond, kMaxJoints> rotation_;
    std::array<JointLimitRef, kMaxJoints> limit_;
    Eigen::Vector3d base_position_m_ = Eigen::Vector3d::Zero();
    Eigen::Quaterniond base_rotation_ = Eigen::Quaterniond::Identity();
    Eigen::Vector3d tip_offset_m_ = Eigen::Vector3d::Zero();
    Eigen::Vector3d stick_axis_ = Eigen::Vector3d::UnitX();
};

template <class Derived>
void KinematicChain::tip_jacobian(const ChainFrames &frames, int joints,
                                  const Eigen::MatrixBase<Derived> &jacobian_out)
{
    // Eigen's documented idiom for writing into an expression passed by const reference.
    Eigen::MatrixBase<Derived> &jacobian = const_cast<Eigen::MatrixBase<Derived> &>(jacobian_out);
    for (int j = 0; j < joints; ++j) {
        const Eigen::Vector3d r = frames.tip_position_m - frames.joint_position_m[j];
        // -[r]_x: column k is e_k x r.
        jacobian.template block<3, 3>(0, 3 * j) << 0.0, r.z(), -r.y(), -r.z(), 0.0, r.x(), r.y(),
            -r.x(), 0.0;
    }
}

} // namespace ictus
