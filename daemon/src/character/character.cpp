// The character model: CMU skeleton -> 19 ball joints, de Leva masses, sticks.
#include "ictus/character/character.hpp"
#include "ictus/character/anthropometry.hpp"
#include "ictus/base/rotation.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>

namespace ictus
{

const char *to_string(Grip grip)
{
    return grip == Grip::french ? "french" : "german";
}

Grip grip_from_string(const std::string &text)
{
    std::string lower = text;
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (lower == "french")
        return Grip::french;
    if (lower == "german")
        return Grip::german;
    throw CharacterError("grip: expected french or german, got '" + text + "'");
}

namespace
{

// How a body's mass and inertia are taken from the table.
enum class MassRule {
    table,          // the de Leva row as is, CoM from the proximal joint
    table_reversed, // CoM fraction measured from the distal (cranial) end
    share,          // a given fraction of body mass, CoM at mid-segment
};

struct MapRow {
    const char *body;
    const char *joint;
    const char *source; // mocap joint (the body frame)
    int parent;         // body index
    const char *distal; // mocap joint, or "X/end" for X's end site
    DeLevaSegment segment;
    MassRule rule;
    double mass_fraction; // for MassRule::share, or the table row's share used
};

// de Leva has no clavicle and treats head+neck as one segment: the clavicles
// (shoulder girdle) take 1 % of body mass each out of the upper trunk, and the
// two neck segments 0.8 % each out of the head+neck segment. The pelvis (LPT)
// is anchored, its mass only matters for the record.
constexpr double kClavicleShare = 0.010;
constexpr double kNeckShare = 0.008;

const MapRow kMap[CharacterModel::kBodies] = {
    {"pelvis", "", "Hips", -1, "LowerBack", DeLevaSegment::lower_trunk, MassRule::table_reversed,
     0},
    {"abdomen", "lumbar", "LowerBack", 0, "Spine", DeLevaSegment::middle_trunk,
     MassRule::table_reversed, 0},
    {"thorax", "thorax", "Spine", 1, "Spine1", DeLevaSegment::upper_trunk, MassRule::table_reversed,
     0.1596 - 2 * kClavicleShare},
    {"neck", "neck", "Neck", 2, "Neck1", DeLevaSegment::head, MassRule::share, kNeckShare},
    {"upper_neck", "upper_neck", "Neck1", 3, "Head", DeLevaSegment::head, MassRule::share,
     kNeckShare},
    {"head", "head", "Head", 4, "Head/end", DeLevaSegment::head, MassRule::table_reversed,
     0.0694 - 2 * kNeckShare},
    {"l_clavicle", "l_clavicle", "LeftShoulder", 2, "LeftArm", DeLevaSegment::upper_trunk,
     MassRule::share, kClavicleShare},
    {"l_upper_arm", "l_shoulder", "LeftArm", 6, "LeftForeArm", DeLevaSegment::upper_arm,
     MassRule::table, 0},
    {"l_forearm", "l_elbow", "LeftForeArm", 7, "LeftHand", DeLevaSegment::forearm, MassRule::table,
     0},
    {"l_hand", "l_wrist", "LeftHand", 8, "LeftHandIndex1", DeLevaSegment::hand, MassRule::table, 0},
    {"r_clavicle", "r_clavicle", "RightShoulder", 2, "RightArm", DeLevaSegment::upper_trunk,
     MassRule::share, kClavicleShare},
    {"r_upper_arm", "r_shoulder", "RightArm", 10, "RightForeArm", DeLevaSegment::upper_arm,
     MassRule::table, 0},
    {"r_forearm", "r_elbow", "RightForeArm", 11, "RightHand", DeLevaSegment::forearm,
     MassRule::table, 0},
    {"r_hand", "r_wrist", "RightHand", 12, "RightHandIndex1", DeLevaSegment::hand, MassRule::table,
     0},
    {"l_thigh", "l_hip", "LeftUpLeg", 0, "LeftLeg", DeLevaSegment::thigh, MassRule::table, 0},
    {"l_shank", "l_knee", "LeftLeg", 14, "LeftFoot", DeLevaSegment::shank, MassRule::table, 0},
    {"l_foot", "l_ankle", "LeftFoot", 15, "LeftToeBase/end", DeLevaSegment::foot, MassRule::table,
     0},
    {"r_thigh", "r_hip", "RightUpLeg", 0, "RightLeg", DeLevaSegment::thigh, MassRule::table, 0},
    {"r_shank", "r_knee", "RightLeg", 17, "RightFoot", DeLevaSegment::shank, MassRule::table, 0},
    {"r_foot", "r_ankle", "RightFoot", 18, "RightToeBase/end", DeLevaSegment::foot, MassRule::table,
     0},
};

bool finite_positive(double v)
{
    return std::isfinite(v) && v > 0.0;
}

// The four limbs: their inertia scales with their captured length.
bool is_limb(DeLevaSegment segment)
{
    return segment == DeLevaSegment::upper_arm || segment == DeLevaSegment::forearm ||
           segment == DeLevaSegment::thigh || segment == DeLevaSegment::shank;
}

// Where a joint's OFFSET was read ("FILE:LINE", "FILE", or "skeleton").
std::string offset_place(const Skeleton &skeleton, int joint)
{
    if (skeleton.source.empty())
        return "skeleton";
    const int line = skeleton.joints[joint].offset_line;
    return line > 0 ? skeleton.source + ":" + std::to_string(line) : skeleton.source;
}

std::string fmt(double v)
{
    std::ostringstream s;
    s << v;
    return s.str();
}

// The mocap joint `name`, or for "X/end" the first end site below X.
int find_joint(const Skeleton &skeleton, const std::string &name)
{
    const auto slash = name.find("/end");
    if (slash == std::string::npos) {
        const int j = skeleton.find(name);
        if (j < 0)
            throw CharacterError(
                (skeleton.source.empty() ? std::string("skeleton") : skeleton.source) +
                ": no joint named '" + name +
                "' (the character expects CMU joint names, see docs/character.md)");
        return j;
    }
    const int parent = find_joint(skeleton, name.substr(0, slash));
    for (int j = 0; j < static_cast<int>(skeleton.joints.size()); ++j)
        if (skeleton.joints[j].parent == parent && skeleton.joints[j].end_site)
            return j;
    throw CharacterError("skeleton: joint '" + name.substr(0, slash) + "' has no end site");
}

// The distal end of a row's body. A hand without fingers or a foot without
// toes (a skeleton exported without them) ends at its own joint's End Site:
// their inertia comes from de Leva's lengths, the skeleton only gives their
// direction (and the grip's place along the hand). Else the CMU joint is
// required, and its absence named.
int find_distal(const Skeleton &skeleton, const MapRow &row)
{
    try {
        return find_joint(skeleton, row.distal);
    } catch (const CharacterError &) {
        if (row.segment != DeLevaSegment::hand && row.segment != DeLevaSegment::foot)
            throw;
        const int own = skeleton.find(row.source);
        for (int j = 0; j < static_cast<int>(skeleton.joints.size()); ++j)
            if (skeleton.joints[j].parent == own && skeleton.joints[j].end_site)
                return j;
        throw;
    }
}

// Mocap joints from `ancestor` (exclusive) down to `joint` (inclusive), parent-most first.
std::vector<int> path_between(const Skeleton &skeleton, int ancestor, int joint)
{
    std::vector<int> path;
    for (int j = joint; j != ancestor; j = skeleton.joints[j].parent) {
        if (j < 0)
            throw CharacterError("skeleton: joint '" + skeleton.joints[joint].name +
                                 "' is not below '" + skeleton.joints[ancestor].name + "'");
        path.push_back(j);
    }
    std::reverse(path.begin(), path.end());
    return path;
}

// Rest-pose offset along a path: the sum of OFFSETs (exact when the rotations
// of joints with zero-length children are all that the path composes, as in
// the CMU files; see docs/character.md).
Eigen::Vector3d rest_offset(const Skeleton &skeleton, const std::vector<int> &path)
{
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (int j : path)
        sum += skeleton.joints[j].offset_m;
    return sum;
}

// Principal inertia of a segment: radii of gyration (fractions of length_m)
// about the antero-posterior axis (sagittal), the remaining one (transverse)
// and the long axis. The character faces +z with y up at rest (CMU).
Eigen::Matrix3d segment_inertia(double mass_kg, double length_m, const Eigen::Vector3d &long_dir,
                                const SegmentParameters &row)
{
    Eigen::Vector3d u = long_dir.norm() > 1e-9 ? long_dir.normalized() : Eigen::Vector3d::UnitY();
    Eigen::Vector3d ap = Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ().dot(u) * u;
    if (ap.norm() < 0.3)
        ap = Eigen::Vector3d::UnitX() - Eigen::Vector3d::UnitX().dot(u) * u;
    ap.normalize();
    const Eigen::Vector3d other = u.cross(ap);
    const double l2 = length_m * length_m;
    return mass_kg * l2 *
           (row.radius_sagittal * row.radius_sagittal * ap * ap.transpose() +
            row.radius_transverse * row.radius_transverse * other * other.transpose() +
            row.radius_long * row.radius_long * u * u.transpose());
}

Eigen::Matrix3d parallel_axis(double mass_kg, const Eigen::Vector3d &d)
{
    return mass_kg * (d.squaredNorm() * Eigen::Matrix3d::Identity() - d * d.transpose());
}

// One stretch of the skeleton a body is built from (the mocap joints of
// `path`, their OFFSETs summed) against the bounds of a human body: at most
// kMaxSegmentLength_m, and for a limb at least kMinLimbLength_m. The error
// names the joint whose OFFSET is at fault and its line in the file: the
// longest OFFSET of a stretch too long, the last one of a stretch too short.
// `what`: "the l_forearm segment to be", "the l_hip joint's distance ... to be".
void check_segment(const Skeleton &skeleton, const std::vector<int> &path, bool limb,
                   const std::string &what)
{
    if (path.empty())
        return; // no stretch between a joint and itself
    const double length = rest_offset(skeleton, path).norm();
    const bool too_short = limb && !(length >= kMinLimbLength_m);
    const bool too_long = !(length <= kMaxSegmentLength_m);
    if (!too_short && !too_long)
        return;
    int joint = path.back();
    if (too_long && !too_short)
        for (int j : path)
            if (skeleton.joints[j].offset_m.norm() > skeleton.joints[joint].offset_m.norm())
                joint = j;
    const std::string bounds =
        limb ? fmt(kMinLimbLength_m) + " to " + fmt(kMaxSegmentLength_m) + " m (a human limb)"
             : "at most " + fmt(kMaxSegmentLength_m) + " m (a human body)";
    const std::string summed = path.size() > 1
                                   ? ", the OFFSETs of " + skeleton.joints[path.front()].name +
                                         " .. " + skeleton.joints[path.back()].name + " summed"
                                   : "";
    throw CharacterError(offset_place(skeleton, joint) + ": joint '" + skeleton.joints[joint].name +
                         "': expected " + what + " " + bounds + ", got " + fmt(length) +
                         " m (its OFFSET" + summed + "; check the scale, --scale)");
}

void check_segment_lengths(const Skeleton &skeleton, const std::vector<int> &source,
                           const std::vector<int> &distal)
{
    for (int b = 0; b < CharacterModel::kBodies; ++b) {
        const MapRow &row = kMap[b];
        check_segment(skeleton, path_between(skeleton, source[b], distal[b]), is_limb(row.segment),
                      std::string("the ") + row.body + " segment to be");
        if (row.parent >= 0)
            check_segment(skeleton, path_between(skeleton, source[row.parent], source[b]), false,
                          std::string("the ") + row.joint +
                              " joint's distance from its parent to be");
    }
}

// ODE refuses (dMassCheck: it aborts the process) a body whose mass is not
// positive or whose inertia is not positive definite. The length bounds keep
// a skeleton from building one; this is the guard for anything else.
void check_mass(const std::string &body, double mass_kg, const Eigen::Vector3d &com_m,
                const Eigen::Matrix3d &inertia_kg_m2)
{
    if (!finite_positive(mass_kg) || !com_m.allFinite() || !inertia_kg_m2.allFinite())
        throw CharacterError("body '" + body + "': expected a finite mass > 0 and a finite " +
                             "centre of mass and inertia, got mass " + fmt(mass_kg) + " kg");
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(inertia_kg_m2,
                                                                Eigen::EigenvaluesOnly);
    const Eigen::Vector3d moments = solver.eigenvalues(); // ascending
    const double asymmetry = (inertia_kg_m2 - inertia_kg_m2.transpose()).cwiseAbs().maxCoeff();
    if (!(moments[0] > 1e-12 * moments[2]) || !(moments[0] > 0.0) || asymmetry > 1e-9 * moments[2])
        throw CharacterError("body '" + body +
                             "': expected a symmetric, positive-definite inertia, got principal "
                             "moments " +
                             fmt(moments[0]) + ", " + fmt(moments[1]) + ", " + fmt(moments[2]) +
                             " kg m^2 (a degenerate segment)");
}

} // namespace

namespace
{

void check_options(const CharacterOptions &options)
{
    const StickParams &s = options.stick;
    if (!finite_positive(options.body_mass_kg) || options.body_mass_kg > 500.0)
        throw CharacterError("body mass: expected 0 < kg <= 500, got " + fmt(options.body_mass_kg));
    if (!finite_positive(s.length_m) || s.length_m > 2.0)
        throw CharacterError("stick length: expected 0 < m <= 2, got " + fmt(s.length_m));
    if (!finite_positive(s.mass_kg) || s.mass_kg > 2.0)
        throw CharacterError("stick mass: expected 0 < kg <= 2, got " + fmt(s.mass_kg));
    if (!finite_positive(s.tip_radius_m) || s.tip_radius_m * 2.0 >= s.length_m)
        throw CharacterError("stick tip radius: expected 0 < m < length/2, got " +
                             fmt(s.tip_radius_m));
    if (!finite_positive(s.shaft_radius_m) || s.shaft_radius_m * 2.0 >= s.length_m)
        throw CharacterError("stick shaft radius: expected 0 < m < length/2, got " +
                             fmt(s.shaft_radius_m));
    if (!(s.grip_from_butt_m >= 0.0) || s.grip_from_butt_m >= s.length_m)
        throw CharacterError("stick grip point: expected 0 <= m < length, got " +
                             fmt(s.grip_from_butt_m));
    if (!std::isfinite(s.grip_angle_rad) || std::fabs(s.grip_angle_rad) > 1.5708)
        throw CharacterError("stick grip angle: expected |rad| <= pi/2, got " +
                             fmt(s.grip_angle_rad));
}

// Inertia lengths: limbs use their mocap lengths; segments whose mocap
// length does not span the anatomical segment (trunk, head, hand, foot)
// use de Leva's mean length scaled by the subject's limb proportions: this ratio.
double limb_size_ratio(const Skeleton &skeleton, const std::vector<int> &source,
                       const std::vector<int> &distal)
{
    double ratio_sum = 0.0;
    int ratio_n = 0;
    for (int b = 0; b < CharacterModel::kBodies; ++b) {
        const DeLevaSegment seg = kMap[b].segment;
        if (is_limb(seg)) {
            const double l =
                rest_offset(skeleton, path_between(skeleton, source[b], distal[b])).norm();
            ratio_sum += l / de_leva_male(seg).length_m;
            ++ratio_n;
        }
    }
    const double size_ratio = ratio_n > 0 ? ratio_sum / ratio_n : 1.0;
    if (!finite_positive(size_ratio))
        throw CharacterError("skeleton: limb lengths are zero (check --scale)");
    return size_ratio;
}

// Body b of kMap: its place in the skeleton, its mass, centre of mass and inertia.
void build_body(const Skeleton &skeleton, const std::vector<int> &source,
                const std::vector<int> &distal, int b, double size_ratio, double body_mass_kg,
                BodySpec &body)
{
    const MapRow &row = kMap[b];
    body.name = row.body;
    body.joint_name = row.joint;
    body.source = row.source;
    body.parent = row.parent;
    if (b > 0) {
        body.source_path = path_between(skeleton, source[row.parent], source[b]);
        body.offset_m = rest_offset(skeleton, body.source_path);
    } else {
        body.source_path = {source[0]};
    }
    body.distal_m = rest_offset(skeleton, path_between(skeleton, source[b], distal[b]));
    body.length_m = body.distal_m.norm();

    const SegmentParameters &table = de_leva_male(row.segment);
    const double inertia_length =
        is_limb(row.segment) ? body.length_m : table.length_m * size_ratio;
    double fraction = table.mass_fraction;
    if (row.mass_fraction > 0.0)
        fraction = row.mass_fraction;
    body.mass_kg = fraction * body_mass_kg;
    switch (row.rule) {
    case MassRule::table:
        body.com_m = table.com_fraction * body.distal_m;
        break;
    case MassRule::table_reversed:
        body.com_m = (1.0 - table.com_fraction) * body.distal_m;
        break;
    case MassRule::share:
        body.com_m = 0.5 * body.distal_m;
        break;
    }
    // Shares carved out of a table segment keep that segment's radii of
    // gyration relative to their own (mocap) length.
    const double len = row.rule == MassRule::share ? std::max(body.length_m, 0.02) : inertia_length;
    body.inertia_kg_m2 = segment_inertia(body.mass_kg, len, body.distal_m, table);
}

// The direction of the hand's thumb at rest, across the fingers `f`: towards the
// thumb's end site when the skeleton has one, else what is left of +z.
Eigen::Vector3d thumb_direction(const Skeleton &skeleton, int side, int hand_joint,
                                const Eigen::Vector3d &f)
{
    Eigen::Vector3d t = Eigen::Vector3d::UnitZ();
    const int thumb = skeleton.find(side == 0 ? "LThumb" : "RThumb");
    if (thumb >= 0) {
        try {
            const int thumb_end =
                find_joint(skeleton, std::string(side == 0 ? "LThumb" : "RThumb") + "/end");
            const Eigen::Vector3d d =
                rest_offset(skeleton, path_between(skeleton, hand_joint, thumb_end));
            if (d.norm() > 1e-9)
                t = d;
        } catch (const CharacterError &) {
        }
    }
    t = (t - t.dot(f) * f);
    if (t.norm() < 1e-6)
        t = Eigen::Vector3d::UnitZ() - f.z() * f;
    t.normalize();
    return t;
}

// A stick in `hand`. Hand frame at rest: fingers along distal_m, thumb towards the
// thumb's end site, palm normal facing down (the CMU T-pose).
void build_stick(const Skeleton &skeleton, const CharacterOptions &options, int side,
                 int hand_joint, const BodySpec &hand, StickInHand &st)
{
    const StickParams &s = options.stick;
    const Eigen::Vector3d f =
        hand.distal_m.norm() > 1e-9 ? hand.distal_m.normalized() : Eigen::Vector3d::UnitX();
    const Eigen::Vector3d t = thumb_direction(skeleton, side, hand_joint, f);
    Eigen::Vector3d n = f.cross(t);
    if (n.y() > 0.0)
        n = -n;
    const double a = s.grip_angle_rad;
    st.axis = (std::cos(a) * f + std::sin(a) * (options.grip == Grip::german ? t : n)).normalized();
    // The fulcrum sits in the fist: at the hand's CoM along the fingers,
    // 2.5 cm towards the palm.
    st.grip_m = de_leva_male(DeLevaSegment::hand).com_fraction * hand.distal_m + 0.025 * n;
    // The stroke plane holds the stick and the hand's direction that is
    // vertical in the grip (German: the palm normal; French: the thumb);
    // the fulcrum turns about its normal.
    st.fulcrum_axis = st.axis.cross(options.grip == Grip::german ? n : t).normalized();
    st.butt_m = st.grip_m - s.grip_from_butt_m * st.axis;
    st.tip_m = st.grip_m + (s.length_m - s.grip_from_butt_m) * st.axis;
    st.com_m = 0.5 * (st.butt_m + st.tip_m);
    const Eigen::Matrix3d aa = st.axis * st.axis.transpose();
    st.inertia_kg_m2 =
        s.mass_kg * s.length_m * s.length_m / 12.0 * (Eigen::Matrix3d::Identity() - aa) +
        0.5 * s.mass_kg * s.shaft_radius_m * s.shaft_radius_m * aa;
}

} // namespace

CharacterModel CharacterModel::from_skeleton(const Skeleton &skeleton,
                                             const CharacterOptions &options)
{
    check_options(options);
    CharacterModel model;
    model.options_ = options;
    model.bodies_.resize(kBodies);
    std::vector<int> source(kBodies), distal(kBodies);
    for (int b = 0; b < kBodies; ++b) {
        source[b] = find_joint(skeleton, kMap[b].source);
        distal[b] = find_distal(skeleton, kMap[b]);
    }
    check_segment_lengths(skeleton, source, distal);
    const double size_ratio = limb_size_ratio(skeleton, source, distal);
    for (int b = 0; b < kBodies; ++b)
        build_body(skeleton, source, distal, b, size_ratio, options.body_mass_kg, model.bodies_[b]);
    for (int side = 0; side < 2; ++side) {
        const int hb = side == 0 ? 9 : 13;
        model.hand_body_[side] = hb;
        build_stick(skeleton, options, side, source[hb], model.bodies_[hb], model.stick_[side]);
    }
    for (int b = 0; b < kBodies; ++b) {
        double mass_kg;
        Eigen::Vector3d com_m;
        Eigen::Matrix3d inertia_kg_m2;
        model.merged_mass(b, mass_kg, com_m, inertia_kg_m2);
        check_mass(model.bodies_[b].name, mass_kg, com_m, inertia_kg_m2);
    }
    return model;
}

int CharacterModel::body_index(const std::string &name) const
{
    for (int b = 0; b < kBodies; ++b)
        if (bodies_[b].name == name)
            return b;
    return -1;
}

int CharacterModel::joint_index(const std::string &name) const
{
    for (int j = 0; j < kJoints; ++j)
        if (bodies_[j + 1].joint_name == name)
            return j;
    return -1;
}

double CharacterModel::total_mass_kg() const
{
    double m = 0.0;
    for (const BodySpec &b : bodies_)
        m += b.mass_kg;
    return m + 2.0 * options_.stick.mass_kg;
}

CharacterPose CharacterModel::pose_from_motion(const Motion &motion, int frame) const
{
    if (frame < 0 || frame >= motion.frames())
        throw CharacterError("motion: frame " + std::to_string(frame) + " out of range [0, " +
                             std::to_string(motion.frames()) + ")");
    const auto &rot = motion.local_rotation[frame];
    CharacterPose pose;
    pose.local.resize(kJoints);
    for (int b = 0; b < kBodies; ++b) {
        Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
        for (int j : bodies_[b].source_path) {
            if (j >= static_cast<int>(rot.size()))
                throw CharacterError("motion: frame " + std::to_string(frame) +
                                     " has fewer rotations than the skeleton has joints");
            q = q * rot[j];
        }
        q.normalize();
        if (b == 0)
            pose.pelvis_rotation = q;
        else
            pose.local[b - 1] = q;
    }
    pose.pelvis_position_m = motion.root_position_m[frame];
    return pose;
}

CharacterPose CharacterModel::rest_pose() const
{
    CharacterPose pose;
    pose.local.assign(kJoints, Eigen::Quaterniond::Identity());
    return pose;
}

void CharacterModel::forward(const CharacterPose &pose, BodyFrames &frames) const
{
    frames.origin_m.resize(kBodies);
    frames.rotation.resize(kBodies);
    frames.origin_m[0] = pose.pelvis_position_m;
    frames.rotation[0] = pose.pelvis_rotation;
    for (int b = 1; b < kBodies; ++b) {
        const int p = bodies_[b].parent;
        frames.origin_m[b] = frames.origin_m[p] + frames.rotation[p] * bodies_[b].offset_m;
        frames.rotation[b] = frames.rotation[p] * pose.local[b - 1];
    }
}

Eigen::Vector3d CharacterModel::tip_position(Side side, const Eigen::Vector3d &hand_origin_m,
                                             const Eigen::Quaterniond &hand_rotation) const
{
    return hand_origin_m + hand_rotation * stick(side).tip_m;
}

void CharacterModel::merged_mass(int body, double &mass_kg, Eigen::Vector3d &com_m,
                                 Eigen::Matrix3d &inertia_kg_m2) const
{
    const BodySpec &b = bodies_[body];
    mass_kg = b.mass_kg;
    com_m = b.com_m;
    inertia_kg_m2 = b.inertia_kg_m2;
    for (int side = 0; side < 2; ++side) {
        if (hand_body_[side] != body)
            continue;
        const StickInHand &st = stick_[side];
        const double ms = options_.stick.mass_kg;
        const double m = mass_kg + ms;
        const Eigen::Vector3d c = (mass_kg * com_m + ms * st.com_m) / m;
        inertia_kg_m2 = inertia_kg_m2 + parallel_axis(mass_kg, com_m - c) + st.inertia_kg_m2 +
                        parallel_axis(ms, st.com_m - c);
        mass_kg = m;
        com_m = c;
    }
}

CharacterModel::SubtreeInertia CharacterModel::subtree_inertia(int joint,
                                                               const CharacterPose &pose) const
{
    BodyFrames frames;
    forward(pose, frames);
    const int top = joint + 1;
    const Eigen::Vector3d pivot = frames.origin_m[top];
    Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
    double mass = 0.0;
    for (int b = top; b < kBodies; ++b) {
        int a = b;
        while (a > top)
            a = bodies_[a].parent;
        if (a != top)
            continue;
        double m;
        Eigen::Vector3d c;
        Eigen::Matrix3d i;
        merged_mass(b, m, c, i);
        const Eigen::Matrix3d r = frames.rotation[b].toRotationMatrix();
        const Eigen::Vector3d cw = frames.origin_m[b] + r * c;
        inertia += r * i * r.transpose() + parallel_axis(m, cw - pivot);
        mass += m;
    }
    return {inertia.trace() / 3.0, mass};
}

ReferenceMotion::ReferenceMotion(const CharacterModel &model, const Motion &motion)
{
    if (motion.frames() < 1)
        throw CharacterError("motion: no frames");
    if (!finite_positive(motion.frame_rate_hz))
        throw CharacterError("motion: frame rate must be > 0, got " + fmt(motion.frame_rate_hz));
    frame_rate_hz_ = motion.frame_rate_hz;
    frames_.reserve(motion.frames());
    for (int f = 0; f < motion.frames(); ++f) {
        frames_.push_back(model.pose_from_motion(motion, f));
        // The pelvis is anchored: the whole reference keeps the first frame's.
        frames_.back().pelvis_position_m = frames_.front().pelvis_position_m;
        frames_.back().pelvis_rotation = frames_.front().pelvis_rotation;
    }
    prepare_spans();
}

void ReferenceMotion::prepare_spans()
{
    const int n = frames();
    spans_.assign(static_cast<size_t>(std::max(n - 1, 0)) * CharacterModel::kJoints, SlerpSpan());
    // Eigen's QuaternionBase::slerp, up to its use of t.
    const double one = 1.0 - Eigen::NumTraits<double>::epsilon();
    for (int f = 0; f + 1 < n; ++f)
        for (int j = 0; j < CharacterModel::kJoints; ++j) {
            SlerpSpan &s = spans_[static_cast<size_t>(f) * CharacterModel::kJoints + j];
            const double d = frames_[f].local[j].dot(frames_[f + 1].local[j]);
            const double abs_d = std::abs(d);
            s.negative = d < 0.0;
            s.linear = abs_d >= one;
            if (!s.linear) {
                s.theta = std::acos(abs_d);
                s.sin_theta = std::sin(s.theta);
            }
        }
}

ReferenceFilter::Kernel reference_kernel_from_string(const std::string &text)
{
    if (text == "gaussian")
        return ReferenceFilter::Kernel::gaussian;
    if (text == "butterworth")
        return ReferenceFilter::Kernel::butterworth;
    throw CharacterError("smoothing kernel: expected gaussian or butterworth, got '" + text + "'");
}

const char *to_string(ReferenceFilter::Kernel kernel)
{
    return kernel == ReferenceFilter::Kernel::butterworth ? "butterworth" : "gaussian";
}

std::vector<double> reference_kernel_taps(ReferenceFilter::Kernel kernel, double cutoff_hz,
                                          double frame_rate_hz)
{
    if (!(cutoff_hz > 0.0 && frame_rate_hz > 0.0 && std::isfinite(cutoff_hz) &&
          std::isfinite(frame_rate_hz)))
        throw CharacterError("smoothing kernel: cutoff and frame rate must be > 0 Hz");
    std::vector<double> taps;
    if (kernel == ReferenceFilter::Kernel::gaussian) {
        const double sigma_frames = frame_rate_hz / (2.0 * M_PI * cutoff_hz);
        const int half = static_cast<int>(std::ceil(3.0 * sigma_frames));
        for (int k = 0; k <= half; ++k)
            taps.push_back(std::exp(-0.5 * k * k / (sigma_frames * sigma_frames)));
    } else {
        // h[k] = (2 / fs) * integral over 0..fs/2 of G(f) cos(2 pi f k / fs) df,
        // G(f) = 1 / (1 + (f / fc)^4), by the midpoint rule (G is smooth; 4096
        // points put the quadrature error far below the truncation's 1e-3).
        constexpr int kPoints = 4096;
        const double df = 0.5 * frame_rate_hz / kPoints;
        const int reach = static_cast<int>(std::ceil(4.0 * frame_rate_hz / cutoff_hz));
        std::vector<double> g(kPoints), f(kPoints);
        for (int i = 0; i < kPoints; ++i) {
            f[i] = (i + 0.5) * df;
            const double x = f[i] / cutoff_hz;
            g[i] = 1.0 / (1.0 + x * x * x * x);
        }
        for (int k = 0; k <= reach; ++k) {
            double sum = 0.0;
            for (int i = 0; i < kPoints; ++i)
                sum += g[i] * std::cos(2.0 * M_PI * f[i] * k / frame_rate_hz);
            taps.push_back(2.0 / frame_rate_hz * sum * df);
        }
        int half = 0;
        for (int k = 0; k <= reach; ++k)
            if (std::fabs(taps[k]) >= 1e-3 * taps[0])
                half = k;
        taps.resize(static_cast<size_t>(half) + 1);
    }
    // The Gaussian's taps stay unnormalised (the smoothing divides by their
    // sum, and earlier outputs were measured with these exact weights).
    if (kernel == ReferenceFilter::Kernel::butterworth) {
        double total = taps[0];
        for (size_t k = 1; k < taps.size(); ++k)
            total += 2.0 * taps[k];
        for (double &t : taps)
            t /= total;
    }
    return taps;
}

ReferenceMotion::ReferenceMotion(const CharacterModel &model, const Motion &motion,
                                 const ReferenceFilter &filter)
    : ReferenceMotion(model, motion)
{
    if (!(std::isfinite(filter.spike_threshold_rad) && filter.spike_threshold_rad >= 0.0))
        throw CharacterError("reference filter: spike threshold must be >= 0 rad");
    if (!(std::isfinite(filter.smooth_cutoff_hz) && filter.smooth_cutoff_hz >= 0.0))
        throw CharacterError("reference filter: smoothing cutoff must be >= 0 Hz");
    if (!(std::isfinite(filter.spike_reference_rate_hz) && filter.spike_reference_rate_hz >= 0.0))
        throw CharacterError("reference filter: spike reference rate must be >= 0 Hz");
    const int n = frames();
    auto angle = [](const Eigen::Quaterniond &a, const Eigen::Quaterniond &b) {
        return 2.0 * std::acos(std::min(1.0, std::fabs(a.dot(b))));
    };
    if (filter.spike_threshold_rad > 0.0) {
        const double slower = std::max(1.0, filter.spike_reference_rate_hz / frame_rate_hz_);
        const double threshold_rad = filter.spike_threshold_rad * slower * slower;
        for (int j = 0; j < CharacterModel::kJoints; ++j) {
            for (int f = 1; f + 1 < n; ++f) {
                const Eigen::Quaterniond &a = frames_[f - 1].local[j];
                const Eigen::Quaterniond &b = frames_[f + 1].local[j];
                const Eigen::Quaterniond mid = a.slerp(0.5, b);
                const double off = angle(frames_[f].local[j], mid);
                if (off > threshold_rad && angle(a, b) < off) {
                    frames_[f].local[j] = mid;
                    ++spikes_removed_;
                }
            }
        }
    }
    if (filter.smooth_cutoff_hz > 0.0 && n > 2) {
        const std::vector<double> taps =
            reference_kernel_taps(filter.kernel, filter.smooth_cutoff_hz, frame_rate_hz_);
        const int half = static_cast<int>(taps.size()) - 1;
        std::vector<double> w(2 * half + 1);
        for (int k = -half; k <= half; ++k)
            w[k + half] = taps[static_cast<size_t>(std::abs(k))];
        std::vector<Eigen::Quaterniond> smoothed(n);
        for (int j = 0; j < CharacterModel::kJoints; ++j) {
            for (int f = 0; f < n; ++f) {
                // Weighted mean of the neighbours' rotation vectors relative to
                // this frame (a tangent-space average: no Euler angles).
                const Eigen::Quaterniond &q = frames_[f].local[j];
                Eigen::Vector3d sum = Eigen::Vector3d::Zero();
                double wsum = 0.0;
                for (int k = -half; k <= half; ++k) {
                    const int g = f + k;
                    if (g < 0 || g >= n)
                        continue;
                    const Eigen::Vector3d v = log_map(q.conjugate() * frames_[g].local[j]);
                    sum += w[k + half] * v;
                    wsum += w[k + half];
                }
                // Back from the tangent space through Eigen's angle-axis (the
                // reference outputs were measured with it; exp_map differs by rounding).
                const Eigen::Vector3d mean = sum / wsum;
                const double a = mean.norm();
                const Eigen::Quaterniond e =
                    a < 1e-12 ? Eigen::Quaterniond::Identity()
                              : Eigen::Quaterniond(Eigen::AngleAxisd(a, mean / a));
                smoothed[f] = (q * e).normalized();
            }
            for (int f = 0; f < n; ++f)
                frames_[f].local[j] = smoothed[f];
        }
    }
    prepare_spans();
}

double ReferenceMotion::duration_s() const
{
    return (frames() - 1) / frame_rate_hz_;
}

void ReferenceMotion::sample(double time_s, CharacterPose &pose) const
{
    const int n = frames();
    pose.pelvis_position_m = frames_[0].pelvis_position_m;
    pose.pelvis_rotation = frames_[0].pelvis_rotation;
    pose.local.resize(CharacterModel::kJoints);
    if (n == 1 || !(time_s > 0.0)) {
        pose.local = frames_[0].local;
        return;
    }
    const double span = n - 1;
    double u = std::fmod(time_s * frame_rate_hz_, 2.0 * span);
    if (u > span)
        u = 2.0 * span - u;
    int i = static_cast<int>(std::floor(u));
    if (i >= n - 1)
        i = n - 2;
    const double a = u - i;
    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        // frames_[i].local[j].slerp(a, frames_[i + 1].local[j]), its constants kept.
        const SlerpSpan &s = spans_[static_cast<size_t>(i) * CharacterModel::kJoints + j];
        double scale0, scale1;
        if (s.linear) {
            scale0 = 1.0 - a;
            scale1 = a;
        } else {
            scale0 = std::sin((1.0 - a) * s.theta) / s.sin_theta;
            scale1 = std::sin(a * s.theta) / s.sin_theta;
        }
        if (s.negative)
            scale1 = -scale1;
        pose.local[j] = Eigen::Quaterniond(scale0 * frames_[i].local[j].coeffs() +
                                           scale1 * frames_[i + 1].local[j].coeffs());
    }
}

} // namespace ictus
