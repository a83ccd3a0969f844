// foot_player.hpp -- a foot of a score's performance (private to
// src/perform): the plan's notes of that foot (GesturePlan::foot_notes)
// played by its pedal (ictus/sim/kick_pedal.hpp, docs/pedal.md): the right
// foot's on the kit's kick, the left foot's on its hi-hat (the chick), each
// scheduled a little ahead of its time, the pedal advanced with the physics
// and its contacts reported as strikes of that foot (StrikeEvent::hand
// kFootRight, kFootLeft).
#pragma once

#include "ictus/perform/kit.hpp"
#include "ictus/score/gesture_score.hpp"
#include "ictus/sim/kick_pedal.hpp"
#include "ictus/sim/strike_detector.hpp"

#include <array>
#include <vector>

namespace ictus
{

class FootPlayer
{
  public:
    // The pedal of the kit's piece `drum` before the performer: the right
    // foot's on a kick (KitDrum::foot; force_dir: the performer's facing,
    // world), the left foot's on a hi-hat (kit_drum_has_pedal; force_dir:
    // down, the top plate onto the bottom one).
    FootPlayer(const KitDrum &drum, int drum_index, const Eigen::Vector3d &force_dir,
               Side side = Side::right);

    // A plan starts at origin_s (the performance's clock): its foot notes
    // from now on; the pushes not yet begun are dropped.
    void start(const GesturePlan &plan, double origin_s, double now_s);
    // A plan under way is replaced (a tempo change, a replan): the notes
    // already scheduled stay, the new plan's later ones follow.
    void replace(const GesturePlan &plan);
    // The performance stops: the pushes not yet begun are dropped.
    void stop(double now_s);

    // The pedal to now_s (the end of a physics step): the notes due within
    // the look-ahead scheduled, the pedal advanced.
    void advance(double now_s);
    // The contacts begun and ended in the step taken. Seqs come from the
    // detector, in onset order with the hands' (first_seq: the detector's
    // first seq of the step); of two feet, the one whose contact began first
    // takes them first (ScoreMode).
    void take_contacts(StrikeDetector &detector, long first_seq);
    // The onset time (s) of the contact begun in the step and not taken yet;
    // +inf for none.
    double next_onset_s() const { return pedal_.next_onset_s(); }
    // The foot's contact begun in the last step (at most one), at its onset.
    bool take_onset(StrikeEvent &out);
    // The foot's contact ended in the last step (at most one).
    bool take_end(StrikeEvent &out);

    // The beater's (the top plate's) speed (m/s) for a note's dynamics 0..1.
    double speed_for(double dynamics) const;
    const KickPedal &pedal() const { return pedal_; }
    int drum_index() const { return drum_; }
    Side side() const { return side_; }

    // How far ahead a note is scheduled (s): more than the foot's longest
    // push (docs/pedal.md).
    static constexpr double kLookAhead_s = 0.5;
    // Where the felt meets the head: above its centre at this fraction of
    // its radius (a 22-inch kick's beater, ~4 cm up; the `kick` preset's
    // strike, docs/sound.md).
    static constexpr double kBeaterRadiusFraction = 0.15;
    // The chick on the hi-hat's plate: at its edge (r/a), toward the
    // performer; its sound excited by this mass at the plates' closing speed
    // (a choice, docs/pedal.md: the plates meet all round their rims, damped
    // at once, and a chick sounds below a hand's hit).
    static constexpr double kChickRadiusFraction = 0.95;
    static constexpr double kChickSoundMass_kg = 0.02;

  private:
    StrikeEvent event_for(const PedalStrike &s) const;

    KickPedal pedal_;
    int drum_ = 0;
    Side side_ = Side::right;
    Eigen::Vector3d force_dir_;
    double radius_m_ = 0.2794;
    // The plan's, in time order: the plan performed (ScoreMode holds it while it is
    // this one's; start() and replace() come with every new one), not a copy.
    const std::vector<PlannedFootNote> *notes_ = nullptr;
    size_t next_ = 0;                    // the first not scheduled
    double origin_s_ = 0.0;
    double last_scheduled_s_ = -1e9; // the latest impact scheduled (performance clock)
    long stroke_ = -1;
    bool onset_new_ = false, end_new_ = false;
    StrikeEvent onset_, end_;
    long open_seq_ = -1; // the contact under way's seq
};

} // namespace ictus
