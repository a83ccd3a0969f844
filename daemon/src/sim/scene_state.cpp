// Reading the ODE scene back: bodies and joints in the model's terms, the
// sticks' points, the fulcrum, effective mass, contact and support forces,
// motor torques and speeds. Building is in scene_build.cpp, stepping in
// scene_step.cpp.
#include "ictus/sim/scene.hpp"
#include "scene_ode.hpp"

#include <ode/ode.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>

namespace ictus
{

namespace
{
using ode::to_eigen;
using ode::to_eigen3;
} // namespace

void Scene::body_frames(BodyFrames &frames) const
{
    frames.origin_m.resize(CharacterModel::kBodies);
    frames.rotation.resize(CharacterModel::kBodies);
    for (int b = 0; b < CharacterModel::kBodies; ++b) {
        const Eigen::Quaterniond q = to_eigen(dBodyGetQuaternion(body_[b]));
        frames.rotation[b] = q;
        frames.origin_m[b] = to_eigen3(dBodyGetPosition(body_[b])) - q * com_local_[b];
    }
}

void Scene::local_rotations(std::vector<Eigen::Quaterniond> &local) const
{
    local.resize(CharacterModel::kJoints);
    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        const int child = j + 1;
        const int parent = model_.bodies()[child].parent;
        local[j] = to_eigen(dBodyGetQuaternion(body_[parent])).conjugate() *
                   to_eigen(dBodyGetQuaternion(body_[child]));
    }
}

dBodyID Scene::tip_body(Side side) const
{
    dBodyID stick = stick_body_[static_cast<int>(side)];
    return stick ? stick : body_[model_.hand_body(side)];
}

Eigen::Vector3d Scene::tip_body_com(Side side) const
{
    return stick_body_[static_cast<int>(side)] ? model_.stick(side).com_m
                                               : com_local_[model_.hand_body(side)];
}

namespace
{
// A point fixed in a body, given in the hand frame (`rel`: relative to the
// body's CoM), and its velocity.
Eigen::Vector3d point_of(dBodyID body, const Eigen::Vector3d &rel)
{
    dVector3 out;
    dBodyGetRelPointPos(body, rel.x(), rel.y(), rel.z(), out);
    return to_eigen3(out);
}
Eigen::Vector3d velocity_of(dBodyID body, const Eigen::Vector3d &rel)
{
    dVector3 out;
    dBodyGetRelPointVel(body, rel.x(), rel.y(), rel.z(), out);
    return to_eigen3(out);
}
} // namespace

Eigen::Vector3d Scene::tip_position(Side side) const
{
    return point_of(tip_body(side), model_.stick(side).tip_m - tip_body_com(side));
}

Eigen::Vector3d Scene::tip_velocity(Side side) const
{
    return velocity_of(tip_body(side), model_.stick(side).tip_m - tip_body_com(side));
}

// The bead's centre (the tip minus one bead radius along the stick), relative
// to the tip body's centre of mass, in its frame: what ODE's point queries take.
Eigen::Vector3d Scene::bead_rel_com(Side side) const
{
    const StickInHand &st = model_.stick(side);
    return st.tip_m - model_.options().stick.tip_radius_m * st.axis - tip_body_com(side);
}

Eigen::Vector3d Scene::bead_position(Side side) const
{
    return point_of(tip_body(side), bead_rel_com(side));
}

Eigen::Vector3d Scene::bead_velocity(Side side) const
{
    return velocity_of(tip_body(side), bead_rel_com(side));
}

Eigen::Vector3d Scene::held_tip_position(Side side) const
{
    const int hb = model_.hand_body(side);
    return point_of(body_[hb], model_.stick(side).tip_m - com_local_[hb]);
}

Eigen::Vector3d Scene::held_tip_velocity(Side side) const
{
    const int hb = model_.hand_body(side);
    return velocity_of(body_[hb], model_.stick(side).tip_m - com_local_[hb]);
}

Eigen::Vector3d Scene::held_bead_position(Side side) const
{
    const int hb = model_.hand_body(side);
    const StickInHand &st = model_.stick(side);
    return point_of(body_[hb],
                    st.tip_m - model_.options().stick.tip_radius_m * st.axis - com_local_[hb]);
}

