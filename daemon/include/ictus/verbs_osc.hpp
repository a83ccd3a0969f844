// verbs_osc.hpp -- the verbs that play the drum: `ictusd run` (real time,
// wall-clock paced, OSC in and out on their own threads) and `ictusd render`
// (offline, as fast as possible, deterministic: strikes.csv and a qlist
// events file for a Pd batch patch). Both drive the character with a mocap
// clip in joint space (paper eq. 1, as `ictusd track`) and detect strikes
// with the interaction manager (strike.hpp). See docs/osc.md.
#pragma once

#include "ictus/character.hpp"
#include "ictus/joint_controller.hpp"
#include "ictus/osc_link.hpp"
#include "ictus/scene.hpp"
#include "ictus/strike.hpp"

#include <memory>
#include <string>
#include <vector>

namespace ictus
{

// argv as main() passes it, verb first: argv[0] == "run" / "render".
// Exit status: 0 ok, 1 runtime error, 2 usage error, 130 interrupted.
int cmd_run(int argc, char **argv);
int cmd_render(int argc, char **argv);

struct PerformanceOptions {
    std::string mocap; // BVH with CMU joint names
    double scale_m_per_unit = 0.056444;
    int skip_frames = 1;
    CharacterOptions character;
    SceneOptions scene;
    GainOptions gains;
    bool drum_auto = true; // drum under the clip's lowest tips
    double ramp_s = 0.25;
    double clip_bpm = 120.0; // tempo at which the clip plays at its own speed
    double tempo_bpm = 120.0;
    double drum_density_kg_per_m2 = 0.26; // for the sound only (membrane~)
    StrikeDetectorOptions strikes;
};

// The physics side of run and render: the character tracking the clip, the
// drum, the strike detector, and the commands Pd may send.
class Performance
{
  public:
    explicit Performance(const PerformanceOptions &options); // throws on bad file/options
    ~Performance();

    // One physics step; returns the number of strikes ended in it (<= 2),
    // written to out[0..n).
    int step(StrikeEvent out[2]);
    // Ends contacts still open (end of a run).
    bool flush(StrikeEvent &out) { return detector_.flush(out); }
    // Applies a command from the OSC thread. Returns false with a reason when
    // it cannot be applied (the OSC thread has already validated the values).
    bool apply(const Command &command, std::string *why = nullptr);

    void pose(PoseSnapshot &out) const;
    void tip(int hand, TipState &out) const;
    double time_s() const;
    // The clip's length at the current tempo, s.
    double clip_duration_s() const;
    double step_s() const { return options_.scene.step_s; }
    bool playing() const { return playing_; }
    double tempo_bpm() const { return options_.tempo_bpm; }
    const PerformanceOptions &options() const { return options_; }
    const Scene &scene() const;
    const StrikeDetector &detector() const { return detector_; }
    int divergences() const;

  private:
    struct Rig;
    void build();
    MembraneGeometry membrane() const;
    PerformanceOptions options_;
    std::unique_ptr<Rig> rig_;
    StrikeDetector detector_;
    bool playing_ = true;
    bool rebuild_pending_ = false;
    double clip_time_s_ = 0.0;
    double time_offset_s_ = 0.0; // simulation time at the last (re)build
    double gain_scale_[2] = {1.0, 1.0};
    int divergences_before_ = 0;
};

} // namespace ictus
