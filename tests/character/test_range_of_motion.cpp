// The score performer's joint limits (range_of_motion.hpp): swing-twist
// coordinates that recompose, a clamp that lands inside and keeps what is
// inside, left and right as mirror images, and a real drummer's arms (CMU
// 80_13, captured) inside the published ranges.
#include "ictus/base/rotation.hpp"
#include "ictus/character/range_of_motion.hpp"
#include "ictus/character/stick_capture.hpp"
#include "ictus/mocap/bvh.hpp"
#include "support/sim_test_util.hpp"

#include <catch2/catch.hpp>

#include <random>

using namespace ictus;

namespace
{
Eigen::Quaterniond random_rotation(std::mt19937 &rng, double max_angle)
{
    std::normal_distribution<double> n(0.0, 1.0);
    std::uniform_real_distribution<double> a(0.0, max_angle);
    const Eigen::Vector3d axis = Eigen::Vector3d(n(rng), n(rng), n(rng)).normalized();
    return Eigen::Quaterniond(Eigen::AngleAxisd(a(rng), axis));
}
// The mirror image through the body's midplane (x -> -x): (w, x, y, z) -> (w, x, -y, -z).
Eigen::Quaterniond mirror(const Eigen::Quaterniond &q)
{
    return Eigen::Quaterniond(q.w(), q.x(), -q.y(), -q.z());
}
} // namespace

TEST_CASE("range of motion: coordinates recompose, the clamp lands inside, inside is kept",
          "[character][limits]")
{
    const CharacterModel model = CharacterModel::from_skeleton(default_skeleton());
    const RangeOfMotion rom(model);
    std::mt19937 rng(7);
    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        const SwingTwistLimit &l = rom.limit(j);
        INFO("joint " << model.joint_name(j));
        CHECK(std::fabs(l.u.dot(l.twist_axis)) < 1e-12);
        CHECK(std::fabs(l.w.dot(l.twist_axis)) < 1e-12);
        CHECK(std::fabs(l.u.dot(l.w)) < 1e-12);
        CHECK(l.contains(Eigen::Quaterniond::Identity())); // the rest pose is a human pose
        for (int i = 0; i < 200; ++i) {
            const Eigen::Quaterniond q = random_rotation(rng, M_PI);
            const Eigen::Vector3d c = l.coordinates(q);
            // q = swing * twist, recomposed from the coordinates.
            const Eigen::Quaterniond back =
                exp_map(c[0] * l.u + c[1] * l.w) *
                Eigen::Quaterniond(Eigen::AngleAxisd(c[2], l.twist_axis));
            CHECK(rotation_angle_between(q, back) < 1e-9);
            const Eigen::Quaterniond inside = l.clamp(q);
            CHECK(l.contains(inside, 1e-9));
            CHECK(rotation_angle_between(inside, l.clamp(inside)) < 1e-12);
            CHECK(l.excursion_rad(q) == Approx(rotation_angle_between(q, inside)).margin(1e-12));
            if (l.contains(q))
                CHECK(rotation_angle_between(q, inside) < 1e-12);
        }
    }
}

TEST_CASE("range of motion: the IK's narrowed ranges keep a rotation the margin inside the range",
          "[character][limits]")
{
    // A rotation clamped into the narrowed ranges has every coordinate at
    // least the margin inside the true range (or at its middle, for a range
    // narrower than twice the margin), and a rotation inside the narrowed
    // ranges stays as it is.
    const CharacterModel model = CharacterModel::from_skeleton(default_skeleton());
    const RangeOfMotion rom(model);
    std::mt19937 rng(3141);
    std::uniform_real_distribution<double> margin_deg(0.5, 6.0);
    for (int trial = 0; trial < 5; ++trial) {
        const double m = margin_deg(rng) * M_PI / 180.0;
        const RangeOfMotion narrow(model, m);
        for (int j = 0; j < CharacterModel::kJoints; ++j) {
            const SwingTwistLimit &l = rom.limit(j), &n = narrow.limit(j);
            INFO("joint " << model.joint_name(j) << " margin " << m * 180.0 / M_PI << " deg");
            const double lo[3] = {l.u_lo_rad, l.w_lo_rad, l.twist_lo_rad};
            const double hi[3] = {l.u_hi_rad, l.w_hi_rad, l.twist_hi_rad};
            for (int i = 0; i < 100; ++i) {
                const Eigen::Quaterniond q = random_rotation(rng, M_PI);
                const Eigen::Quaterniond inside = n.clamp(q);
                const Eigen::Vector3d c = l.coordinates(inside);
                for (int k = 0; k < 3; ++k) {
                    const double need = std::min(m, 0.5 * (hi[k] - lo[k]));
                    CHECK(c[k] >= lo[k] + need - 1e-9);
                    CHECK(c[k] <= hi[k] - need + 1e-9);
                }
                CHECK(l.excursion_rad(inside) == 0.0);
                if (n.contains(q))
                    CHECK(rotation_angle_between(q, inside) < 1e-12);
            }
        }
    }
    CHECK_THROWS_AS(RangeOfMotion(model, -0.01), CharacterError);
}

