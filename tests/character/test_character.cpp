// The character model: mapping, anthropometry (de Leva 1996), sticks and grips.
#include "ictus/character/anthropometry.hpp"
#include "ictus/character/character.hpp"
#include "ictus/control/joint_controller.hpp"
#include "ictus/sim/scene.hpp"
#include "support/sim_test_util.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Eigenvalues>
#include <random>
#include <tuple>

using namespace ictus;

TEST_CASE("de Leva's male mass fractions of the whole body add up to 1", "[character]")
{
    // Head + trunk (three parts) + 2 x (upper arm, forearm, hand, thigh, shank, foot).
    double sum = de_leva_male(DeLevaSegment::head).mass_fraction;
    for (DeLevaSegment s :
         {DeLevaSegment::upper_trunk, DeLevaSegment::middle_trunk, DeLevaSegment::lower_trunk})
        sum += de_leva_male(s).mass_fraction;
    for (DeLevaSegment s : {DeLevaSegment::upper_arm, DeLevaSegment::forearm, DeLevaSegment::hand,
                            DeLevaSegment::thigh, DeLevaSegment::shank, DeLevaSegment::foot})
        sum += 2.0 * de_leva_male(s).mass_fraction;
    CHECK(sum == Approx(1.0).margin(1e-3));
    // The trunk parts are de Leva's trunk, 43.46 %.
    CHECK(de_leva_male(DeLevaSegment::upper_trunk).mass_fraction +
              de_leva_male(DeLevaSegment::middle_trunk).mass_fraction +
              de_leva_male(DeLevaSegment::lower_trunk).mass_fraction ==
          Approx(0.4346).margin(1e-4));
}

TEST_CASE("the character has 19 three-DoF joints with CMU segment lengths", "[character]")
{
    const Skeleton skel = default_skeleton();
    CharacterOptions opt;
    opt.body_mass_kg = 80.0;
    const CharacterModel m = CharacterModel::from_skeleton(skel, opt);
    REQUIRE(m.bodies().size() == 20u);
    // Every body but the pelvis hangs from a parent that comes before it.
    for (int b = 1; b < CharacterModel::kBodies; ++b) {
        CHECK(m.bodies()[b].parent >= 0);
        CHECK(m.bodies()[b].parent < b);
    }
    // Upper arm: 5.1 units of 0.056444 m (the CMU convention) = 0.288 m.
    const BodySpec &upper_arm = m.bodies()[m.body_index("l_upper_arm")];
    CHECK(upper_arm.length_m == Approx(5.1 * 0.056444).epsilon(1e-9));
    CHECK(upper_arm.length_m > 0.25);
    CHECK(upper_arm.length_m < 0.35);
    // Mass: de Leva's 2.71 % of 80 kg; CoM at 57.72 % from the shoulder.
    CHECK(upper_arm.mass_kg == Approx(0.0271 * 80.0));
    CHECK(upper_arm.com_m.norm() == Approx(0.5772 * upper_arm.length_m));
    // Inertia about the long axis (x at rest): m (0.158 L)^2.
    CHECK(upper_arm.inertia_kg_m2(0, 0) ==
          Approx(upper_arm.mass_kg * std::pow(0.158 * upper_arm.length_m, 2)).epsilon(1e-9));
    // The whole body: the table's 100 % plus two sticks.
    CHECK(m.total_mass_kg() == Approx(80.0 + 2 * opt.stick.mass_kg).epsilon(1e-3));
    // Spine1 has no segment of its own: its rotation is composed into the
    // neck and the clavicles (it sits where they do), so the neck's source path
    // is Spine1 then Neck.
    const BodySpec &neck = m.bodies()[m.body_index("neck")];
    REQUIRE(neck.source_path.size() == 2u);
    CHECK(skel.joints[neck.source_path[0]].name == "Spine1");
    CHECK(skel.joints[neck.source_path[1]].name == "Neck");
    CHECK(m.joint_index("l_wrist") >= 0);
    CHECK(m.joint_index("nonsense") == -1);
}

