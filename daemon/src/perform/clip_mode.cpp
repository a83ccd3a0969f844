// A Performance of a mocap clip (clip_mode.hpp): the character tracks the
// clip in joint space, and the interaction manager watches the stick tips
// against the drum.
#include "clip_mode.hpp"

#include "ictus/character/character_limits.hpp"
#include "ictus/character/stick_capture.hpp"
#include "ictus/mocap/bvh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <iostream>

namespace ictus
{

namespace
{
double median(std::vector<double> v)
{
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

// Where the clip strikes: the reference stick tips' turnarounds (the mimed
// strokes; a captured performance without a drum still "hits" a plane) that
// came down at 1 m/s or faster (kClipStrokeSpeed_mps), each refined between the
// capture's frames (find_turnarounds: an impact's V or a smooth turn's
// parabola, docs/mocap.md, "Drum placement"). The membrane goes at the median
// height of those vertices, so that about half of the mimed strokes reach it
// and are stopped by it, its centre (x, z) at the mean of the two sticks'
// median points. (track.hpp's auto_drum_center puts the drum under the lowest
// tips, which in a mimed clip are in the rest pose, not in a stroke.) The
// lowest frame of a stroke lies up to half a frame's travel above its vertex
// (a 3 m/s stroke at 60 Hz: 25 mm), and a median of both sticks' points pooled
// jumps from one stick's strokes to the other's as their counts change: the
// vertices and the per-stick medians keep the drum where it is at any frame
// rate and phase.
constexpr double kClipStrokeSpeed_mps = 1.0;

Eigen::Vector3d strike_drum_center(const CharacterModel &model, const ReferenceMotion &reference,
                                   const Eigen::Vector3d &fallback)
{
    const int frames = reference.frames();
    const double rate = reference.frame_rate_hz();
    if (frames < 5 || !(rate > 0.0))
        return fallback;
    TipTrajectory tips;
    for (int f = 0; f < frames; ++f) {
        const std::array<Eigen::Vector3d, 2> at = reference_tips(model, reference.frame(f));
        tips.time_s.push_back(f / rate);
        for (int hand = 0; hand < 2; ++hand)
            tips.tip_m[static_cast<size_t>(hand)].push_back(at[static_cast<size_t>(hand)]);
    }
    std::vector<double> ys;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int sticks = 0;
    for (int hand = 0; hand < 2; ++hand) {
        std::vector<double> xs, zs;
        for (const StrokeTurnaround &ta :
             find_turnarounds(tips, hand, 0.01, kClipStrokeSpeed_mps)) {
            xs.push_back(ta.position_m.x());
            ys.push_back(ta.position_m.y());
            zs.push_back(ta.position_m.z());
        }
        if (xs.empty())
            continue;
        sum += Eigen::Vector3d(median(xs), 0.0, median(zs));
        ++sticks;
    }
    if (ys.size() < 4)
        return fallback;
    return Eigen::Vector3d(sum.x() / sticks, median(ys), sum.z() / sticks);
}
} // namespace

// Everything that depends on the grip or the drum, rebuilt together when they
// change (the tracker's Scene keeps references to the limits, which are
// declared first and so outlive it).
struct ClipMode::Rig {
    CharacterModel model;
    ReferenceMotion reference;
    CharacterLimits limits;
    std::vector<JointGains> base_gains, gains;
    std::unique_ptr<Tracker> tracker;
    // Per-step scratch, sized once (no allocation in the loop).
    CharacterPose ref_pose, step_pose;
    Rig(const CharacterModel &m, const Motion &motion)
        : model(m), reference(model, motion, ReferenceFilter{}), limits(model, reference)
    {
    }
};

// The character rebuilt at the clip's first frame (a grip change).
class ClipMode::RigJob : public Work
{
  public:
    RigJob(const ClipMode &mode, const Command &origin, const PerformanceOptions &options)
        : Work(Kind::clip_rig), options(options), mode_(mode)
    {
        this->origin = origin;
    }
    PerformanceOptions options;
    std::unique_ptr<Rig> rig;
    Eigen::Vector3d drum_center_m = Eigen::Vector3d::Zero();

  protected:
    void build() override
    {
        rig = mode_.make_rig(options);
        drum_center_m = options.scene.drum.center_m;
    }
    void clear_result() override { rig.reset(); }

