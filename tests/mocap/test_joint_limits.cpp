// Joint limits, the paper's two formulations: Euler statistics on synthetic
// angles with known ranges, and Algorithm 1 recovering known axes and spreads.
#include "mocap_test_util.hpp"

#include "ictus/base/rotation.hpp"
#include "ictus/mocap/bvh.hpp"
#include "ictus/mocap/joint_limits.hpp"

#include <random>
#include <sstream>

using namespace ictus;
using namespace mocap_test;

namespace
{

double angle_between(const Eigen::Quaterniond &a, const Eigen::Quaterniond &b)
{
    // atan2 form: acos(|a.b|) loses half the digits near 0.
    const Eigen::Quaterniond d = a.normalized().conjugate() * b.normalized();
    return 2.0 * std::atan2(d.vec().norm(), std::fabs(d.w()));
}

// A uniformly distributed random rotation (Shoemake's method).
Eigen::Quaterniond random_rotation(std::mt19937_64 &rng)
{
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double u1 = u(rng), u2 = 2 * kPi * u(rng), u3 = 2 * kPi * u(rng);
    return Eigen::Quaterniond(std::sqrt(u1) * std::cos(u3), std::sqrt(1 - u1) * std::sin(u2),
                              std::sqrt(1 - u1) * std::cos(u2), std::sqrt(u1) * std::sin(u3));
}

const EulerOrder kOrders[] = {EulerOrder::XYZ, EulerOrder::XZY, EulerOrder::YXZ,
                              EulerOrder::YZX, EulerOrder::ZXY, EulerOrder::ZYX};

} // namespace

TEST_CASE("Rotation helpers: log/exp convention and Euler angles", "[mocap][limits]")
{
    // exp_map takes angle * axis: (0, 0, 0.7) is 0.7 rad about z.
    const Eigen::Quaterniond q = exp_map(Eigen::Vector3d(0, 0, 0.7));
    CHECK((q.toRotationMatrix() - rot_z(0.7)).norm() < 1e-14);
    CHECK((log_map(q) - Eigen::Vector3d(0, 0, 0.7)).norm() < 1e-14);
    // -q is the same rotation: same log.
    Eigen::Quaterniond minus_q = q;
    minus_q.coeffs() = -q.coeffs();
    CHECK((log_map(minus_q) - Eigen::Vector3d(0, 0, 0.7)).norm() < 1e-14);
    CHECK(log_map(Eigen::Quaterniond::Identity()).norm() == 0.0);
    CHECK((log_map(exp_map(Eigen::Vector3d(1e-14, -2e-14, 0))) - Eigen::Vector3d(1e-14, -2e-14, 0))
              .norm() < 1e-25);

    // from_euler is the intrinsic composition, in the order's letters.
    const Eigen::Vector3d a(0.3, -0.5, 1.1);
    for (EulerOrder order : kOrders) {
        const std::string name = to_string(order);
        INFO(name);
        const Eigen::Matrix3d by_hand =
            rot_axis(name[0], a[0]) * rot_axis(name[1], a[1]) * rot_axis(name[2], a[2]);
        CHECK((from_euler(a, order).toRotationMatrix() - by_hand).norm() < 1e-14);
        CHECK((euler_angles(from_euler(a, order), order) - a).norm() < 1e-12);
        CHECK(euler_order_from_string(name) == order);
    }
    CHECK_THROWS_AS(euler_order_from_string("XYX"), MocapError);

    // Round trip of any rotation, including gimbal lock (middle angle +/- 90 deg).
    std::mt19937_64 rng(7);
    for (EulerOrder order : kOrders) {
        for (int i = 0; i < 200; ++i) {
            const Eigen::Quaterniond r = random_rotation(rng);
            const Eigen::Vector3d angles = euler_angles(r, order);
            CHECK(std::fabs(angles[1]) <= kPi / 2 + 1e-12);
            CHECK(angle_between(from_euler(angles, order), r) < 1e-9);
        }
        const Eigen::Quaterniond locked = from_euler(Eigen::Vector3d(0.4, kPi / 2, -0.3), order);
        CHECK(angle_between(from_euler(euler_angles(locked, order), order), locked) < 1e-7);
        const Eigen::Quaterniond locked_minus =
            from_euler(Eigen::Vector3d(0.4, -kPi / 2, 0.9), order);
        CHECK(angle_between(from_euler(euler_angles(locked_minus, order), order), locked_minus) <
              1e-7);
    }
}