TEST_CASE("a missing CMU joint or a bad option is refused with its name", "[character]")
{
    Skeleton skel = default_skeleton();
    skel.joints[skel.find("LeftForeArm")].name = "LeftLowerArm";
    CHECK_THROWS_WITH(CharacterModel::from_skeleton(skel), Catch::Contains("LeftForeArm"));
    const Skeleton good = default_skeleton();
    CharacterOptions opt;
    opt.body_mass_kg = -3;
    CHECK_THROWS_WITH(CharacterModel::from_skeleton(good, opt), Catch::Contains("body mass"));
    opt = {};
    opt.stick.tip_radius_m = 0.5;
    CHECK_THROWS_WITH(CharacterModel::from_skeleton(good, opt), Catch::Contains("tip radius"));
    opt = {};
    opt.stick.length_m = std::nan("");
    CHECK_THROWS_WITH(CharacterModel::from_skeleton(good, opt), Catch::Contains("stick length"));
    CHECK_THROWS_WITH(grip_from_string("italian"), Catch::Contains("italian"));
    CHECK(grip_from_string("German") == Grip::german);
}

// A CMU-named skeleton exported without fingers or toes was refused ("no
// joint named 'LeftHandIndex1'"). The hand and the foot end at their own
// End Site instead; every other joint is still required by name.
TEST_CASE("a skeleton without fingers or toes ends its hands and feet at their End Sites",
          "[character]")
{
    const Skeleton full = default_skeleton();
    const std::vector<std::string> dropped = {
        "LeftFingerBase", "LeftHandIndex1",  "LeftHandIndex1_end", "LThumb",
        "LThumb_end",     "RightFingerBase", "RightHandIndex1",    "RightHandIndex1_end",
        "RThumb",         "RThumb_end",      "LeftToeBase",        "LeftToeBase_end",
        "RightToeBase",   "RightToeBase_end"};
    // The joints kept, parents renumbered; then an End Site where the fingers
    // (the toes) ended: the same stretch of skeleton as FingerBase + HandIndex1.
    auto without = [&](bool with_end_sites) {
        Skeleton s;
        std::vector<int> index(full.joints.size(), -1);
        for (size_t j = 0; j < full.joints.size(); ++j) {
            if (std::find(dropped.begin(), dropped.end(), full.joints[j].name) != dropped.end())
                continue;
            SkeletonJoint joint = full.joints[j];
            joint.parent = joint.parent < 0 ? -1 : index[static_cast<size_t>(joint.parent)];
            index[j] = static_cast<int>(s.joints.size());
            s.joints.push_back(joint);
        }
        if (with_end_sites)
            for (const auto &[joint, first, last] :
                 {std::tuple<const char *, const char *, const char *>{"LeftHand", "LeftFingerBase",
                                                                       "LeftHandIndex1"},
                  {"RightHand", "RightFingerBase", "RightHandIndex1"},
                  {"LeftFoot", "LeftToeBase", "LeftToeBase_end"},
                  {"RightFoot", "RightToeBase", "RightToeBase_end"}}) {
                SkeletonJoint end;
                end.name = std::string(joint) + "_End";
                end.parent = s.find(joint);
                end.end_site = true;
                end.offset_m =
                    full.joints[full.find(first)].offset_m + full.joints[full.find(last)].offset_m;
                s.joints.push_back(end);
            }
        return s;
    };
    const CharacterModel reference = CharacterModel::from_skeleton(full);
    const CharacterModel m = CharacterModel::from_skeleton(without(true));
    for (int b = 0; b < CharacterModel::kBodies; ++b) {
        const BodySpec &got = m.bodies()[b], &want = reference.bodies()[b];
        INFO("body " << got.name);
        CHECK((got.distal_m - want.distal_m).norm() < 1e-12);
        CHECK(got.mass_kg == Approx(want.mass_kg));
        CHECK((got.com_m - want.com_m).norm() < 1e-12);
        CHECK((got.inertia_kg_m2 - want.inertia_kg_m2).norm() < 1e-12);
    }
    for (const Side side : {Side::left, Side::right}) {
        // The default thumb lies along +z across the fingers: so does the fallback's.
        CHECK((m.stick(side).tip_m - reference.stick(side).tip_m).norm() < 1e-12);
        CHECK((m.stick(side).axis - reference.stick(side).axis).norm() < 1e-12);
    }
    // Without an End Site either, the CMU joint is named.
    CHECK_THROWS_WITH(CharacterModel::from_skeleton(without(false)),
                      Catch::Contains("no joint named 'LeftHandIndex1'"));
}