  private:
    const ClipMode &mode_;
};

ClipMode::ClipMode(Performance &performance) : perf_(performance)
{
    const PerformanceOptions &o = perf_.options_;
    BvhOptions bo;
    bo.scale = o.scale_m_per_unit;
    bo.skip_frames = o.skip_frames;
    MocapWarnings warnings;
    clip_ = std::make_unique<BvhFile>(read_bvh(o.mocap, bo, &warnings));
    for (const std::string &w : warnings)
        std::cerr << "ictusd: warning: " << w << "\n";
}

ClipMode::~ClipMode() = default;

void ClipMode::begin()
{
    install_rig(make_rig(perf_.options_));
}

const Skeleton &ClipMode::skeleton() const
{
    return clip_->skeleton;
}

std::unique_ptr<ClipMode::Rig> ClipMode::make_rig(PerformanceOptions &options) const
{
    const BvhFile &bvh = *clip_;
    const CharacterModel model = CharacterModel::from_skeleton(bvh.skeleton, options.character);
    auto rig = std::make_unique<Rig>(model, bvh.motion);
    Rig &r = *rig;
    if (options.drum_auto)
        options.scene.drum.center_m =
            strike_drum_center(r.model, r.reference, auto_drum_center(r.model, r.reference));
    const CharacterPose initial = r.reference.frame(0);
    r.base_gains = default_gains(r.model, initial, options.gains);
    scale_gains(r.base_gains, perf_.gain_scale_, r.gains);
    // Eq. 1 on every joint: the tracker's joint mode, as `ictusd track --mode joint`,
    // in its scene (track_scene_defaults: the pelvis a kinematic body, not welded).
    SceneOptions scene = options.scene;
    scene.pelvis_kinematic = track_scene_defaults().pelvis_kinematic;
    r.tracker = std::make_unique<Tracker>(r.model, scene, initial, r.gains, r.limits.refs(),
                                          TrackMode::joint);
    r.ref_pose = initial;
    r.step_pose = initial;
    return rig;
}

void ClipMode::install_rig(std::unique_ptr<Rig> rig)
{
    const double previous_time = rig_ ? perf_.time_s() : 0.0;
    if (rig_)
        perf_.divergences_before_ += rig_->tracker->scene().divergences();
    std::swap(rig_, rig);
    use_rig(rig_->model, *rig_->tracker, rig_->base_gains, rig_->gains);
    // The clip restarts from its beginning.
    clip_time_s_ = 0.0;
    perf_.took_over(previous_time);
    if (rig && perf_.worker_)
        perf_.discard(std::make_unique<Disposal<Rig>>(std::move(rig)));
}

double ClipMode::duration_s() const
{
    const PerformanceOptions &o = perf_.options_;
    return rig_->reference.duration_s() * o.clip_bpm / o.tempo_bpm;
}

int ClipMode::step(StrikeEvent out[kStepStrikes])
{
    Rig &r = *rig_;
    const PerformanceOptions &o = perf_.options_;
    const double h = o.scene.step_s;
    if (perf_.playing_)
        clip_time_s_ += h * o.tempo_bpm / o.clip_bpm;
    const double since_build = r.tracker->scene().time_s() + h;
    // Targets for the end of this step, blended in from the first frame.
    r.reference.sample(clip_time_s_, r.ref_pose);
    blend_pose(r.reference.frame(0), r.ref_pose, ramp_weight(since_build, o.ramp_s), r.step_pose);
    r.tracker->step(r.step_pose, nullptr);
    return detect_strikes(perf_.detector_, r.tracker->scene(), out, perf_.time_offset_s_);
}

bool ClipMode::play(const Command &c, std::string *why)
{
    if (!rebuild_pending_) {
        perf_.playing_ = true;
        return true;
    }
    // The grip changed while stopped or playing: the character is rebuilt at
    // the clip's first frame (a Scene has no setter for it), and plays when
    // it is ready.
    rebuild_pending_ = false;
    return perf_.submit(std::make_unique<RigJob>(*this, c, perf_.options_), why);
}

bool ClipMode::nuance(const Command &, std::string *why)
{
    return refuse(why, "nuance: a clip has no nuances; without --mocap the daemon plays scores, "
                       "whose notes name their nuance (/ictus/score \"R accent\")");
}

bool ClipMode::mode(const Command &c, std::string *why)
{
    if (std::strcmp(c.text, "joint") != 0)
        return refuse(why, "mode: a clip plays in joint space only (eq. 1); cartesian tracks a "
                           "score's stick tips: start ictusd without --mocap");
    return true;
}

bool ClipMode::score(const Command &, std::string *why)
{
    return refuse(why, "score: the daemon plays a clip (--mocap); start it without --mocap to "
                       "perform scores");
}

bool ClipMode::install(Work &work, std::string *)
{
    RigJob &job = static_cast<RigJob &>(work);
    if (perf_.options_.drum_auto)
        perf_.options_.scene.drum.center_m = job.drum_center_m;
    install_rig(std::move(job.rig));
    // A stop after the play that asked for the rebuild: the clip waits.
    if (!job.cancelled())
        perf_.playing_ = true;
    return true;
}

} // namespace ictus
