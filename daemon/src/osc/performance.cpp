// The physics side of `ictusd run` and `ictusd render` (verbs_osc.hpp): the
// character tracks the clip in joint space (eq. 1, the sim helper's Scene),
// and the interaction manager watches the stick tips against the drum.
#include "ictus/bvh.hpp"
#include "ictus/character_limits.hpp"
#include "ictus/track.hpp"
#include "ictus/verbs_osc.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <iostream>

namespace ictus
{

namespace
{
double smoothstep(double x)
{
    x = std::min(1.0, std::max(0.0, x));
    return x * x * (3.0 - 2.0 * x);
}

double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

// Where the clip strikes: the reference stick tips' local minima of height
// reached at more than 1 m/s downwards (the mimed strokes; a captured
// performance without a drum still "hits" a plane). The membrane goes at the
// median of those points, so that about half of the mimed strokes reach it
// and are stopped by it. (track.hpp's auto_drum_center puts the drum under
// the lowest tips, which in a mimed clip are in the rest pose, not in a stroke.)
Eigen::Vector3d strike_drum_center(const CharacterModel &model, const ReferenceMotion &reference,
                                   const Eigen::Vector3d &fallback)
{
    const int frames = reference.frames();
    std::vector<std::array<Eigen::Vector3d, 2>> tips(static_cast<size_t>(frames));
    for (int f = 0; f < frames; ++f)
        tips[static_cast<size_t>(f)] = reference_tips(model, reference.frame(f));
    std::vector<double> xs, ys, zs;
    const double rate = reference.frame_rate_hz();
    for (int hand = 0; hand < 2; ++hand)
        for (int f = 2; f + 2 < frames; ++f) {
            auto y = [&](int g) { return tips[static_cast<size_t>(g)][hand].y(); };
            const bool minimum =
                y(f) < y(f - 1) && y(f) <= y(f + 1) && y(f) < y(f - 2) && y(f) <= y(f + 2);
            const double approach_mps = (y(f - 2) - y(f)) * rate / 2.0;
            if (minimum && approach_mps > 1.0) {
                xs.push_back(tips[static_cast<size_t>(f)][hand].x());
                ys.push_back(y(f));
                zs.push_back(tips[static_cast<size_t>(f)][hand].z());
            }
        }
    if (xs.size() < 4)
        return fallback;
    return Eigen::Vector3d(median(xs), median(ys), median(zs));
}
} // namespace

// Everything that depends on the grip or the drum, rebuilt together when they
// change (the Scene keeps references to the limits).
struct Performance::Rig {
    CharacterModel model;
    ReferenceMotion reference;
    CharacterLimits limits;
    std::vector<JointGains> base_gains, gains;
    std::unique_ptr<Scene> scene;
    // Per-step scratch, sized once (no allocation in the loop).
    CharacterPose ref_pose;
    std::vector<Eigen::Quaterniond> previous_target, target;
    std::vector<Eigen::Vector3d> rate;
    mutable BodyFrames frames;
    Rig(const CharacterModel &m, const Motion &motion)
        : model(m), reference(model, motion, ReferenceFilter{}), limits(model, reference)
    {
    }
};

Performance::Performance(const PerformanceOptions &options)
    : options_(options), detector_(MembraneGeometry{}, options.strikes)
{
    validate(options_.scene);
    if (!(options_.clip_bpm > 0.0 && std::isfinite(options_.clip_bpm)))
        throw CharacterError("clip tempo: expected a finite value > 0 bpm");
    if (!(options_.tempo_bpm >= 20.0 && options_.tempo_bpm <= 400.0))
        throw CharacterError("tempo: expected 20 to 400 bpm");
    build();
}

Performance::~Performance() = default;

void Performance::build()
{
    BvhOptions bo;
    bo.scale = options_.scale_m_per_unit;
    bo.skip_frames = options_.skip_frames;
    MocapWarnings warnings;
    const BvhFile bvh = read_bvh(options_.mocap, bo, &warnings);
    for (const std::string &w : warnings)
        std::cerr << "ictusd: warning: " << w << "\n";
    const CharacterModel model = CharacterModel::from_skeleton(bvh.skeleton, options_.character);
    const double previous_time = rig_ ? time_s() : 0.0;
    if (rig_)
        divergences_before_ += rig_->scene->divergences();
    rig_.reset(new Rig(model, bvh.motion));
    Rig &r = *rig_;
    if (options_.drum_auto)
        options_.scene.drum.center_m =
            strike_drum_center(r.model, r.reference, auto_drum_center(r.model, r.reference));
    const CharacterPose initial = r.reference.frame(0);
    r.base_gains = default_gains(r.model, initial, options_.gains);
    r.gains = r.base_gains;
    for (JointGains &g : r.gains) {
        g.kp_nm_per_rad *= gain_scale_[0];
        g.kd_nm_s_per_rad *= gain_scale_[1];
    }
    r.scene.reset(new Scene(r.model, options_.scene, initial, r.gains));
    r.scene->set_joint_limits(r.limits.refs());
    r.ref_pose = initial;
    r.previous_target = initial.local;
    r.target = initial.local;
    r.rate.assign(CharacterModel::kJoints, Eigen::Vector3d::Zero());
    r.scene->body_frames(r.frames);
    // The simulation clock keeps running across rebuilds (strike times and
    // timetags stay monotonic); the clip restarts from its beginning.
    time_offset_s_ = previous_time;
    clip_time_s_ = 0.0;
    detector_.reset(membrane());
}

MembraneGeometry Performance::membrane() const
{
    MembraneGeometry m;
    const DrumParams &d = options_.scene.drum;
    m.center_m = d.center_m;
    m.radius_m = d.radius_m;
    m.tip_radius_m = rig_->model.options().stick.tip_radius_m;
    m.stiffness_n_per_m = d.stiffness_n_per_m(m.tip_radius_m);
    m.damping_n_s_per_m = d.contact_damping_n_s_per_m;
    m.friction = d.friction;
    return m;
}

const Scene &Performance::scene() const
{
    return *rig_->scene;
}

double Performance::time_s() const
{
    return time_offset_s_ + rig_->scene->time_s();
}

double Performance::clip_duration_s() const
{
    return rig_->reference.duration_s() * options_.clip_bpm / options_.tempo_bpm;
}

int Performance::divergences() const
{
    return divergences_before_ + rig_->scene->divergences();
}

int Performance::step(StrikeEvent out[2])
{
    Rig &r = *rig_;
    const double h = options_.scene.step_s;
    if (playing_)
        clip_time_s_ += h * options_.tempo_bpm / options_.clip_bpm;
    const double since_build = r.scene->time_s() + h;
    // Targets for the end of this step, blended in from the first frame.
    r.reference.sample(clip_time_s_, r.ref_pose);
    const double blend = options_.ramp_s > 0.0 ? smoothstep(since_build / options_.ramp_s) : 1.0;
    const CharacterPose &initial = r.reference.frame(0);
    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        r.target[j] = initial.local[j].slerp(blend, r.ref_pose.local[j]);
        r.rate[j] = rotation_vector(r.target[j] * r.previous_target[j].conjugate()) / h;
    }
    std::swap(r.previous_target, r.target);
    r.scene->set_joint_targets(r.previous_target, r.rate);
    r.scene->step();