TEST_CASE("grips: German sticks lie in the palm plane, French ones in the finger-palm plane",
          "[character]")
{
    const Skeleton skel = default_skeleton();
    for (Grip grip : {Grip::german, Grip::french}) {
        CharacterOptions opt;
        opt.grip = grip;
        const CharacterModel m = CharacterModel::from_skeleton(skel, opt);
        const StickInHand &st = m.stick(Side::left);
        // Left hand at rest: fingers +x, thumb +z, palm facing -y.
        if (grip == Grip::german) {
            CHECK(st.axis.y() == Approx(0.0).margin(1e-12));
            CHECK(st.axis.z() == Approx(std::sin(opt.stick.grip_angle_rad)));
        } else {
            CHECK(st.axis.z() == Approx(0.0).margin(1e-12));
            CHECK(st.axis.y() == Approx(-std::sin(opt.stick.grip_angle_rad)));
        }
        CHECK(st.axis.x() == Approx(std::cos(opt.stick.grip_angle_rad)));
        // The tip is the stick's far end: length minus the butt-to-grip part.
        CHECK((st.tip_m - st.grip_m).norm() ==
              Approx(opt.stick.length_m - opt.stick.grip_from_butt_m));
        CHECK((st.tip_m - st.butt_m).norm() == Approx(opt.stick.length_m));
        // Merging the stick moves the hand's centre of mass towards the stick's.
        double mass;
        Eigen::Vector3d com;
        Eigen::Matrix3d inertia;
        m.merged_mass(m.hand_body(Side::left), mass, com, inertia);
        const BodySpec &hand = m.bodies()[m.hand_body(Side::left)];
        CHECK(mass == Approx(hand.mass_kg + opt.stick.mass_kg));
        CHECK((com - (hand.mass_kg * hand.com_m + opt.stick.mass_kg * st.com_m) / mass).norm() <
              1e-12);
    }
}

TEST_CASE("reference motion: composed rotations, slerp in time, ping-pong past the end",
          "[character]")
{
    const Skeleton skel = default_skeleton();
    const CharacterModel m = CharacterModel::from_skeleton(skel);
    // Elbow (LeftForeArm) turns about z by 10 degrees per frame, Spine1 by 1 per frame.
    const Motion motion = simtest::make_motion(skel, 5, 10.0, [](int f, const std::string &j) {
        if (j == "LeftForeArm")
            return Eigen::Quaterniond(
                Eigen::AngleAxisd(f * 10.0 * M_PI / 180, Eigen::Vector3d::UnitZ()));
        if (j == "Spine1")
            return Eigen::Quaterniond(Eigen::AngleAxisd(f * M_PI / 180, Eigen::Vector3d::UnitX()));
        return Eigen::Quaterniond::Identity();
    });
    const ReferenceMotion ref(m, motion);
    CHECK(ref.duration_s() == Approx(0.4));
    const int elbow = m.joint_index("l_elbow"), clav = m.joint_index("l_clavicle");
    CharacterPose p;
    ref.sample(0.15, p); // between frames 1 and 2: 15 degrees
    CHECK(Eigen::AngleAxisd(p.local[elbow]).angle() * 180 / M_PI == Approx(15.0));
    CHECK(Eigen::AngleAxisd(p.local[clav]).angle() * 180 / M_PI == Approx(1.5));
    ref.sample(0.5, p); // 0.1 s past the end: back at frame 3, 30 degrees
    CHECK(Eigen::AngleAxisd(p.local[elbow]).angle() * 180 / M_PI == Approx(30.0));
}