TEST_CASE("Algorithm 1 recovers known mean, axes and spreads", "[mocap][limits]")
{
    // q = mean * exp(R diag(s) n), n ~ N(0, I): tangent covariance R diag(s^2) R^T.
    const Eigen::Quaterniond true_mean =
        from_euler(Eigen::Vector3d(0.8, -0.4, 2.0), EulerOrder::ZYX);
    const Eigen::Matrix3d true_axes =
        Eigen::AngleAxisd(1.0, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    const Eigen::Vector3d spread(0.3, 0.15, 0.05);
    const int n = 100000; // relative error of a std estimate ~ 1/sqrt(2n) = 0.22 %
    std::mt19937_64 rng(12345);
    std::normal_distribution<double> normal(0.0, 1.0);
    std::uniform_int_distribution<int> coin(0, 1);
    std::vector<Eigen::Quaterniond> samples, flipped;
    samples.reserve(n);
    flipped.reserve(n);
    for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d unit_normal(normal(rng), normal(rng), normal(rng));
        const Eigen::Quaterniond q =
            true_mean * exp_map(true_axes * spread.cwiseProduct(unit_normal));
        samples.push_back(q);
        Eigen::Quaterniond other = q;
        if (coin(rng))
            other.coeffs() = -other.coeffs();
        flipped.push_back(other);
    }
    const QuaternionLimit limit = learn_quaternion_limit(samples);
    CHECK(limit.k == 3.0);
    CHECK(angle_between(limit.mean, true_mean) < 0.005); // ~ 5 standard errors of 0.3/sqrt(n)
    for (int j = 0; j < 3; ++j) {
        INFO("axis " << j);
        CHECK(std::fabs(limit.axes.col(j).dot(true_axes.col(j))) > 0.999);
        CHECK(limit.sigma_rad[j] == Approx(spread[j]).epsilon(0.01));
    }
    CHECK(limit.axes.determinant() == Approx(1.0).margin(1e-12));

    // Signs of the samples do not matter.
    const QuaternionLimit same = learn_quaternion_limit(flipped);
    CHECK(angle_between(same.mean, limit.mean) < 1e-9);
    CHECK((same.axes - limit.axes).norm() < 1e-6);
    CHECK((same.sigma_rad - limit.sigma_rad).norm() < 1e-9);

    // A 3-D Gaussian lies within 3 standard deviations (Mahalanobis) with the
    // chi-square(3) probability P = erf(3/sqrt 2) - sqrt(2/pi) 3 exp(-9/2) = 0.9707.
    const double expected_inside =
        std::erf(3.0 / std::sqrt(2.0)) - std::sqrt(2.0 / kPi) * 3.0 * std::exp(-4.5);
    int inside = 0;
    for (const Eigen::Quaterniond &q : samples)
        inside += limit.contains(q) ? 1 : 0;
    CHECK(static_cast<double>(inside) / n == Approx(expected_inside).margin(0.003));

    // Clamp: inside unchanged; outside onto the surface, same tangent direction.
    int clamped = 0;
    for (int i = 0; i < 2000; ++i) {
        const Eigen::Quaterniond &q = samples[static_cast<std::size_t>(i)];
        const Eigen::Quaterniond c = limit.clamp(q);
        if (limit.contains(q)) {
            CHECK(angle_between(c, q) < 1e-12);
            continue;
        }
        ++clamped;
        CHECK(limit.normalized_distance(c) == Approx(1.0).margin(1e-9));
        const Eigen::Vector3d v = limit.tangent(q), w = limit.tangent(c);
        CHECK(v.normalized().dot(w.normalized()) > 1 - 1e-12);
    }
    CHECK(clamped > 20);
    std::mt19937_64 far_rng(3);
    for (int i = 0; i < 500; ++i) {
        const Eigen::Quaterniond c = limit.clamp(random_rotation(far_rng));
        CHECK(limit.contains(c, 1e-9));
    }
}

