// Resampling from capture rate to physics rate against analytic motions.
#include "mocap_test_util.hpp"

#include "ictus/base/rotation.hpp"
#include "ictus/mocap/joint_limits.hpp"
#include "ictus/mocap/motion.hpp"

using namespace ictus;
using namespace mocap_test;

TEST_CASE("Resample: constant angular velocity 120 Hz -> 1000 Hz", "[mocap][resample]")
{
    // Joint turning at 3 rad/s about a fixed axis: slerp between samples is
    // exact. Root moving at constant velocity: linear interpolation is exact.
    // Root accelerating (second joint unused): lerp error at most a h^2 / 8.
    const Eigen::Vector3d axis = Eigen::Vector3d(1, -2, 2).normalized(); // |axis| = 1
    const double omega = 3.0;                                            // rad/s
    const Eigen::Vector3d velocity(0.5, -0.25, 1.0);                     // m/s
    Motion motion;
    motion.frame_rate_hz = 120;
    for (int i = 0; i <= 120; ++i) {
        const double t = i / 120.0;
        motion.root_position_m.push_back(velocity * t);
        const double half = 0.5 * omega * t;
        const Eigen::Vector3d s = axis * std::sin(half);
        motion.local_rotation.push_back({Eigen::Quaterniond(std::cos(half), s.x(), s.y(), s.z()),
                                         Eigen::Quaterniond::Identity()});
    }
    const Motion fine = resample(motion, 1000);
    CHECK(fine.frame_rate_hz == 1000);
    REQUIRE(fine.frames() == 1001); // 1 s, both ends included
    double worst_angle = 0, worst_position = 0;
    for (int n = 0; n < fine.frames(); ++n) {
        const double t = n / 1000.0;
        const Eigen::Matrix3d want = Eigen::AngleAxisd(omega * t, axis).toRotationMatrix();
        worst_angle = std::max(
            worst_angle,
            (fine.local_rotation[static_cast<std::size_t>(n)][0].toRotationMatrix() - want).norm());
        worst_position =
            std::max(worst_position,
                     (fine.root_position_m[static_cast<std::size_t>(n)] - velocity * t).norm());
    }
    CHECK(worst_angle < 1e-12);
    CHECK(worst_position < 1e-12);

    // Quadratic motion: the error of linear interpolation is bounded by a h^2 / 8.
    const double accel = 2.0;
    Motion falling;
    falling.frame_rate_hz = 120;
    for (int i = 0; i <= 60; ++i) {
        const double t = i / 120.0;
        falling.root_position_m.emplace_back(0, 0.5 * accel * t * t, 0);
        falling.local_rotation.push_back({Eigen::Quaterniond::Identity()});
    }
    const Motion falling_fine = resample(falling, 1000);
    const double h = 1.0 / 120.0, bound = accel * h * h / 8.0;
    double worst = 0;
    for (int n = 0; n < falling_fine.frames(); ++n) {
        const double t = n / 1000.0;
        worst = std::max(worst,
                         std::fabs(falling_fine.root_position_m[static_cast<std::size_t>(n)].y() -
                                   0.5 * accel * t * t));
    }
    CHECK(worst <= bound * (1 + 1e-9));
    CHECK(worst > 0.9 * bound); // reached near segment midpoints

    CHECK_THROWS_AS(resample(motion, 0.0), MocapError);
    CHECK_THROWS_AS(resample(motion, std::nan("")), MocapError);
    Motion no_rate = motion;
    no_rate.frame_rate_hz = 0;
    CHECK_THROWS_AS(resample(no_rate, 1000), MocapError);
}

TEST_CASE("Resample: marker tracks on an irregular clock", "[mocap][resample]")
{
    // Samples at irregular times of a marker moving linearly and turning at a
    // constant rate about y; the uniform 1 kHz grid starts at the first sample.
    const double start = 0.25, omega = -2.0;
    const Eigen::Vector3d velocity(1.0, 0.0, -0.5), origin(0.1, 1.2, 0.3);
    MarkerCapture capture;
    MarkerTrack track;
    track.name = "stick";
    const double offsets[] = {0.0, 0.003, 0.009, 0.010, 0.0175, 0.024, 0.030};
    for (double dt : offsets) {
        capture.time_s.push_back(start + dt);
        track.position_m.push_back(origin + velocity * dt);
        track.orientation.push_back(exp_map(Eigen::Vector3d(0, omega * dt, 0)));
    }
    capture.tracks.push_back(track);
    const MarkerCapture fine = resample(capture, 1000);
    REQUIRE(fine.time_s.size() == 31);
    CHECK(fine.time_s.front() == start);
    const MarkerTrack &out = fine.tracks[0];
    CHECK(out.name == "stick");
    for (std::size_t n = 0; n < fine.time_s.size(); ++n) {
        const double dt = n / 1000.0;
        CHECK(fine.time_s[n] == Approx(start + dt).margin(1e-12));
        CHECK((out.position_m[n] - (origin + velocity * dt)).norm() < 1e-12);
        CHECK((out.orientation[n].toRotationMatrix() - rot_y(omega * dt)).norm() < 1e-12);
    }
    MarkerCapture backwards = capture;
    std::swap(backwards.time_s[1], backwards.time_s[2]);
    CHECK_THROWS_AS(resample(backwards, 1000), MocapError);
}