TEST_CASE("reference clean-up: the Butterworth kernel has the zero-phase 2nd-order Butterworth "
          "response, flat through a drummer's strokes",
          "[character][track]")
{
    // The taps' transfer function H(f) = w0 + 2 sum w_k cos(2 pi f k / fs)
    // against the response it is made from, G(f) = 1 / (1 + (f / fc)^4): the
    // taps are G's inverse Fourier transform truncated at 1e-3 of the centre
    // tap, so H differs from G by ~1e-3 (measured at most 1.4e-3 over these
    // rates and cutoffs).
    for (const double fs : {100.0, 120.0, 250.0}) {
        for (const double fc : {6.0, 10.0, 15.0}) {
            const std::vector<double> w =
                reference_kernel_taps(ReferenceFilter::Kernel::butterworth, fc, fs);
            REQUIRE(w.size() >= 2);
            for (double f = 0.0; f <= 0.5 * fs; f += 0.5) {
                double h = w[0];
                for (size_t k = 1; k < w.size(); ++k)
                    h += 2.0 * w[k] * std::cos(2.0 * M_PI * f * k / fs);
                INFO("fs " << fs << " Hz, fc " << fc << " Hz, f " << f << " Hz");
                CHECK(h == Approx(1.0 / (1.0 + std::pow(f / fc, 4.0))).margin(2.5e-3));
            }
        }
    }
    // The Gaussian's taps are exp(-k^2 / (2 sigma^2)), sigma = fs / (2 pi fc), to 3 sigma.
    const std::vector<double> g = reference_kernel_taps(ReferenceFilter::Kernel::gaussian, 10, 120);
    const double sigma = 120.0 / (2.0 * M_PI * 10.0);
    REQUIRE(g.size() == static_cast<size_t>(std::ceil(3.0 * sigma)) + 1);
    for (size_t k = 0; k < g.size(); ++k)
        CHECK(g[k] == Approx(std::exp(-0.5 * k * k / (sigma * sigma))));
    CHECK_THROWS_WITH(reference_kernel_from_string("boxcar"),
                      Catch::Contains("gaussian or butterworth") && Catch::Contains("boxcar"));
    CHECK(reference_kernel_from_string(to_string(ReferenceFilter::Kernel::butterworth)) ==
          ReferenceFilter::Kernel::butterworth);

    // On a motion: the elbow swings 30 degrees about one axis at 4 Hz (a
    // drummer's stroke rate), 120 Hz, 3 s. About one axis the tangent-space
    // smoothing is linear, so mid-clip the swing keeps G(4 Hz) of its
    // amplitude: 0.9750 with the Butterworth at 10 Hz, exp(-0.08) = 0.9231
    // with the Gaussian.
    const Skeleton skel = default_skeleton();
    const CharacterModel m = CharacterModel::from_skeleton(skel);
    const double amp = 30.0 * M_PI / 180.0;
    const Motion motion = simtest::make_motion(skel, 361, 120.0, [&](int f, const std::string &j) {
        if (j == "LeftForeArm")
            return Eigen::Quaterniond(Eigen::AngleAxisd(
                amp * std::cos(2.0 * M_PI * 4.0 * f / 120.0), Eigen::Vector3d::UnitZ()));
        return Eigen::Quaterniond::Identity();
    });
    const int elbow = m.joint_index("l_elbow");
    for (const auto kernel :
         {ReferenceFilter::Kernel::butterworth, ReferenceFilter::Kernel::gaussian}) {
        ReferenceFilter filter;
        filter.kernel = kernel;
        const ReferenceMotion ref(m, motion, filter);
        const double expected = kernel == ReferenceFilter::Kernel::butterworth
                                    ? 1.0 / (1.0 + std::pow(4.0 / 10.0, 4.0))
                                    : std::exp(-0.5 * (4.0 / 10.0) * (4.0 / 10.0));
        double peak = 0.0;
        for (int f = 120; f <= 240; ++f) { // mid-clip: the edges' truncated kernels left out
            const Eigen::AngleAxisd a(ref.frame(f).local[elbow]);
            peak = std::max(peak, a.angle());
        }
        INFO(to_string(kernel) << ": peak " << peak * 180 / M_PI << " deg");
        // The frames sample the 4 Hz cosine at its peaks (every 30th frame).
        CHECK(peak / amp == Approx(expected).margin(2e-3));
    }
}

