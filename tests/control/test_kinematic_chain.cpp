// Forward kinematics and the tip Jacobian of ball-joint chains, against hand computation and
// finite differences.
#include <catch2/catch.hpp>

#include "arm_fixture.hpp"

#include <cmath>

using Eigen::Quaterniond;
using Eigen::Vector3d;

static const double kPi = std::acos(-1.0);

TEST_CASE("quaternion exp and log are inverse and match axis-angle", "[control]")
{
    const Quaterniond q = ictus::exp_map(Vector3d(0.0, 0.0, kPi / 2));
    // A quarter turn about z takes x to y.
    CHECK((q * Vector3d::UnitX() - Vector3d::UnitY()).norm() < 1e-15);
    std::mt19937 rng(1);
    for (int i = 0; i < 200; ++i) {
        const Quaterniond r = arm::random_rotation(rng, 3.1);
        const Vector3d v = ictus::log_map(r);
        const Eigen::AngleAxisd aa(r);
        CHECK(std::abs(v.norm() - aa.angle()) < 1e-12);
        CHECK(ictus::exp_map(v).angularDistance(r) < 1e-12);
    }
    // Tiny angles stay accurate (Taylor branch).
    const Vector3d tiny(1e-9, -2e-9, 3e-9);
    CHECK((ictus::log_map(ictus::exp_map(tiny)) - tiny).norm() < 1e-22);
    CHECK(ictus::rotation_angle_between(Quaterniond::Identity(), q) == Approx(kPi / 2));
}

TEST_CASE("chain capacity and bad joints are refused", "[control]")
{
    ictus::KinematicChain chain;
    CHECK(chain.add_joint(Vector3d(std::nan(""), 0, 0)) == -1);
    CHECK(chain.add_joint(Vector3d::Zero(), Quaterniond(0, 0, 0, 0)) == -1);
    for (int j = 0; j < ictus::KinematicChain::kMaxJoints; ++j)
        CHECK(chain.add_joint(Vector3d::UnitY()) == j);
    CHECK(chain.add_joint(Vector3d::UnitY()) == -1);
    CHECK(chain.joints() == ictus::KinematicChain::kMaxJoints);
}

TEST_CASE("forward kinematics of the arm matches hand computation", "[control]")
{
    ictus::KinematicChain chain = arm::make();
    CHECK(chain.reach_m() == Approx(0.15 + 0.29 + 0.27 + std::sqrt(0.08 * 0.08 + 0.4 * 0.4)));

    ictus::ChainFrames frames;
    chain.forward(&frames);
    // Rest pose: arm hanging from the shoulder at (0.15, 1.4, 0), stick forward (+z).
    CHECK((frames.joint_position_m[0] - Vector3d(0.0, 1.4, 0.0)).norm() < 1e-15);
    CHECK((frames.joint_position_m[1] - Vector3d(0.15, 1.4, 0.0)).norm() < 1e-15);
    CHECK((frames.joint_position_m[2] - Vector3d(0.15, 1.11, 0.0)).norm() < 1e-15);
    CHECK((frames.joint_position_m[3] - Vector3d(0.15, 0.84, 0.0)).norm() < 1e-15);
    CHECK((frames.tip_position_m - Vector3d(0.15, 0.76, 0.4)).norm() < 1e-15);
    CHECK((frames.stick_direction - Vector3d::UnitZ()).norm() < 1e-15);

    // Shoulder abducted 90 deg about +z (upper arm to +x), elbow flexed 90 deg about +x
    // (forearm -y -> -z in the upper arm's frame): worked out by hand.
    chain.set_rotation(1, Quaterniond(Eigen::AngleAxisd(kPi / 2, Vector3d::UnitZ())));
    chain.set_rotation(2, Quaterniond(Eigen::AngleAxisd(kPi / 2, Vector3d::UnitX())));
    chain.forward(&frames);
    CHECK((frames.joint_position_m[2] - Vector3d(0.44, 1.4, 0.0)).norm() < 1e-14);
    CHECK((frames.joint_position_m[3] - Vector3d(0.44, 1.4, -0.27)).norm() < 1e-14);
    CHECK((frames.tip_position_m - Vector3d(0.84, 1.4, -0.35)).norm() < 1e-14);
    CHECK((frames.stick_direction - Vector3d::UnitX()).norm() < 1e-14);
    CHECK((chain.tip_position() - frames.tip_position_m).norm() < 1e-15);

    // The base pose carries the whole chain rigidly.
    const Quaterniond turn(Eigen::AngleAxisd(0.7, Vector3d(0.3, 1.0, -0.2).normalized()));
    const Vector3d shift(0.3, -0.1, 2.0);
    const Vector3d tip_before = frames.tip_position_m;
    chain.set_base(shift + turn * arm::kBase, turn);
    CHECK((chain.tip_position() - (shift + turn * tip_before)).norm() < 1e-14);
}

TEST_CASE("tip Jacobian matches central finite differences", "[control]")
{
    std::mt19937 rng(7);
    ictus::KinematicChain chain = arm::make();
    chain.set_base(arm::kBase, Quaterniond(Eigen::AngleAxisd(0.4, Vector3d(1, 2, 3).normalized())));
    Eigen::Matrix<double, 3, 12> jacobian;
    for (int trial = 0; trial < 50; ++trial) {
        Quaterniond q[4];
        arm::random_pose(rng, q, 2.0);
        chain.set_rotations(q);
        ictus::ChainFrames frames;
        chain.forward(&frames);
        ictus::KinematicChain::tip_jacobian(frames, 4, jacobian);

        // Column (j, k): turn joint j by +-h about world axis k, i.e. its local rotation by
        // exp(R_parent^T h e_k), and difference the tip positions.
        const double h = 1e-6;
        for (int j = 0; j < 4; ++j) {
            const Quaterniond parent =
                j == 0 ? chain.base_rotation() : frames.joint_rotation[j - 1];
            for (int k = 0; k < 3; ++k) {
                const Vector3d local = parent.conjugate() * (h * Vector3d::Unit(k));
                ictus::KinematicChain plus = chain, minus = chain;
                plus.set_rotation(j, ictus::exp_map(local) * q[j]);
                minus.set_rotation(j, ictus::exp_map(-local) * q[j]);
                const Vector3d column = (plus.tip_position() - minus.tip_position()) / (2 * h);
                // Central differences: O(h^2 |p|) truncation plus O(eps/h) rounding.
                CHECK((column - jacobian.col(3 * j + k)).norm() < 1e-8);
            }
        }
    }
}
