// joint_controller.hpp -- joint-space PD tracking (paper, eq. 1) for 3-DoF joints.
//
// Eq. 1 is tau = k_s (Theta^T - Theta^S) - k_d dTheta^S (the paper prints the
// difference the other way round; the restoring sign is meant). Here the
// rotation error is the rotation vector of q_T q_S^-1 (no Euler angles, no
// gimbal lock) and the damping acts on the velocity error, with the target's
// rate as feed-forward:
//     tau = k_s log(q_T q_S^-1) + k_d (w_T - w_S),   |tau_i| <= tau_max (per axis)
// It is not applied as an explicit torque (measured unstable at 1 ms here,
// ode-findings.md) but as an ODE angular-motor row, which the solver makes
// implicit in the velocity: a motor row with target velocity v and constraint
// force mixing CFM enforces w_next = v - CFM * tau, i.e. tau = (v - w_next)/CFM.
// With v = w_T + (k_s/k_d) e and CFM = 1/k_d this is exactly the law above,
// the damping evaluated at the end of the step (stable for any k_d) and the
// force bounded by dParamFMax = tau_max. See docs/character.md.
#pragma once

#include "ictus/character/character.hpp"
#include "ictus/control/control_error.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace ictus
{

struct JointGains {
    double kp_nm_per_rad = 0.0;   // k_s
    double kd_nm_s_per_rad = 0.0; // k_d
    double torque_limit_nm = 0.0; // per axis
};

struct GainOptions {
    // Gains scale with the inertia I carried by each joint: k_s = I w^2,
    // k_d = 2 zeta I w, with w = 2 pi natural_frequency_hz.
    double natural_frequency_hz = 30.0;
    double damping_ratio = 1.0;
    double torque_scale = 1.0; // multiplies every joint's torque limit
    bool rate_feedforward = true;
};

// gains = base with every kp scaled by scale[0] and every kd by scale[1]
// (the live /ictus/gains command).
void scale_gains(const std::vector<JointGains> &base, const double scale[2],
                 std::vector<JointGains> &gains);

// A human-sized torque limit for a joint of the character, N m per axis, for
// a body of the given mass (limits scale linearly with body mass from 70 kg).
// Throws ControlError for an unknown joint name.
double default_torque_limit_nm(const std::string &joint_name, double body_mass_kg);

// Per-joint gains: k_s, k_d from the subtree inertia at `pose` (sticks
// included) and the options; torque limits from default_torque_limit_nm.
// Throws ControlError on non-finite or non-positive options.
std::vector<JointGains> default_gains(const CharacterModel &model, const CharacterPose &pose,
                                      const GainOptions &options = {});

// Per-joint overrides, e.g. {"l_wrist": {"kp_nm_per_rad": 40, "torque_limit_nm": 20}}:
// any subset of kp_nm_per_rad, kd_nm_s_per_rad, torque_limit_nm per joint name.
// Throws ControlError naming `source`, the joint and the field on anything
// unknown, non-numeric, non-finite or not > 0.
void apply_gain_overrides(const CharacterModel &model, const nlohmann::json &overrides,
                          const std::string &source, std::vector<JointGains> &gains);
nlohmann::json gains_to_json(const CharacterModel &model, const std::vector<JointGains> &gains);

// The motor row of eq. 1 for one joint. Inputs are world orientations of the
// parent and child bodies, the target local rotation q_T and its rate w_T
// (parent frame, rad/s). Output: the relative angular velocity the motor
// enforces (world frame), its CFM and its force bound.
struct MotorCommand {
    Eigen::Vector3d velocity_world = Eigen::Vector3d::Zero();
    double cfm = 0.0;
    double fmax = 0.0;
    Eigen::Vector3d error_parent = Eigen::Vector3d::Zero(); // log(q_T q_S^-1), rad
};
MotorCommand pd_motor_command(const Eigen::Quaterniond &parent_world,
                              const Eigen::Quaterniond &child_world,
                              const Eigen::Quaterniond &target_local,
                              const Eigen::Vector3d &target_rate_parent, const JointGains &gains,
                              bool rate_feedforward = true);

} // namespace ictus