// track's de-spiking took every stroke's turn of a capture at 30 Hz for a
// spike: a turn of angular acceleration a lies a h^2 / 2 off its neighbours'
// midpoint, 16 times further at 30 Hz than at 120 Hz. Its threshold holds at
// 120 Hz and above and grows as (120 / rate)^2 below.
TEST_CASE(
    "reference clean-up: a stroke's turn is no spike at any frame rate, a one-frame glitch is",
    "[character][track]")
{
    const Skeleton skel = default_skeleton();
    const CharacterModel m = CharacterModel::from_skeleton(skel);
    const int elbow = m.joint_index("r_elbow");
    std::mt19937 rng(2026);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double rates[] = {25.0, 30.0, 40.0, 50.0, 60.0, 100.0, 120.0, 240.0};
    for (int trial = 0; trial < 24; ++trial) {
        const double rate = rates[trial % 8];
        // Strokes of 20-60 degrees at 3-6 Hz: the peak acceleration amp (2 pi f)^2
        // puts a turn at most 2.96 degrees off its neighbours at 120 Hz.
        const double amp = (20.0 + 40.0 * u(rng)) * M_PI / 180.0;
        const double freq = 3.0 + 3.0 * u(rng), phase = 2.0 * M_PI * u(rng);
        const int frames = static_cast<int>(2.0 * rate) + 1;
        const double threshold_deg = 5.0 * std::pow(std::max(1.0, 120.0 / rate), 2.0);
        const int glitch = 2 + static_cast<int>((frames - 4) * u(rng));
        auto swing = [&](int f) {
            return Eigen::Quaterniond(Eigen::AngleAxisd(
                amp * std::cos(2.0 * M_PI * freq * f / rate + phase), Eigen::Vector3d::UnitY()));
        };
        auto angle_deg = [](const Eigen::Quaterniond &a, const Eigen::Quaterniond &b) {
            return 2.0 * std::acos(std::min(1.0, std::fabs(a.dot(b)))) * 180.0 / M_PI;
        };
        // The glitch, about an axis across the swing's: twice the threshold and
        // twice its neighbours' distance from each other (a spike stands out of
        // the motion around it); possible where that stays under 170 degrees.
        const double glitch_deg =
            std::max(2.0 * threshold_deg, 2.0 * angle_deg(swing(glitch - 1), swing(glitch + 1)));
        const double glitch_rad = glitch_deg * M_PI / 180.0;
        const bool glitched = glitch_deg < 170.0;
        for (const bool with_glitch : {false, true}) {
            if (with_glitch && !glitched)
                continue;
            const Motion motion =
                simtest::make_motion(skel, frames, rate, [&](int f, const std::string &j) {
                    if (j != "RightForeArm")
                        return Eigen::Quaterniond::Identity();
                    if (with_glitch && f == glitch)
                        return Eigen::Quaterniond(
                            swing(f) * Eigen::AngleAxisd(glitch_rad, Eigen::Vector3d::UnitX()));
                    return swing(f);
                });
            ReferenceFilter filter; // 5 degrees at 120 Hz and above (track's)
            filter.spike_reference_rate_hz = 120.0;
            filter.smooth_cutoff_hz = 0.0;
            const ReferenceMotion ref(m, motion, filter);
            INFO("trial " << trial << ": " << rate << " Hz, " << amp * 180 / M_PI << " deg at "
                          << freq << " Hz, glitch " << with_glitch << " at frame " << glitch);
            if (!with_glitch) {
                CHECK(ref.spikes_removed() == 0);
                continue;
            }
            CHECK(ref.spikes_removed() == 1);
            // Replaced by its neighbours' midpoint, which lies within the
            // turn's 2.96 (120 / rate)^2 degrees of the swing.
            const Eigen::Quaterniond &cleaned = ref.frame(glitch).local[elbow];
            CHECK(angle_deg(cleaned, swing(glitch - 1).slerp(0.5, swing(glitch + 1))) < 1e-4);
            const double from_swing_deg = angle_deg(cleaned, swing(glitch));
            CHECK(from_swing_deg <= 2.96 * std::pow(std::max(1.0, 120.0 / rate), 2.0) + 1e-6);
        }
    }
}

