// fuzz_score_plan.cpp -- libFuzzer harness of the planner (score/gesture_score.hpp):
// a score that parses is planned on the built-in gesture database, for the
// default body's drum (character/default_skeleton.hpp: default_skeleton(), the
// drum where a score performance puts it), as run and render do.
//
// A refusal (ScoreError: a hand too fast, a performance too long) is a pass.
// A crash, a sanitizer report, a run over the -timeout or a plan that breaks
// its promises (gesture_score.hpp: finite tips, unit stick directions,
// samples in time order with one exactly at each strike, where the tip is on
// its target) is a finding. See docs/fuzzing.md.
#include "fuzz_check.hpp"

#include "ictus/character/character.hpp"
#include "ictus/character/default_skeleton.hpp"
#include "ictus/gesture/gesture.hpp"
#include "ictus/score/gesture_score.hpp"
#include "ictus/score/score.hpp"

#include <algorithm>

using namespace ictus;

namespace
{

constexpr std::size_t kMaxInputBytes = 4 * 1024;
// The planner's work grows with the notes (one unit made per note) and with
// the duration (samples at rate_hz): each run stays well under a second with
// these, so that the -timeout catches a loop that does not end, not a long score.
constexpr std::size_t kMaxNotes = 400;
constexpr double kMaxDuration_s = 120.0;
constexpr double kRate_hz = 250.0;

// Where a score performance puts the drum for the default body
// (perform/performance.cpp, build_score: the midpoint of the shoulders, 0.42 m
// forward and 0.42 m down, PerformanceOptions' drum_forward_m and drum_below_m).
PerformerFrame default_body_frame()
{
    const Skeleton skeleton = default_skeleton();
    const CharacterModel model = CharacterModel::from_skeleton(skeleton);
    Motion motion;
    motion.frame_rate_hz = 100.0;
    motion.root_position_m.push_back(Eigen::Vector3d(0.0, 0.9, 0.0));
    motion.local_rotation.emplace_back(skeleton.joints.size(), Eigen::Quaterniond::Identity());
    BodyFrames frames;
    model.forward(model.pose_from_motion(motion, 0), frames);
    const Eigen::Vector3d l = frames.origin_m[model.body_index("l_upper_arm")];
    const Eigen::Vector3d r = frames.origin_m[model.body_index("r_upper_arm")];
    Eigen::Vector3d left = l - r;
    left.y() = 0.0;
    left.normalize();
    const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
    const Eigen::Vector3d centre = 0.5 * (l + r) + 0.42 * left.cross(up) - 0.42 * up;
    return performer_frame_for_drum(centre, 0.178);
}

void check_plan(const Score &score, const GesturePlan &plan, const PerformerFrame &frame,
                const PlanOptions &options)
{
    ICTUS_FUZZ_CHECK(plan.notes.size() == score.notes.size(), "not one planned note per note");
    ICTUS_FUZZ_CHECK(std::isfinite(plan.duration_s) && plan.duration_s > 0.0 &&
                         plan.duration_s <= options.max_duration_s,
                     "duration not in (0, max_duration_s]");
    const std::vector<double> &t = plan.tips.time_s;
    ICTUS_FUZZ_CHECK(!t.empty(), "no samples");
    for (std::size_t i = 1; i < t.size(); ++i)
        ICTUS_FUZZ_CHECK(t[i] > t[i - 1], "sample times not strictly increasing");
    ICTUS_FUZZ_CHECK(t.back() <= plan.duration_s + 1.0 / options.rate_hz + 1e-9,
                     "samples past the end");
    for (int s = 0; s < 2; ++s) {
        ICTUS_FUZZ_CHECK(plan.tips.tip_m[s].size() == t.size() &&
                             plan.stick_dir[s].size() == t.size(),
                         "tips or directions not one per sample");
        for (const Eigen::Vector3d &p : plan.tips.tip_m[s])
            ICTUS_FUZZ_CHECK(ictus_fuzz::finite(p) && (p - frame.membrane_center_m).norm() < 5.0,
                             "a tip not finite or metres away from the drum");
        for (const Eigen::Vector3d &d : plan.stick_dir[s])
            ICTUS_FUZZ_CHECK(d.allFinite() && std::fabs(d.norm() - 1.0) < 1e-6,
                             "a stick direction that is not a unit vector");
    }
    double previous = 0.0;
    for (const PlannedNote &n : plan.notes) {
        ICTUS_FUZZ_CHECK(std::isfinite(n.time_s) && n.time_s >= previous,
                         "planned notes not in time order");
        previous = n.time_s;
        ICTUS_FUZZ_CHECK(ictus_fuzz::finite(n.impact_velocity_mps), "impact velocity not finite");
        // One sample exactly at the strike, where the tip is on its target.
        const auto at = std::lower_bound(t.begin(), t.end(), n.time_s - 1e-9);
        ICTUS_FUZZ_CHECK(at != t.end() && std::fabs(*at - n.time_s) < 1e-9,
                         "no sample at a strike");
        const std::size_t i = static_cast<std::size_t>(at - t.begin());
        const Eigen::Vector3d &tip = plan.tips.tip_m[static_cast<int>(n.hand)][i];
        ICTUS_FUZZ_CHECK((tip - n.tip_target_m).norm() < 1e-6, "the tip misses its target");
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
    if (size > kMaxInputBytes)
        return -1; // not kept in the corpus
    static const GestureDatabase db = GestureDatabase::builtin();
    static const PerformerFrame frame = default_body_frame();
    Score score;
    try {
        score = parse_score(ictus_fuzz::text_of(data, size), "fuzz");
    } catch (const ScoreError &) {
        return 0; // fuzz_score's business
    }
    if (score.notes.size() > kMaxNotes)
        return 0;
    PlanOptions options;
    options.rate_hz = kRate_hz;
    options.max_duration_s = kMaxDuration_s;
    try {
        const GesturePlan plan = plan_performance(score, db, frame, options);
        check_plan(score, plan, frame, options);
    } catch (const ScoreError &e) {
        // A score of rests alone that lasts too long has no note to point at (line 0).
        ICTUS_FUZZ_CHECK(score.notes.empty() || (e.line() >= 1 && e.column() >= 1),
                         "a refusal without its position");
    }
    return 0;
}