    // The interaction manager: the beads' centres against the membrane.
    r.scene->body_frames(r.frames);
    const double t = time_s();
    int n = 0;
    for (int hand = 0; hand < 2; ++hand) {
        const Side side = static_cast<Side>(hand);
        const StickInHand &st = r.model.stick(side);
        const Eigen::Quaterniond &q = r.frames.rotation[r.model.hand_body(side)];
        TipSample s;
        s.time_s = t;
        s.center_m =
            r.scene->tip_position(side) - r.model.options().stick.tip_radius_m * (q * st.axis);
        s.velocity_mps = r.scene->tip_velocity(side);
        if (detector_.update(hand, s, out[n]))
            ++n;
    }
    return n;
}

bool Performance::apply(const Command &c, std::string *why)
{
    auto fail = [&](const std::string &text) {
        if (why)
            *why = text;
        return false;
    };
    switch (c.kind) {
    case CommandKind::play:
        if (rebuild_pending_) {
            // Grip or drum changed while stopped or playing: the character and
            // the drum are rebuilt at the clip's first frame (a Scene has no
            // setters for them).
            rebuild_pending_ = false;
            build();
        }
        playing_ = true;
        return true;
    case CommandKind::stop:
        playing_ = false;
        return true;
    case CommandKind::tempo:
        options_.tempo_bpm = c.value;
        return true;
    case CommandKind::grip:
        options_.character.grip = grip_from_string(c.text);
        rebuild_pending_ = true;
        return true;
    case CommandKind::nuance:
        return fail("nuance: stored for the score player, which is not implemented yet");
    case CommandKind::mode:
        if (std::strcmp(c.text, "joint") != 0)
            return fail("mode: only joint is implemented");
        return true;
    case CommandKind::gains: {
        gain_scale_[0] = c.value;
        gain_scale_[1] = c.value2;
        Rig &r = *rig_;
        for (size_t j = 0; j < r.gains.size(); ++j) {
            r.gains[j] = r.base_gains[j];
            r.gains[j].kp_nm_per_rad *= c.value;
            r.gains[j].kd_nm_s_per_rad *= c.value2;
        }
        r.scene->set_gains(r.gains);
        return true;
    }
    case CommandKind::drum_radius:
        if (!(c.value > rig_->model.options().stick.tip_radius_m * 2.0))
            return fail("drum radius: must exceed the stick tip's diameter");
        options_.scene.drum.radius_m = c.value;
        rebuild_pending_ = true;
        return true;
    case CommandKind::drum_tension:
        options_.scene.drum.tension_n_per_m = c.value;
        rebuild_pending_ = true;
        return true;
    case CommandKind::drum_density:
        // The membrane's density changes its modes (membrane~), not the
        // contact stiffness 2 pi T / ln(R / r): nothing to rebuild.
        options_.drum_density_kg_per_m2 = c.value;
        return true;
    }
    return fail("unknown command");
}