double Scene::fulcrum_angle_rad(Side side) const
{
    dJointID f = fulcrum_[static_cast<int>(side)];
    return f ? dJointGetHingeAngle(f) : 0.0;
}

Eigen::Quaterniond Scene::stick_in_hand(Side side) const
{
    const Eigen::Quaterniond hand = to_eigen(dBodyGetQuaternion(body_[model_.hand_body(side)]));
    return (hand.conjugate() * to_eigen(dBodyGetQuaternion(tip_body(side)))).normalized();
}

Eigen::Vector3d Scene::fulcrum_axis(Side side) const
{
    const Eigen::Quaterniond q = to_eigen(dBodyGetQuaternion(body_[model_.hand_body(side)]));
    return q * model_.stick(side).fulcrum_axis;
}

Eigen::Vector3d Scene::stick_axis(Side side) const
{
    return to_eigen(dBodyGetQuaternion(tip_body(side))) * model_.stick(side).axis;
}

double Scene::fulcrum_rate_rad_s(Side side) const
{
    dJointID f = fulcrum_[static_cast<int>(side)];
    return f ? dJointGetHingeAngleRate(f) : 0.0;
}

namespace
{
// The inverse of the effective mass at a point p along n of a set of rigid
// bodies whose velocities are J u for the generalised velocities u:
// n^T G (J^T M J)^-1 G^T n, G the point's velocity row in u.
// Fixed sizes: it runs on run's physics thread, which does not allocate.
template <int Bodies, int Dofs>
double inverse_effective_mass(const Eigen::Matrix<double, Bodies, Dofs> &J,
                              const Eigen::Matrix<double, Bodies, Bodies> &M,
                              const Eigen::Matrix<double, 1, Dofs> &g)
{
    const Eigen::Matrix<double, Dofs, Dofs> Mu = J.transpose() * M * J;
    return g * Mu.ldlt().solve(g.transpose());
}

Eigen::Matrix3d skew(const Eigen::Vector3d &v)
{
    Eigen::Matrix3d m;
    m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
    return m;
}

// A body's world mass matrix (diag m, world inertia about its CoM).
void body_mass(dBodyID body, Eigen::Matrix<double, 6, 6> &out)
{
    dMass mass;
    dBodyGetMass(body, &mass);
    Eigen::Matrix3d local;
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k)
            local(i, k) = mass.I[i * 4 + k];
    const Eigen::Matrix3d r = to_eigen(dBodyGetQuaternion(body)).toRotationMatrix();
    out.setZero();
    out.topLeftCorner<3, 3>() = mass.mass * Eigen::Matrix3d::Identity();
    out.bottomRightCorner<3, 3>() = r * local * r.transpose();
}
} // namespace