TEST_CASE("Algorithm 1: degenerate spreads use the floor", "[mocap][limits]")
{
    const Eigen::Quaterniond fixed = exp_map(Eigen::Vector3d(0.2, 0.1, -0.3));
    const std::vector<Eigen::Quaterniond> still(50, fixed);
    QuaternionLimitOptions options;
    options.sigma_floor_rad = 2e-3;
    const QuaternionLimit limit = learn_quaternion_limit(still, options);
    CHECK(angle_between(limit.mean, fixed) < 1e-12);
    CHECK((limit.sigma_rad - Eigen::Vector3d::Constant(2e-3)).norm() == 0.0);
    CHECK(limit.contains(fixed));
    const Eigen::Quaterniond c = limit.clamp(Eigen::Quaterniond::Identity());
    CHECK(std::isfinite(c.norm()));
    CHECK(angle_between(c, fixed) == Approx(3 * 2e-3).epsilon(1e-6)); // k * floor (sphere)

    // Motion about one axis only: two spreads at the floor, one real.
    std::vector<Eigen::Quaterniond> hinge;
    for (int i = 0; i < 1001; ++i)
        hinge.push_back(exp_map(Eigen::Vector3d(0, 0.5 * std::sin(0.01 * i), 0)));
    const QuaternionLimit hinge_limit = learn_quaternion_limit(hinge);
    CHECK(std::fabs(hinge_limit.axes.col(0).y()) > 1 - 1e-12);
    CHECK(hinge_limit.sigma_rad[1] == 1e-3);
    CHECK(hinge_limit.sigma_rad[2] == 1e-3);

    CHECK_THROWS_AS(learn_quaternion_limit({}), MocapError);
    QuaternionLimitOptions bad;
    bad.k = 0;
    CHECK_THROWS_AS(learn_quaternion_limit(still, bad), MocapError);
    std::vector<Eigen::Quaterniond> with_nan = still;
    with_nan[3] = Eigen::Quaterniond(std::nan(""), 0, 0, 0);
    CHECK_THROWS_AS(learn_quaternion_limit(with_nan), MocapError);
}