TEST_CASE("range of motion: the left side is the mirror image of the right", "[character][limits]")
{
    const CharacterModel model = CharacterModel::from_skeleton(default_skeleton());
    const RangeOfMotion rom(model);
    std::mt19937 rng(8);
    for (const char *joint : {"clavicle", "shoulder", "elbow", "wrist", "hip", "knee", "ankle"}) {
        const SwingTwistLimit &right = rom.limit(model.joint_index(std::string("r_") + joint));
        const SwingTwistLimit &left = rom.limit(model.joint_index(std::string("l_") + joint));
        INFO(joint);
        int inside = 0;
        for (int i = 0; i < 500; ++i) {
            const Eigen::Quaterniond q = random_rotation(rng, 2.0);
            CHECK(right.contains(q, 1e-6) == left.contains(mirror(q), 1e-6));
            inside += right.contains(q);
        }
        CHECK(inside > 0); // the draws reach inside
    }
}

TEST_CASE("range of motion: a real drummer's arms and trunk stay inside (CMU 80_13)",
          "[character][limits][data]")
{
    const std::string path = simtest::data_file("cmu/80_13.bvh");
    if (path.empty())
        return;
    BvhOptions options;
    options.scale = kCmuBvhScale_m;
    const BvhFile file = read_bvh(path, options, nullptr);
    const CharacterModel model = CharacterModel::from_skeleton(file.skeleton);
    const RangeOfMotion rom(model);
    // The joints the score performer moves. The table's ranges are the published ones;
    // where the CMU skeleton's frames put a motion (the elbow's axis between y and z, the
    // forearm's pronation in the wrist's twist) was read from this clip (docs/character.md),
    // so this is a check of that reading, and of everything else against a real drummer.
    // (The capture's feet sit in a rest convention 30-100 degrees from the body's: the legs
    // are not compared.)
    for (const char *joint : {"lumbar", "thorax", "neck", "l_clavicle", "l_shoulder", "l_elbow",
                              "l_wrist", "r_clavicle", "r_shoulder", "r_elbow", "r_wrist"}) {
        const int j = model.joint_index(joint);
        double worst = 0.0;
        for (int f = 0; f < file.motion.frames(); ++f)
            worst = std::max(
                worst, rom.limit(j).excursion_rad(model.pose_from_motion(file.motion, f).local[j]));
        INFO(joint << ": worst excursion " << worst * 180.0 / M_PI << " deg over "
                   << file.motion.frames() << " frames");
        CHECK(worst * 180.0 / M_PI < 2.0);
    }
}

// The clamp's quick inside test (bounds on atan, no trigonometry) must never
// call a rotation inside that is not: rotations built from known coordinates
// just inside and just outside each bound, the others anywhere in range.
TEST_CASE("range of motion: inside and outside at the bounds, from known coordinates",
          "[character][limits]")
{
    const CharacterModel model = CharacterModel::from_skeleton(default_skeleton());
    const RangeOfMotion rom(model);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        const SwingTwistLimit &l = rom.limit(j);
        INFO("joint " << model.joint_name(j));
        const double lo[3] = {l.u_lo_rad, l.w_lo_rad, l.twist_lo_rad};
        const double hi[3] = {l.u_hi_rad, l.w_hi_rad, l.twist_hi_rad};
        for (int i = 0; i < 400; ++i) {
            double c[3];
            for (int k = 0; k < 3; ++k)
                c[k] = lo[k] + (hi[k] - lo[k]) * unit(rng);
            const int k = i % 3;
            const bool upper = (i / 3) % 2 == 0, out = (i / 6) % 2 == 0;
            const double bound = upper ? hi[k] : lo[k];
            const double nudge = 1e-6 * (out == upper ? 1.0 : -1.0);
            c[k] = bound + nudge;
            if (std::hypot(c[0], c[1]) >= M_PI)
                continue; // a swing past a half turn is another rotation's coordinates
            const Eigen::Quaterniond q = exp_map(c[0] * l.u + c[1] * l.w) *
                                         Eigen::Quaterniond(Eigen::AngleAxisd(c[2], l.twist_axis));
            INFO("coordinates " << c[0] << " " << c[1] << " " << c[2] << ", axis " << k
                                << (upper ? " upper" : " lower") << (out ? " outside" : " inside"));
            CHECK(l.contains(q, 0.0) == !out);
            CHECK((l.excursion_rad(q) > 0.0) == out);
            CHECK((rotation_angle_between(q, l.clamp(q)) > 1e-12) == out);
            // Far inside: the rest pose's neighbourhood is kept as it is.
            const Eigen::Quaterniond small =
                exp_map(0.01 * c[0] * l.u + 0.01 * c[1] * l.w) *
                Eigen::Quaterniond(Eigen::AngleAxisd(0.01 * c[2], l.twist_axis));
            CHECK(l.clamp(small).coeffs() == small.normalized().coeffs());
        }
    }
}
