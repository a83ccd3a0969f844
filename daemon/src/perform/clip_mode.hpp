// clip_mode.hpp -- a Performance of a mocap clip (private to src/perform):
// the character tracks the clip in joint space (eq. 1, a Tracker in joint
// mode, as `ictusd track --mode joint`).
#pragma once

#include "perform_mode.hpp"

#include <memory>

namespace ictus
{

class ClipMode final : public PerformMode
{
  public:
    // Reads the clip (Performance's options: mocap, scale, skip) once: a
    // rebuild starts from this copy, so that the physics thread never
    // touches the disk.
    explicit ClipMode(Performance &performance);
    ~ClipMode() override;
    void begin() override;

    int step(StrikeEvent out[kStepStrikes]) override;

    // The grip is rebuilt at the next play; the other commands act at once.
    bool play(const Command &c, std::string *why) override;
    void stop() override {}
    bool tempo(const Command &c, std::string *) override
    {
        perf_.options_.tempo_bpm = c.value;
        return true;
    }
    bool grip(const Command &, std::string *) override
    {
        rebuild_pending_ = true;
        return true;
    }
    // Refused: a clip has no nuances, no modes but joint, no score.
    bool nuance(const Command &c, std::string *why) override;
    bool mode(const Command &c, std::string *why) override;
    bool score(const Command &c, std::string *why) override;
    bool drum_changed(const Command &, std::string *) override { return true; }
    void firmness_changed() override { perf_.set_grips(perf_.options_.grip_firmness); }
    bool install(Work &work, std::string *why) override;

    const Skeleton &skeleton() const;
    // The clip's length at the current tempo, s.
    double duration_s() const;

  private:
    struct Rig;
    class RigJob;
    // The character, its reference and controller for `options` (drum_auto:
    // the drum centre is set in `options`). Reads only the clip.
    std::unique_ptr<Rig> make_rig(PerformanceOptions &options) const;
    void install_rig(std::unique_ptr<Rig> rig);

    Performance &perf_;
    std::unique_ptr<BvhFile> clip_; // the capture, read once
    std::unique_ptr<Rig> rig_;
    double clip_time_s_ = 0.0;
    bool rebuild_pending_ = false; // a grip change waits for the next play
};

} // namespace ictus