namespace
{

// Every body as ODE gets it (the hands with their sticks): mass > 0 and a
// positive-definite inertia, what dMassCheck asserts before aborting.
void require_physical_bodies(const CharacterModel &m)
{
    for (int b = 0; b < CharacterModel::kBodies; ++b) {
        double mass;
        Eigen::Vector3d com;
        Eigen::Matrix3d inertia;
        m.merged_mass(b, mass, com, inertia);
        INFO("body " << m.bodies()[b].name);
        CHECK(mass > 0.0);
        const Eigen::Vector3d moments =
            Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(inertia).eigenvalues();
        CHECK(moments.minCoeff() > 1e-9);
    }
}

} // namespace

// A BVH with a zero OFFSET on a limb's joint built a forearm of length 0,
// inertia 0: ODE's dMassCheck aborted the process (SIGABRT) in track, render
// and run. Now the builder refuses it, naming the joint and its OFFSET's line.
TEST_CASE("a limb of zero length is refused at its OFFSET, naming the joint", "[character]")
{
    const struct {
        const char *joint; // whose OFFSET ends the limb
        const char *body;
    } limbs[] = {{"LeftForeArm", "l_upper_arm"},  {"LeftHand", "l_forearm"},
                 {"LeftLeg", "l_thigh"},          {"LeftFoot", "l_shank"},
                 {"RightForeArm", "r_upper_arm"}, {"RightHand", "r_forearm"},
                 {"RightLeg", "r_thigh"},         {"RightFoot", "r_shank"}};
    for (const auto &limb : limbs) {
        INFO(limb.joint);
        Skeleton skel = default_skeleton();
        const int j = skel.find(limb.joint);
        skel.joints[j].offset_m.setZero();
        CHECK_THROWS_WITH(CharacterModel::from_skeleton(skel),
                          Catch::StartsWith(std::string("skeleton: joint '") + limb.joint +
                                            "': expected the " + limb.body +
                                            " segment to be 0.05 to 1 m (a human limb), got 0 m"));
        // Read from a file: the file and the line of the OFFSET lead.
        skel.source = "clip.bvh";
        skel.joints[j].offset_line = 42;
        CHECK_THROWS_WITH(CharacterModel::from_skeleton(skel),
                          Catch::StartsWith(std::string("clip.bvh:42: joint '") + limb.joint));
    }
    // Too long: a segment of more than 1 m, the joint with the longest OFFSET named.
    Skeleton skel = default_skeleton();
    skel.joints[skel.find("Head_end")].offset_m *= 20.0; // 1.9 m of head
    CHECK_THROWS_WITH(CharacterModel::from_skeleton(skel),
                      Catch::StartsWith("skeleton: joint 'Head_end': expected the head segment to "
                                        "be at most 1 m (a human body), got 1.9"));
    skel = default_skeleton();
    skel.joints[skel.find("LHipJoint")].offset_m = Eigen::Vector3d(0, -1.5, 0);
    CHECK_THROWS_WITH(CharacterModel::from_skeleton(skel),
                      Catch::Contains("joint 'LHipJoint': expected the l_hip joint's distance "
                                      "from its parent to be at most 1 m"));
    // Not a number: refused, not built.
    skel = default_skeleton();
    skel.joints[skel.find("LeftShoulder")].offset_m.x() = std::nan("");
    CHECK_THROWS_AS(CharacterModel::from_skeleton(skel), CharacterError);
}

