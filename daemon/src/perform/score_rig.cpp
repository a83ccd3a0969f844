// The body that performs a score (score_rig.hpp).
#include "score_rig.hpp"

#include "ictus/character/stick_capture.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace ictus
{

namespace
{
// The stick-tip sits this far above the membrane plane when its bead touches
// it: the bead's centre is one tip radius above, the end point a further
// r * (stick axis . up) (the stick points down at the head, so less than 2 r).
// The plan's strike points are raised by it, so that the planned tip target
// on the beat is the tip at first contact (strike_depth_m is then measured
// from the contact, not from the plane).
double contact_height_m(double tip_radius_m, const Eigen::Vector3d &stick_dir_world)
{
    return tip_radius_m * (1.0 + stick_dir_world.normalized().y());
}

// The knee of a leg from its hip H to its ankle A (thigh l1, shank l2): on
// the circle where the two segments meet, toward `pole` (the knee's side).
Eigen::Vector3d knee_between(const Eigen::Vector3d &h, const Eigen::Vector3d &a, double l1,
                             double l2, const Eigen::Vector3d &pole)
{
    const Eigen::Vector3d ha = a - h;
    const double d = std::clamp(ha.norm(), std::abs(l1 - l2) + 1e-6, l1 + l2 - 1e-6);
    const Eigen::Vector3d u = ha.normalized();
    const double along = (l1 * l1 - l2 * l2 + d * d) / (2.0 * d);
    const double off = std::sqrt(std::max(0.0, l1 * l1 - along * along));
    const Eigen::Vector3d side = (pole - pole.dot(u) * u).normalized();
    return h + along * u + off * side;
}
} // namespace

void sit_on_throne(const CharacterModel &model, const RangeOfMotion &rom, CharacterPose &pose)
{
    pose.pelvis_position_m.y() -= ScoreRig::kThroneDrop_m;
    BodyFrames frames;
    model.forward(pose, frames);
    const Eigen::Vector3d up = Eigen::Vector3d::UnitY(), forward = Eigen::Vector3d::UnitZ();
    for (const char *s : {"l_", "r_"}) {
        const std::string side(s);
        const double out = side == "l_" ? 1.0 : -1.0; // the performer's left is +X (world)
        const int thigh = model.body_index(side + "thigh"),
                  shank = model.body_index(side + "shank"), foot = model.body_index(side + "foot");
        const Eigen::Vector3d h = frames.origin_m[thigh], k0 = frames.origin_m[shank],
                              a0 = frames.origin_m[foot];
        // The ankle's place (right, up, forward from the pelvis over the
        // floor) in the world: facing +Z, the performer's right is -X.
        const Eigen::Vector3d &seat =
            side == "l_" ? ScoreRig::kLeftAnkleSeated_m : ScoreRig::kRightAnkleSeated_m;
        const Eigen::Vector3d a(pose.pelvis_position_m.x() - seat.x(), seat.y(),
                                pose.pelvis_position_m.z() + seat.z());
        const Eigen::Vector3d k =
            knee_between(h, a, (k0 - h).norm(), (a0 - k0).norm(),
                         forward + 0.6 * out * Eigen::Vector3d::UnitX() + 0.5 * up);
        // World rotations of the thigh and shank that carry the standing
        // segments onto the seated ones, the knee a hinge: the thigh turned
        // so that the knee's flexion axis (its range's u, in the thigh's
        // frame) stands normal to the leg's plane (hip, knee, ankle), the
        // shank then flexed about it alone, within the knee's range.
        const Eigen::Vector3d hinge0 =
            frames.rotation[thigh] * rom.limit(model.joint_index(side + "knee")).u;
        const Eigen::Vector3d t0 = (k0 - h).normalized(), t1 = (k - h).normalized();
        const Eigen::Vector3d n1 = t1.cross(a - k).normalized();
        Eigen::Matrix3d from, to;
        from.col(0) = t0;
        from.col(1) = (hinge0 - hinge0.dot(t0) * t0).normalized();
        from.col(2) = from.col(0).cross(from.col(1));
        to.col(0) = t1;
        to.col(1) = n1;
        to.col(2) = t1.cross(n1);
        const Eigen::Quaterniond rt(to * from.transpose());
        const Eigen::Vector3d sv = rt * (a0 - k0), sw = a - k;
        const Eigen::Vector3d pv = sv - sv.dot(n1) * n1, pw = sw - sw.dot(n1) * n1;
        const double flex = std::atan2(pv.cross(pw).dot(n1), pv.dot(pw));
        const Eigen::Quaterniond rs = Eigen::Quaterniond(Eigen::AngleAxisd(flex, n1)) * rt;
        const Eigen::Quaterniond p = pose.pelvis_rotation;
        pose.local[model.joint_index(side + "hip")] = p.conjugate() * rt * p;
        pose.local[model.joint_index(side + "knee")] = p.conjugate() * rt.conjugate() * rs * p;
        // The foot as level as the ankle's range lets it (the left one, under
        // a knee turned out, rolls 6.5 degrees): the scene's limits would
        // clamp it there anyway.
        const int ankle = model.joint_index(side + "ankle");
        pose.local[ankle] = rom.limit(ankle).clamp(p.conjugate() * rs.conjugate() * p);
    }
}

PerformerFrame frame_for(const DrumParams &drum, double tip_radius_m, const Eigen::Vector3d &right,
                         const Eigen::Vector3d &forward, const Kit *kit,
                         const std::vector<DrumParams> *kit_drums,
                         const Eigen::Vector3d &right_sole_m,
                         const std::array<Eigen::Vector3d, 2> *shoulder_m)
{
    const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
    const Eigen::Vector3d raise = contact_height_m(tip_radius_m, kDefaultStickDirection) * up;
    PerformerFrame f = performer_frame_for_drum(drum.center_m + raise, drum.radius_m);
    f.right = right;
    f.forward = forward;
    if (shoulder_m)
        f.shoulder_m = *shoulder_m;
    if (kit && !kit->empty()) {
        // The rest tips before the kit's anchor (where the one drum goes),
        // not its first drum, which may stand to a side (two timpani).
        const Eigen::Vector3d &p0 = kit->drums.front().place_m;
        const Eigen::Vector3d anchor = drum.center_m - p0.x() * right - p0.y() * up - p0.z() * forward;
        f.rest_tip_m = performer_frame_for_drum(anchor + raise, drum.radius_m).rest_tip_m;
        for (size_t i = 0; i < kit->drums.size(); ++i) {
            const KitDrum &k = kit->drums[i];
            if (k.foot) { // not in the scene: its upright head's centre from the right foot
                const Eigen::Vector3d c = right_sole_m + k.place_m.x() * right +
                                          k.place_m.y() * up + k.place_m.z() * forward;
                f.drums.push_back({k.name, c, k.radius_m, false, false, true});
                continue;
            }
            const DrumParams &d =
                i == 0 || !kit_drums || i - 1 >= kit_drums->size() ? drum : (*kit_drums)[i - 1];
            f.drums.push_back(
                {k.name, d.center_m + raise, d.radius_m, k.cymbal(), kit_drum_has_pedal(k)});
        }
    }
    return f;
}

std::unique_ptr<ScoreRig> make_score_rig(const PerformanceOptions &options,
                                         const std::vector<Eigen::Quaterniond> *pose)
{
    const Skeleton skeleton = default_skeleton();
    Motion motion;
    motion.frame_rate_hz = 100.0;
    motion.root_position_m.push_back(Eigen::Vector3d(0.0, 0.9, 0.0));
    motion.local_rotation.emplace_back(skeleton.joints.size(), Eigen::Quaterniond::Identity());
    const CharacterModel model = CharacterModel::from_skeleton(skeleton, options.character);
    auto rig = std::make_unique<ScoreRig>(model, options.score.ik_limit_margin_deg * M_PI / 180.0);
    ScoreRig &r = *rig;
    r.body = model.pose_from_motion(motion, 0);
    if (kit_foot_piece(options.kit) >= 0)
        sit_on_throne(model, r.range_of_motion, r.body);

    // The drum in front of the performer: from the midpoint of the shoulders,
    // drum_forward_m along the facing direction and drum_below_m down, unless
    // a centre was given.
    BodyFrames frames;
    model.forward(r.body, frames);
    const Eigen::Vector3d shoulder[2] = {frames.origin_m[model.body_index("l_upper_arm")],
                                         frames.origin_m[model.body_index("r_upper_arm")]};
    Eigen::Vector3d left = shoulder[0] - shoulder[1];
    left.y() = 0.0;
    left.normalize();
    const Eigen::Vector3d up = Eigen::Vector3d::UnitY();
    const Eigen::Vector3d forward = left.cross(up);
    SceneOptions scene = options.scene;
    // A joint pushed outside its range of motion (the stick's reactions on the
    // wrist) meets its stop 1 degree out, which takes the whole overshoot
    // back in one step (docs/perform.md, "Joint limits").
    scene.stop_margin_rad = std::min(scene.stop_margin_rad, 1.0 * M_PI / 180.0);
    scene.stop_erp = 1.0;
    scene.stop_inelastic = true;
    // The legs hang off the welded pelvis and hold no stick: placed at their
    // targets, not simulated (SceneOptions::legs_kinematic, docs/perform.md).
    scene.legs_kinematic = true;
    scene.pelvis_kinematic = true; // welded: fixed, without the weld's rows
    if (options.drum_auto)
        scene.drum.center_m = 0.5 * (shoulder[0] + shoulder[1]) +
                              options.score.drum_forward_m * forward -
                              options.score.drum_below_m * up;
    if (!options.kit.empty()) {
        // The kit from its anchor, in the performer's frame: the automatic
        // drum's place, or (a given or live centre) the first drum's centre
        // less its place.
        const Eigen::Vector3d &p0 = options.kit.drums.front().place_m;
        const Eigen::Vector3d anchor =
            options.drum_auto ? scene.drum.center_m
                              : Eigen::Vector3d(scene.drum.center_m + p0.x() * left -
                                                p0.y() * up - p0.z() * forward);
        const std::vector<DrumParams> placed =
            place_kit(options.kit, scene.drum, anchor, -left, up, forward);
        scene.drum = placed.front();
        scene.extra_drums.assign(placed.begin() + 1, placed.end());
        r.kit_drums = scene.extra_drums;
    }
    r.drum_center_m = scene.drum.center_m;
    // The right ankle over the floor, and each ankle's axis of plantar
    // flexion (the performer's left) in its shank's frame.
    r.right_sole_m = frames.origin_m[model.body_index("r_foot")];
    r.right_sole_m.y() = 0.0;
    for (Side side : {Side::left, Side::right})
        r.ankle_axis[static_cast<size_t>(side)] =
            (frames.rotation[model.body_index(side == Side::left ? "l_shank" : "r_shank")]
                 .conjugate() *
             left)
                .normalized();
    r.shoulder_m = {shoulder[0], shoulder[1]};
    r.frame = frame_for(scene.drum, options.character.stick.tip_radius_m, -left, forward,
                        &options.kit, &r.kit_drums, r.right_sole_m, &r.shoulder_m);

    // Start: the arms solved to hold the sticks at the rest tips (or the
    // pose the old rig was in, when a grip change rebuilds it).
    CharacterPose initial = r.body;
    if (pose && pose->size() == initial.local.size())
        initial.local = *pose;
    else {
        const std::array<Eigen::Vector3d, 2> directions = {rest_stick_direction(r.frame, 0),
                                                           rest_stick_direction(r.frame, 1)};
        Tracker::solve_arms(model, r.ik_limits, options.score.cartesian.ik, r.frame.rest_tip_m,
                            initial, &directions);
    }
    r.base_gains = default_gains(model, initial, options.gains);
    // The trunk is compliant: lumbar and thorax under eq. 1 at kTrunkHz (the
    // arms' natural frequency is options.gains'), so they sway under the arms'
    // reactions (docs/perform.md, "The trunk").
    const double trunk_ratio = ScoreRig::kTrunkHz / options.gains.natural_frequency_hz;
    if (trunk_ratio < 1.0)
        for (int j : {r.lumbar, r.thorax}) {
            r.base_gains[j].kp_nm_per_rad *= trunk_ratio * trunk_ratio;
            r.base_gains[j].kd_nm_s_per_rad *= trunk_ratio;
        }
    r.step_body = r.body;
    r.gains = r.base_gains; // scaled when installed
    CartesianOptions co = options.score.cartesian;
    co.reference_has_arms = false; // the body's reference has no arm motion
    r.tracker =
        std::make_unique<Tracker>(r.model, scene, initial, r.gains, r.range_of_motion.refs(),
                                  options.score.mode, co, options.gains, &r.ik_limits);
    r.tips.has_position = true;
    for (int s = 0; s < 2; ++s)
        r.tips.position_m[s] = r.tracker->scene().tip_position(static_cast<Side>(s));
    return rig;
}

// The trunk leans forward as the sticks go
// down (kTrunkLean_rad_per_m of the mean tip target's drop below the rest
// tips) and turns the shoulder of the higher stick back (kTrunkTwist_rad_per_m
// of the difference of the tips' heights), 40 % at the lumbar joint and 60 %
// at the thorax; eq. 1 then follows it with the trunk's compliant gains.
void ScoreRig::foot_on_pedal(Side side, double footboard_rad)
{
    // The axis is in the shank's (the joint's parent's) frame, so the turn
    // comes before the ankle's own rotation.
    const int s = static_cast<int>(side);
    const int j = ankle[static_cast<size_t>(s)];
    step_body.local[j] =
        Eigen::Quaterniond(Eigen::AngleAxisd(footboard_rad, ankle_axis[static_cast<size_t>(s)])) *
        body.local[j];
}

void ScoreRig::trunk_synergy()
{
    ScoreRig &r = *this;
    const PerformerFrame &f = r.frame;
    const TipTargets &tips = r.tips;
    auto height = [&](int s) { return (tips.position_m[s] - f.membrane_center_m).dot(f.up); };
    const double rest = 0.5 * ((f.rest_tip_m[0] - f.membrane_center_m).dot(f.up) +
                               (f.rest_tip_m[1] - f.membrane_center_m).dot(f.up));
    const int right = static_cast<int>(Side::right), left = static_cast<int>(Side::left);
    const double lean = kTrunkLean_rad_per_m * (rest - 0.5 * (height(left) + height(right)));
    double twist = -kTrunkTwist_rad_per_m * (height(right) - height(left));
    // Reaching far: each shoulder toward its tip target.
    const Eigen::Vector3d mid = 0.5 * (r.shoulder_m[0] + r.shoulder_m[1]);
    auto in_plan = [&](const Eigen::Vector3d &p, int s) {
        const Eigen::Vector3d to = p - r.shoulder_m[s];
        return Eigen::Vector3d(to - to.dot(f.up) * f.up);
    };
    // One hand's reach toward `to` (in plan, from its shoulder): the twist it
    // adds and the lean's rotation vector; none within kReachFrom_m.
    struct Reach {
        double twist = 0.0;
        Eigen::Vector3d lean = Eigen::Vector3d::Zero();
    };
    auto reach_to = [&](const Eigen::Vector3d &to, int s) {
        Reach out;
        const double excess = to.norm() - kReachFrom_m;
        if (!(excess > 0.0))
            return out;
        const Eigen::Vector3d dir = to.normalized();
        const Eigen::Vector3d swing = f.up.cross(r.shoulder_m[s] - mid).normalized();
        out.twist = kReachTwist_rad_per_m * excess * dir.dot(swing);
        out.lean = kReachLean_rad_per_m * excess * f.up.cross(dir).normalized();
        return out;
    };
    Eigen::Quaterniond reach = Eigen::Quaterniond::Identity();
    for (int s = 0; s < 2; ++s) {
        const Eigen::Vector3d now = in_plan(tips.position_m[s], s);
        Reach hand = reach_to(now, s);
        if (r.has_ahead) {
            // The farther of the two, blended across kReachBlend_m of their
            // difference in length, so that the trunk's targets do not jump
            // when the two cross.
            const Eigen::Vector3d ahead = in_plan(r.ahead_m[s], s);
            // (smoothstep takes a NaN for 0: the target now.)
            const double w = smoothstep(0.5 + (ahead.norm() - now.norm()) / kReachBlend_m);
            const Reach far = reach_to(ahead, s);
            hand.twist += w * (far.twist - hand.twist);
            hand.lean += w * (far.lean - hand.lean);
        }
        twist += hand.twist;
        const double lean_rad = hand.lean.norm();
        if (lean_rad > 0.0)
            reach = reach * Eigen::Quaterniond(Eigen::AngleAxisd(lean_rad, hand.lean / lean_rad));
    }
    // Lean about the performer's left axis (forward flexion), twist about up.
    const Eigen::Vector3d left_axis = -f.right;
    const Eigen::Quaterniond q = reach * Eigen::Quaterniond(Eigen::AngleAxisd(twist, f.up)) *
                                 Eigen::Quaterniond(Eigen::AngleAxisd(lean, left_axis));
    const Eigen::Quaterniond part = Eigen::Quaterniond::Identity().slerp(0.4, q);
    r.step_body.local[r.lumbar] = r.body.local[r.lumbar] * part;
    r.step_body.local[r.thorax] = r.body.local[r.thorax] * part.conjugate() * q;
}

} // namespace ictus