void Performance::pose(PoseSnapshot &p) const
{
    const Rig &r = *rig_;
    r.scene->body_frames(r.frames);
    p.time_s = time_s();
    p.bodies = std::min<int>(CharacterModel::kBodies, PoseSnapshot::kMaxBodies);
    for (int b = 0; b < p.bodies; ++b) {
        for (int i = 0; i < 3; ++i)
            p.position_m[b][i] = static_cast<float>(r.frames.origin_m[b][i]);
        const Eigen::Quaterniond &q = r.frames.rotation[b];
        p.rotation_wxyz[b][0] = static_cast<float>(q.w());
        p.rotation_wxyz[b][1] = static_cast<float>(q.x());
        p.rotation_wxyz[b][2] = static_cast<float>(q.y());
        p.rotation_wxyz[b][3] = static_cast<float>(q.z());
    }
    for (int hand = 0; hand < 2; ++hand) {
        const Side side = static_cast<Side>(hand);
        const int hb = r.model.hand_body(side);
        const StickInHand &st = r.model.stick(side);
        const Eigen::Vector3d tip = r.frames.origin_m[hb] + r.frames.rotation[hb] * st.tip_m;
        const Eigen::Vector3d butt = r.frames.origin_m[hb] + r.frames.rotation[hb] * st.butt_m;
        for (int i = 0; i < 3; ++i) {
            p.stick_tip_m[hand][i] = static_cast<float>(tip[i]);
            p.stick_butt_m[hand][i] = static_cast<float>(butt[i]);
        }
    }
    for (int i = 0; i < 3; ++i)
        p.drum_center_m[i] = static_cast<float>(options_.scene.drum.center_m[i]);
    p.drum_radius_m = static_cast<float>(options_.scene.drum.radius_m);
}

void Performance::tip(int hand, TipState &out) const
{
    const Side side = static_cast<Side>(hand & 1);
    out.time_s = time_s();
    out.hand = hand & 1;
    const Eigen::Vector3d p = rig_->scene->tip_position(side);
    const Eigen::Vector3d v = rig_->scene->tip_velocity(side);
    for (int i = 0; i < 3; ++i) {
        out.position_m[i] = static_cast<float>(p[i]);
        out.velocity_mps[i] = static_cast<float>(v[i]);
    }
}

} // namespace ictus