// Zero-length segments that carry no body of their own, or whose inertia
// comes from de Leva's lengths, are legal: a zero End Site, zero fingers.
// Property: zero each joint's OFFSET in turn: either the builder refuses it
// naming that joint (the eight limbs), or every body is physical and the ODE
// scene builds and steps.
TEST_CASE("zeroing any one OFFSET either names the joint or builds a physical body",
          "[character]")
{
    const Skeleton good = default_skeleton();
    int refused = 0;
    for (std::size_t j = 1; j < good.joints.size(); ++j) {
        Skeleton skel = good;
        skel.joints[j].offset_m.setZero();
        INFO("zero OFFSET on " << skel.joints[j].name);
        try {
            const CharacterModel m = CharacterModel::from_skeleton(skel);
            require_physical_bodies(m);
            CharacterPose pose = m.rest_pose();
            pose.pelvis_position_m = Eigen::Vector3d(0, 1.0, 0);
            Scene scene(m, SceneOptions{}, pose, default_gains(m, pose));
            scene.set_joint_targets(
                pose.local,
                std::vector<Eigen::Vector3d>(CharacterModel::kJoints, Eigen::Vector3d::Zero()));
            CHECK(scene.step() == StepResult::ok);
        } catch (const CharacterError &e) {
            ++refused;
            CHECK_THAT(e.what(), Catch::StartsWith("skeleton: joint '" + skel.joints[j].name +
                                                   "': expected the"));
            CHECK_THAT(e.what(), Catch::Contains("a human limb"));
        }
    }
    CHECK(refused == 8); // the eight limbs, nothing else
}

// Property: the default skeleton at a random scale is built exactly when its
// shortest limb (forearm, 3.6 units) is >= 0.05 m and its longest segment
// (shank, |(2.6, -7, 0)| units) <= 1 m; every body built is physical.
TEST_CASE("a skeleton at any scale is built exactly within the bounds of a human body",
          "[character]")
{
    const double shortest_limb = 3.6, longest = Eigen::Vector3d(2.6, -7.0, 0).norm();
    std::mt19937 rng(4242);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int trial = 0; trial < 200; ++trial) {
        const double scale = 1e-3 * std::pow(1e3, unit(rng));
        const bool human =
            scale * shortest_limb >= kMinLimbLength_m && scale * longest <= kMaxSegmentLength_m;
        INFO("scale " << scale);
        if (std::fabs(scale * shortest_limb - kMinLimbLength_m) < 1e-9 ||
            std::fabs(scale * longest - kMaxSegmentLength_m) < 1e-9)
            continue; // on an edge: either answer is rounding
        if (human) {
            const CharacterModel m =
                CharacterModel::from_skeleton(simtest::default_skeleton_at_scale(scale));
            require_physical_bodies(m);
        } else {
            CHECK_THROWS_WITH(CharacterModel::from_skeleton(simtest::default_skeleton_at_scale(scale)),
                              Catch::Contains(scale * shortest_limb < kMinLimbLength_m
                                                  ? "a human limb"
                                                  : "check the scale, --scale"));
        }
    }
}