TEST_CASE("Euler limits on synthetic angles with known ranges", "[mocap][limits]")
{
    // Angles uniform in known ranges, order ZYX; a0 crosses +/- pi.
    const Eigen::Vector3d lo(2.8, -0.3, 0.1), hi(3.6, 0.2, 0.9);
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Eigen::Quaterniond> samples;
    for (int i = 0; i < 20000; ++i) {
        Eigen::Vector3d a;
        for (int k = 0; k < 3; ++k)
            a[k] = lo[k] + (hi[k] - lo[k]) * u(rng);
        samples.push_back(from_euler(a, EulerOrder::ZYX));
    }
    SECTION("min/max (percentile 0) recovers the ranges")
    {
        EulerLimitOptions options;
        options.method = EulerLimitOptions::Method::percentile;
        options.percentile = 0.0;
        const EulerLimit limit = learn_euler_limit(samples, options);
        // a0's range is found up to a whole turn.
        const double turn = std::round((limit.lower_rad[0] - lo[0]) / (2 * kPi)) * 2 * kPi;
        CHECK(limit.lower_rad[0] - turn == Approx(lo[0]).margin(1e-3));
        CHECK(limit.upper_rad[0] - turn == Approx(hi[0]).margin(1e-3));
        for (int k = 1; k < 3; ++k) {
            CHECK(limit.lower_rad[k] == Approx(lo[k]).margin(1e-3));
            CHECK(limit.upper_rad[k] == Approx(hi[k]).margin(1e-3));
        }
        CHECK(limit.contains(from_euler(Eigen::Vector3d(kPi, 0, 0.5), EulerOrder::ZYX)));
        CHECK_FALSE(limit.contains(from_euler(Eigen::Vector3d(0, 0, 0.5), EulerOrder::ZYX)));
    }
    SECTION("mean +/- k std: uniform std = width / sqrt(12)")
    {
        EulerLimitOptions options; // mean_std, k = 2.5
        const EulerLimit limit = learn_euler_limit(samples, options);
        for (int k = 0; k < 3; ++k) {
            const double centre = 0.5 * (lo[k] + hi[k]);
            const double half = 2.5 * (hi[k] - lo[k]) / std::sqrt(12.0);
            const double mid = 0.5 * (limit.lower_rad[k] + limit.upper_rad[k]);
            const double turn = std::round((mid - centre) / (2 * kPi)) * 2 * kPi;
            CHECK(mid - turn == Approx(centre).margin(0.01 * half));
            CHECK(0.5 * (limit.upper_rad[k] - limit.lower_rad[k]) == Approx(half).epsilon(0.01));
        }
    }
    SECTION("clamp puts any rotation inside and leaves inside ones alone")
    {
        EulerLimitOptions options;
        options.method = EulerLimitOptions::Method::percentile;
        options.percentile = 1.0;
        const EulerLimit limit = learn_euler_limit(samples, options);
        std::mt19937_64 any(5);
        for (int i = 0; i < 2000; ++i) {
            const Eigen::Quaterniond q = random_rotation(any);
            const Eigen::Quaterniond c = limit.clamp(q);
            CHECK(limit.contains(c, 1e-9));
            if (limit.contains(q, 0.0))
                CHECK(angle_between(c, q) < 1e-12);
        }
        int unchanged = 0;
        for (std::size_t i = 0; i < 1000; ++i)
            if (limit.contains(samples[i], 0.0)) {
                ++unchanged;
                CHECK(angle_between(limit.clamp(samples[i]), samples[i]) < 1e-12);
            }
        CHECK(unchanged > 900); // about 97 % of the samples lie in [1 %, 99 %] on all axes
        // A rotation beyond one limit moves onto it, the others stay.
        const Eigen::Vector3d beyond(kPi, 0.5, 0.5);
        const Eigen::Vector3d clamped = limit.angles(limit.clamp(from_euler(beyond, limit.order)));
        CHECK(clamped[1] == Approx(limit.upper_rad[1]).margin(1e-9));
        CHECK(clamped[2] == Approx(0.5).margin(1e-9));
    }
}

TEST_CASE("Joint limits: JSON round trip, report and table", "[mocap][limits]")
{
    std::vector<Eigen::Quaterniond> elbow, wrist;
    for (int i = 0; i < 200; ++i) {
        elbow.push_back(
            exp_map(Eigen::Vector3d(0.1 * std::sin(0.1 * i), 0.8 * std::sin(0.05 * i), 0)));
        wrist.push_back(exp_map(Eigen::Vector3d(0.02 * i / 200.0, 0, 0.3 * std::cos(0.07 * i))));
    }
    const LimitOptions options;
    const nlohmann::json report = limits_report({"elbow", "wrist"}, {elbow, wrist}, options);
    REQUIRE(report["joints"].size() == 2);
    CHECK(report["joints"][0]["name"] == "elbow");
    CHECK(report["joints"][1]["samples"] == 200);
    CHECK(report["options"]["quaternion"]["k"] == 3.0);
    CHECK(report["options"]["euler"]["order"] == "ZYX");
    const std::string dumped = report.dump();
    CHECK(dumped.find("null") == std::string::npos); // no NaN anywhere

    const EulerLimit euler = learn_euler_limit(elbow);
    const EulerLimit euler_back =
        euler_limit_from_json(nlohmann::json::parse(to_json(euler).dump()));
    CHECK(euler_back.order == euler.order);
    CHECK((euler_back.lower_rad - euler.lower_rad).norm() < 1e-12);
    CHECK((euler_back.upper_rad - euler.upper_rad).norm() < 1e-12);
    const QuaternionLimit quat = learn_quaternion_limit(elbow);
    const QuaternionLimit quat_back =
        quaternion_limit_from_json(nlohmann::json::parse(to_json(quat).dump()));
    CHECK(angle_between(quat_back.mean, quat.mean) < 1e-12);
    CHECK((quat_back.axes - quat.axes).norm() < 1e-12);
    CHECK((quat_back.sigma_rad - quat.sigma_rad).norm() < 1e-15);
    CHECK(quat_back.k == quat.k);
    CHECK_THROWS_AS(quaternion_limit_from_json(nlohmann::json{{"k", 3}}), MocapError);
    CHECK_THROWS_AS(euler_limit_from_json(nlohmann::json{{"order", "ABC"}}), MocapError);

    std::ostringstream table;
    print_limits(table, learn_limits({"elbow", "wrist"}, {elbow, wrist}));
    const std::string text = table.str();
    CHECK(text.find("elbow") != std::string::npos);
    CHECK(text.find("wrist") != std::string::npos);
    CHECK(std::count(text.begin(), text.end(), '\n') == 3);

    CHECK_THROWS_AS(learn_limits({"a"}, {elbow, wrist}), MocapError);
    CHECK_THROWS_AS(learn_limits({"a"}, {{}}), MocapError);
}

