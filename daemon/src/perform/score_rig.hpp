// score_rig.hpp -- the body that performs a score (private to src/perform):
// the default character standing before the drum, its controller, and the
// trunk's part in the strokes (docs/perform.md, "The trunk").
#pragma once

#include "ictus/perform/performance.hpp"

#include <memory>
#include <vector>

namespace ictus
{

// The character, its controller and the drum of score mode, rebuilt together
// when the grip or the drum changes (a Scene has no setters for them).
struct ScoreRig {
    CharacterModel model;
    RangeOfMotion range_of_motion;    // the joint limits (declared before the tracker)
    RangeOfMotion ik_range_of_motion; // the same, narrowed: the arms' IK's
    std::vector<JointLimitRef> ik_limits = ik_range_of_motion.refs();
    int lumbar = model.joint_index("lumbar"), thorax = model.joint_index("thorax");
    std::vector<JointGains> base_gains, gains;
    std::unique_ptr<Tracker> tracker;
    CharacterPose body;      // the reference held by the trunk and legs (arms: IK)
    CharacterPose step_body; // body with the trunk's synergy of this step
    PerformerFrame frame;
    Eigen::Vector3d drum_center_m = Eigen::Vector3d::Zero(); // where the drum goes
    std::vector<DrumParams> kit_drums; // a kit's drums after the first, placed
    // The right foot's ankle over the floor (world, y 0), where a kit's foot
    // piece is placed from (KitDrum::foot); each ankle's axis of plantar
    // flexion in its shank's frame (the performer's left), [Side].
    Eigen::Vector3d right_sole_m = Eigen::Vector3d::Zero();
    std::array<Eigen::Vector3d, 2> shoulder_m{}; // [Side], world (PerformerFrame::shoulder_m)
    std::array<int, 2> ankle = {model.joint_index("l_ankle"), model.joint_index("r_ankle")};
    std::array<Eigen::Vector3d, 2> ankle_axis = {Eigen::Vector3d::UnitX(),
                                                 Eigen::Vector3d::UnitX()};
    TipTargets tips;
    // Each hand's tip target kReachLead_s ahead of this step, while a plan
    // plays (has_ahead): the trunk's reach turns toward the farther of it and
    // the target now (blended where the two are near: kReachBlend_m).
    std::array<Eigen::Vector3d, 2> ahead_m{};
    bool has_ahead = false;
    ScoreRig(const CharacterModel &m, double ik_limit_margin_rad)
        : model(m), range_of_motion(model), ik_range_of_motion(model, ik_limit_margin_rad)
    {
    }
    // The trunk takes part in the strokes: step_body is body with the lean
    // and twist that the tip targets of this step call for.
    void trunk_synergy();
    // A foot on its pedal (the right on the kick's, the left on the
    // hi-hat's): step_body's ankle of that side turned toe down by the
    // footboard's angle (rad; docs/pedal.md).
    void foot_on_pedal(Side side, double footboard_rad);

    // The trunk: eq. 1's natural frequency of the lumbar and thorax joints,
    // and how they follow the sticks.
    static constexpr double kTrunkHz = 8.0;
    static constexpr double kTrunkLean_rad_per_m = 0.15;
    static constexpr double kTrunkTwist_rad_per_m = 0.2;
    // A tip target further than kReachFrom_m from its shoulder in plan (the
    // right hand at the crash, the left at the ride): the trunk turns that
    // shoulder toward it, kReachTwist_rad_per_m times the excess times the
    // share of the shoulder's swing that points at the target, and leans
    // toward it, kReachLean_rad_per_m times the excess (docs/perform.md). The
    // reach takes the farther of the target now and kReachLead_s ahead (the
    // trunk turns before the hand sets off across the kit), the two blended
    // while their lengths differ by less than half of kReachBlend_m.
    static constexpr double kReachFrom_m = 0.85;
    static constexpr double kReachLead_s = 0.03;
    static constexpr double kReachBlend_m = 0.04;
    static constexpr double kReachTwist_rad_per_m = 6.0;
    static constexpr double kReachLean_rad_per_m = 3.0;

    // On a throne (a kit with a foot piece, docs/kit.md "The throne"): the
    // hips this much lower than standing, and the ankles' places (right, up,
    // forward from the pelvis over the floor, m): the right foot on the
    // kick's pedal, the left on the hi-hat's, the feet level.
    static constexpr double kThroneDrop_m = 0.15;
    static inline const Eigen::Vector3d kRightAnkleSeated_m{0.26, 0.08, 0.445};
    static inline const Eigen::Vector3d kLeftAnkleSeated_m{-0.36, 0.08, 0.17};
};

// The standing default body (its legs straight, the identity pose) seated on
// a throne: the pelvis lowered by ScoreRig::kThroneDrop_m, each knee placed
// between its hip and its seated ankle (bent forward and a little out, a
// hinge), the feet as level as the ankles' ranges in rom allow.
void sit_on_throne(const CharacterModel &model, const RangeOfMotion &rom, CharacterPose &pose);

// The default body (stick_capture.hpp), standing with the hips 0.9 m up
// (seated on a throne with a kit that has a foot piece), pelvis welded, facing +Z, in `pose` (joint
// rotations) or with the arms solved to hold the sticks at the rest tips. Reads only `options`.
std::unique_ptr<ScoreRig> make_score_rig(const PerformanceOptions &options,
                                         const std::vector<Eigen::Quaterniond> *pose);

// The plan's frame for a drum: the shared frames of docs/perform.md, facing
// `forward` with `right` to the performer's right, the membrane raised by the
// tip's contact height.
// With a kit, the frame's drums (PerformerFrame::drums): `drum` first, then
// `kit_drums`, named as the kit's, each raised so; a foot piece (the kick)
// at its place from `right_sole_m` (ScoreRig::right_sole_m); the shoulders
// (ScoreRig::shoulder_m) when given.
PerformerFrame frame_for(const DrumParams &drum, double tip_radius_m, const Eigen::Vector3d &right,
                         const Eigen::Vector3d &forward, const Kit *kit = nullptr,
                         const std::vector<DrumParams> *kit_drums = nullptr,
                         const Eigen::Vector3d &right_sole_m = Eigen::Vector3d::Zero(),
                         const std::array<Eigen::Vector3d, 2> *shoulder_m = nullptr);

} // namespace ictus