double Scene::effective_mass_kg(Side side, const Eigen::Vector3d &normal_in, int drum) const
{
    const Eigen::Vector3d n = normal_in.normalized();
    const int s = static_cast<int>(side);
    dBodyID hand = body_[model_.hand_body(side)];
    const Eigen::Vector3d ch = to_eigen3(dBodyGetPosition(hand));
    const Eigen::Vector3d bead = bead_position(side);
    Eigen::Matrix<double, 6, 6> mh;
    body_mass(hand, mh);
    if (!stick_body_[s]) {
        // One body: 1/m + (r x n)^T I^-1 (r x n).
        // n . (v + w x r) = n . v + w . (r x n).
        Eigen::Matrix<double, 1, 6> g;
        g << n.transpose(), (bead - ch).cross(n).transpose();
        return 1.0 / inverse_effective_mass<6, 6>(Eigen::Matrix<double, 6, 6>::Identity(), mh, g);
    }
    dBodyID stick = stick_body_[s];
    const Eigen::Vector3d cs = to_eigen3(dBodyGetPosition(stick));
    dVector3 anchor, axis;
    dJointGetHingeAnchor(fulcrum_[s], anchor);
    dJointGetHingeAxis(fulcrum_[s], axis);
    const Eigen::Vector3d p = to_eigen3(anchor), a = to_eigen3(axis).normalized();
    Eigen::Matrix<double, 6, 6> ms;
    body_mass(stick, ms);
    Eigen::Matrix<double, 12, 12> M = Eigen::Matrix<double, 12, 12>::Zero();
    M.topLeftCorner<6, 6>() = mh;
    M.bottomRightCorner<6, 6>() = ms;
    // u = (v_h, w_h, theta'): the hand's twist and the fulcrum's rate.
    // Stick: w_s = w_h + a theta'; v_s = v_h + w_h x (c_s - c_h) + theta' a x (c_s - p).
    Eigen::Matrix<double, 12, 7> J = Eigen::Matrix<double, 12, 7>::Zero();
    J.block<3, 3>(0, 0).setIdentity();
    J.block<3, 3>(3, 3).setIdentity();
    J.block<3, 3>(6, 0).setIdentity();
    J.block<3, 3>(6, 3) = -skew(cs - ch);
    J.block<3, 1>(6, 6) = a.cross(cs - p);
    J.block<3, 3>(9, 3).setIdentity();
    J.block<3, 1>(9, 6) = a;
    // The bead moves with the stick: n . (v_s + w_s x (b - c_s)).
    Eigen::Matrix<double, 1, 6> gs;
    gs << n.transpose(), (bead - cs).cross(n).transpose();
    const Eigen::Matrix<double, 1, 7> g = gs * J.bottomRows<6>();
    const double m_pivot = 1.0 / inverse_effective_mass<12, 7>(J, M, g);
    // The stick welded to the hand: theta' = 0.
    const Eigen::Matrix<double, 12, 6> J_rigid = J.leftCols<6>();
    const Eigen::Matrix<double, 1, 6> g_rigid = g.head<6>();
    const double m_rigid = 1.0 / inverse_effective_mass<12, 6>(J_rigid, M, g_rigid);
    const double lever = a.cross(bead - p).norm();
    const double k_grip = options_.grip[s].stiffness_nm_per_rad / std::max(lever * lever, 1e-6);
    const double k_drum = drum_contact_stiffness_n_per_m(drum);
    const double w = k_grip / (k_grip + k_drum);
    return m_pivot + w * (m_rigid - m_pivot);
}

Eigen::Vector3d Scene::support_force_n() const
{
    if (pelvis_weld_)
        return to_eigen3(weld_feedback_.f1);
    // The pelvis at rest: support + weight + its joints' forces on it = 0.
    Eigen::Vector3d f(0.0, options_.gravity_mps2 * pelvis_mass_kg_, 0.0);
    for (int j = 0; j < CharacterModel::kJoints; ++j)
        if (model_.bodies()[j + 1].parent == 0 && !kinematic_body_[j + 1])
            f -= to_eigen3(ball_feedback_[j].f2);
    return f;
}

Eigen::Vector3d Scene::motor_torque(int joint) const
{
    return to_eigen3(feedback_.at(joint).t1);
}

bool Scene::motor_saturated(int joint) const
{
    const Eigen::Vector3d t = motor_torque(joint);
    const double limit = gains_[joint].torque_limit_nm;
    for (int i = 0; i < 3; ++i)
        if (std::fabs(t.dot(motor_axes_[joint][i])) >= 0.999 * limit)
            return true;
    return false;
}

// One square root for the largest: sqrt is monotone and correctly rounded, so
// sqrt(max |v|^2) is max sqrt(|v|^2) = max |v| (Eigen's norm()) bit for bit.
double Scene::max_linear_speed_mps() const
{
    double m2 = 0.0;
    for (dBodyID b : body_)
        m2 = std::max(m2, to_eigen3(dBodyGetLinearVel(b)).squaredNorm());
    return std::sqrt(m2);
}

double Scene::max_angular_speed_rad_s() const
{
    double m2 = 0.0;
    for (dBodyID b : body_)
        m2 = std::max(m2, to_eigen3(dBodyGetAngularVel(b)).squaredNorm());
    return std::sqrt(m2);
}

} // namespace ictus