TEST_CASE("Joint limits on the CMU drumming file", "[mocap][limits][data]")
{
    const std::string path = data_file("cmu/80_13.bvh");
    if (path.empty())
        return;
    BvhOptions options;
    options.skip_frames = 1; // drop the converter's reference pose
    const BvhFile bvh = read_bvh(path, options);
    LimitOptions limit_options;
    limit_options.euler.method = EulerLimitOptions::Method::percentile;
    limit_options.euler.percentile = 0.0;
    const std::vector<JointLimit> limits = learn_limits(bvh.skeleton, bvh.motion, limit_options);
    REQUIRE(limits.size() == 31);
    CHECK(limits_report(limits, limit_options).dump().find("null") == std::string::npos);

    // LeftHand's Z and Y channels are always zero (README): its ZYX Euler
    // limits are [0, 0] on a0, a1 and the min/max of the X column on a2.
    // That column (65) read straight from the text:
    std::ifstream in(path, std::ios::binary);
    std::string line;
    double x_min = 1e9, x_max = -1e9;
    for (int n = 1; std::getline(in, line); ++n) {
        if (n < 189) // line 188 is the reference pose
            continue;
        std::istringstream fields(line);
        double value = 0;
        for (int c = 0; c <= 65; ++c)
            fields >> value;
        x_min = std::min(x_min, value);
        x_max = std::max(x_max, value);
    }
    const JointLimit *hand = nullptr;
    for (const JointLimit &limit : limits)
        if (limit.name == "LeftHand")
            hand = &limit;
    REQUIRE(hand);
    CHECK(hand->samples == 1014);
    CHECK(std::fabs(hand->euler.lower_rad[0]) < 1e-12);
    CHECK(std::fabs(hand->euler.upper_rad[0]) < 1e-12);
    CHECK(std::fabs(hand->euler.lower_rad[1]) < 1e-12);
    CHECK(std::fabs(hand->euler.upper_rad[1]) < 1e-12);
    CHECK(hand->euler.lower_rad[2] == Approx(deg(x_min)).margin(1e-12));
    CHECK(hand->euler.upper_rad[2] == Approx(deg(x_max)).margin(1e-12));
    // A hinge-like joint: its main spread axis is x, the others at the floor.
    CHECK(std::fabs(hand->quaternion.axes.col(0).x()) > 1 - 1e-9);
    CHECK(hand->quaternion.sigma_rad[1] == 1e-3);
    // LHipJoint never moves: every spread at the floor.
    for (const JointLimit &limit : limits)
        if (limit.name == "LHipJoint")
            CHECK((limit.quaternion.sigma_rad - Eigen::Vector3d::Constant(1e-3)).norm() == 0.0);
}
