// The trunk's reach (docs/perform.md, "The trunk"): a tip target beyond the
// arm's reach turns and leans the trunk toward it; while a plan plays, toward
// the farther of the target now and the target a moment ahead. The rig is
// private to src/perform (score_rig.hpp): this test reaches into it.
#include "score_rig.hpp"

#include "ictus/perform/kit.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace ictus;

namespace
{

constexpr int kRight = static_cast<int>(Side::right);

// The lumbar's and the thorax's references after trunk_synergy().
struct Trunk {
    Eigen::Quaterniond lumbar, thorax;
};

Trunk synergy(ScoreRig &r)
{
    r.trunk_synergy();
    return {r.step_body.local[r.lumbar], r.step_body.local[r.thorax]};
}

double apart(const Trunk &a, const Trunk &b)
{
    return a.lumbar.angularDistance(b.lumbar) + a.thorax.angularDistance(b.thorax);
}

} // namespace

TEST_CASE("trunk: the reach follows the look-ahead without a jump where its length crosses the "
          "target's",
          "[perform][trunk]")
{
    PerformanceOptions o;
    o.kit = kit_named("full");
    std::unique_ptr<ScoreRig> rig = make_score_rig(o, nullptr);
    ScoreRig &r = *rig;
    const Eigen::Vector3d up = r.frame.up, right = r.frame.right, fwd = r.frame.forward;
    const Eigen::Vector3d shoulder = r.shoulder_m[kRight];
    // The right hand's target now 1.0 m away in plan toward the crash's side
    // (forward-left), the target ahead toward the floor tom's (right-back of
    // forward), both 0.3 m below the shoulder; the left hand at rest.
    const Eigen::Vector3d now_dir = (fwd - 0.6 * right).normalized();
    const Eigen::Vector3d ahead_dir = (fwd + 0.9 * right).normalized();
    const Eigen::Vector3d drop = -0.3 * up;
    r.tips.position_m[0] = r.frame.rest_tip_m[0];
    r.ahead_m[0] = r.frame.rest_tip_m[0];
    r.tips.position_m[kRight] = shoulder + 1.0 * now_dir + drop;
    r.has_ahead = true;

    // The target ahead from 0.9 to 1.1 m in 0.5 mm steps: its length crosses
    // the target's now at 1.0 m, where the reach turns from one to the other.
    const int steps = 400;
    Trunk first{}, last{}, prev{};
    double largest_step = 0.0;
    for (int i = 0; i <= steps; ++i) {
        const double len = 0.9 + 0.2 * i / steps;
        r.ahead_m[kRight] = shoulder + len * ahead_dir + drop;
        const Trunk t = synergy(r);
        if (i == 0)
            first = t;
        else
            largest_step = std::max(largest_step, apart(prev, t));
        prev = last = t;
    }
    const double whole = apart(first, last);
    INFO("whole change " << whole << " rad, largest 0.5 mm step " << largest_step << " rad");
    // The reach changes direction over the sweep: a turn the size of a
    // reaching twist (tenths of a radian), not a small drift.
    REQUIRE(whole > 0.1);
    // Taken in one step (the farther of the two, unblended), the switch is
    // most of the whole change; blended, it spreads over many steps.
    CHECK(largest_step < 0.1 * whole);

    // Beyond half the blend's width (kReachBlend_m / 2) of the crossing the
    // reach is the farther target's alone: the same trunk as with that target
    // now and nothing ahead; within it, a blend that differs from both.
    const double half = 0.5 * ScoreRig::kReachBlend_m;
    auto alone_at = [&](const Eigen::Vector3d &target) {
        r.tips.position_m[kRight] = target;
        r.has_ahead = false;
        return synergy(r);
    };
    const Eigen::Vector3d now_target = shoulder + 1.0 * now_dir + drop;
    for (double d : {-1.05 * half, -0.95 * half, 0.95 * half, 1.05 * half}) {
        INFO("ahead longer by " << d << " m");
        const Eigen::Vector3d ahead_target = shoulder + (1.0 + d) * ahead_dir + drop;
        r.tips.position_m[kRight] = now_target;
        r.ahead_m[kRight] = ahead_target;
        r.has_ahead = true;
        const Trunk blended = synergy(r);
        const Trunk farther = alone_at(d > 0.0 ? ahead_target : now_target);
        if (std::abs(d) > half)
            CHECK(apart(blended, farther) < 1e-12);
        else
            CHECK(apart(blended, farther) > 1e-6);
    }
}
