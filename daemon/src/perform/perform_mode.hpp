// perform_mode.hpp -- the two motion sources of a Performance (private to
// src/perform): a mocap clip in joint space (clip_mode.cpp) and a score's
// gesture plan (score_mode.cpp), behind one interface, so that
// Performance::apply handles each command once and asks the mode only for
// the part that differs.
#pragma once

#include "ictus/perform/performance.hpp"
#include "planning_worker.hpp"

#include <string>
#include <vector>

namespace ictus
{

class PerformMode
{
  public:
    virtual ~PerformMode() = default;
    // Builds and installs the first rig (the Performance holds the mode by then).
    virtual void begin() = 0;

    // The rig in use: its scene, character, and gains (at scale 1, and as
    // the scene has them).
    Scene &scene() { return tracker_->scene(); }
    const Scene &scene() const { return tracker_->scene(); }
    const CharacterModel &model() const { return *model_; }
    const std::vector<JointGains> &base_gains() const { return *base_gains_; }
    std::vector<JointGains> &gains() { return *gains_; }
    // One physics step; the strikes ended in it (<= kStepStrikes: the two
    // hands' and the foot's) in out[0..n).
    virtual int step(StrikeEvent out[kStepStrikes]) = 0;
    // A foot's contact begun in the last step, at its onset (score mode); each
    // once, true while there is one.
    virtual bool take_foot_onset(StrikeEvent &) { return false; }

    // The commands' parts that differ. False with a reason when refused;
    // they may throw (Performance::apply answers with what()).
    virtual bool play(const Command &c, std::string *why) = 0;
    virtual void stop() = 0; // Performance::playing_ is false already
    virtual bool tempo(const Command &c, std::string *why) = 0;
    virtual bool grip(const Command &c, std::string *why) = 0; // options' grip is the new one
    virtual bool nuance(const Command &c, std::string *why) = 0;
    virtual bool mode(const Command &c, std::string *why) = 0;
    // The live scene and the strike detector have the new drum already.
    virtual bool drum_changed(const Command &c, std::string *why) = 0;
    virtual void firmness_changed() = 0; // options' grip_firmness is the new one
    virtual bool score(const Command &c, std::string *why) = 0; // score, score_clear

    // A job of this mode came back from run(), with or without an error.
    virtual void returned(const Work &) {}
    // Installs an error-free job's result, or refuses it with why.
    virtual bool install(Work &work, std::string *why) = 0;

  protected:
    // The rig in use from now on (the mode owns it).
    void use_rig(const CharacterModel &model, Tracker &tracker,
                 const std::vector<JointGains> &base_gains, std::vector<JointGains> &gains)
    {
        model_ = &model;
        tracker_ = &tracker;
        base_gains_ = &base_gains;
        gains_ = &gains;
    }

  private:
    const CharacterModel *model_ = nullptr;
    Tracker *tracker_ = nullptr;
    const std::vector<JointGains> *base_gains_ = nullptr;
    std::vector<JointGains> *gains_ = nullptr;
};

// A refusal with a reason.
inline bool refuse(std::string *why, const std::string &text)
{
    if (why)
        *why = text;
    return false;
}

} // namespace ictus
