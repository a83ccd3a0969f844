// gesture_score.hpp -- from a score to motion: the gesture score. Each note
// selects a gesture unit (grip x nuance x hand, scaled by its dynamics),
// time-warped so its strike lands exactly on the note's beat, placed at the
// note's spot on the drum, and co-articulated with the hand's previous and
// next units into one smooth (C1) stick-tip trajectory per hand: the targets
// X^T of the Cartesian controller (paper, Eq. 2 and Figure 5). The method is
// described in docs/score.md.
#pragma once

#include "ictus/character/character.hpp"
#include "ictus/gesture/gesture.hpp"
#include "ictus/score/score.hpp"
#include "ictus/character/stick_capture.hpp"

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace ictus
{

// The stick's direction the planner assumes for units that carry none, and
// the performance for the tip's contact height: butt to tip, 15 degrees below
// the horizontal, forward (y up, the default performer facing +Z).
const Eigen::Vector3d kDefaultStickDirection(0.0, -0.2588190451, 0.9659258263);

// Where the performer and the drum are (world frame, m). The axes are unit
// and orthogonal: right = the performer's right, up, forward = toward the drum.
struct PerformerFrame {
    // Defaults: the Scene's default drum (scene.hpp) and performer_frame_for_drum's rest tips.
    Eigen::Vector3d membrane_center_m = Eigen::Vector3d(0.0, 0.7, 0.45);
    Eigen::Vector3d right = -Eigen::Vector3d::UnitX();
    Eigen::Vector3d up = Eigen::Vector3d::UnitY();
    Eigen::Vector3d forward = Eigen::Vector3d::UnitZ();
    double membrane_radius_m = 0.178;
    // Where each stick tip waits when its hand has nothing to play [Side].
    std::array<Eigen::Vector3d, 2> rest_tip_m = {Eigen::Vector3d(0.1, 0.85, 0.4),
                                                 Eigen::Vector3d(-0.1, 0.85, 0.4)};
    // The shoulders [Side] (performer_frame_for_drum: 0.18 m to each side, 0.45 m
    // behind the membrane's centre): a stroke on a kit's other pieces turns about
    // the vertical as the direction from its hand's shoulder to the strike turns
    // from that to the first drum's centre (piece_yaw_rad).
    std::array<Eigen::Vector3d, 2> shoulder_m = {Eigen::Vector3d(0.18, 1.2, 0.0),
                                                 Eigen::Vector3d(-0.18, 1.2, 0.0)};
    // A kit (docs/perform.md, "A kit"): its drums by name, the first the
    // membrane above (its centre and radius equal membrane_center_m and
    // membrane_radius_m). Empty: the one drum, whose notes name none.
    struct Drum {
        std::string name;
        Eigen::Vector3d membrane_center_m = Eigen::Vector3d::Zero(); // raised as membrane_center_m
        double membrane_radius_m = 0.178;
        bool cymbal = false; // played where a note gives no spot at kCymbal* (score.hpp)
        bool pedal = false;  // a hi-hat: its notes carry the pedal's openness
        // Played by the right foot (the kick, docs/pedal.md): its notes are
        // GesturePlan::foot_notes, never a hand's; membrane_center_m is its
        // upright head's centre, out of the sticks' way.
        bool foot = false;
    };
    std::vector<Drum> drums;
};

// The shared frames (docs/perform.md; the character faces +Z: right = world -X),
// a drum of `radius_m` centred at `membrane_center_m`, and rest tips
// `rest_height_m` above the head, 0.1 m to each side of the centre and
// 0.05 m nearer the performer.
PerformerFrame performer_frame_for_drum(const Eigen::Vector3d &membrane_center_m, double radius_m,
                                        double rest_height_m = 0.15);

// How a hand holds its stick at its rest tip (butt -> tip, unit): forward and
// 15 degrees down (kDefaultStickDirection), turned 40 degrees toward the
// midline. The performer starts and ends every plan in it, and the plan's
// rests (before the first note, between far-apart notes, after the last) ask for it.
Eigen::Vector3d rest_stick_direction(const PerformerFrame &frame, int side);

// The turn about frame.up (rad, > 0 toward the performer's left) that a stroke of hand
// `side` at `strike_m` on kit piece `drum` is given: the horizontal direction from the
// hand's shoulder to the strike, less that to the first drum's centre; 0 on the first
// drum and without a kit. A hand reaching across the kit then holds its stick along its
// forearm, as a drummer does, where a stroke of the first drum's shape would ask the
// wrist for a stick turned back toward the front (and the arm would leave it pitched up).
double piece_yaw_rad(const PerformerFrame &frame, int side, const Eigen::Vector3d &strike_m,
                     int drum);

// A point of the head from the membrane frame of docs/osc.md (x_m = world
// +X, y_m = world -Z, around the centre); of a kit's drum `drum` (0: the first).
Eigen::Vector3d membrane_point(const PerformerFrame &frame, double r_over_a, double theta_deg,
                               int drum = 0);

// One note as it will be played.
struct PlannedNote {
    double time_s = 0.0; // the strike, plan clock (0 = start of the plan)
    Side hand = Side::right;
    Nuance nuance = Nuance::legato;
    Grip grip = Grip::french;
    double dynamics = 0.0;
    double beats = 0.0;
    double tempo_bpm = 0.0;                                        // at the note's beat
    Eigen::Vector3d strike_point_m = Eigen::Vector3d::Zero();      // on the head, world
    Eigen::Vector3d tip_target_m = Eigen::Vector3d::Zero();        // the tip at time_s: strike
                                                                   // point - strike_depth_m * up
    Eigen::Vector3d impact_velocity_mps = Eigen::Vector3d::Zero(); // planned, just before
    double r_over_a = 0.0;
    double theta_deg = 0.0;
    double firmness = -1.0; // ScoreNote::firmness
    int drum = 0;           // the kit's drum (PerformerFrame::drums), 0: the first or only
    // The hi-hat's pedal for a note on a hi-hat (PerformerFrame::Drum::pedal):
    // ScoreNote::openness, closed (0) when the note names none; -1 on any
    // other drum.
    double openness = -1.0;
    int line = 0;           // where the note is written
    int column = 0;
    Grace grace = Grace::none; // a flam's or a drag's grace stroke (ScoreNote::grace)
    // The stroke is planned this long before the note's time (a rehearsal's
    // correction, PlanOptions::note_lead_s): time_s is the planned strike,
    // written_time_s() the note's own time, against which it is judged.
    double lead_s = 0.0;
    int score_note = -1; // the note's index in Score::notes
    double written_time_s() const { return time_s + lead_s; }
};

// A note of a foot (docs/pedal.md): the right foot's (`RF`) on the kick's
// pedal strikes its drum, the left foot's (`LF`) on the hi-hat's pedal closes
// the hi-hat (the chick), at time_s (plan clock) at `dynamics`.
struct PlannedFootNote {
    double time_s = 0.0;
    double dynamics = 0.0;
    // The kit's foot piece (PerformerFrame::Drum::foot) for the right foot,
    // its hi-hat (Drum::pedal) for the left.
    int drum = 0;
    Side side = Side::right; // the foot
    int line = 0, column = 0;
};

// A meter of the score (ScoreMeter) from plan time time_s on.
struct PlannedMeter {
    double time_s = 0.0;
    double beat = 0.0; // in the score
    int numerator = 4;
    int denominator = 4;
};

struct PlanOptions {
    double lead_in_s = 1.0; // time before the score's beat 0 (>= 0.2 s)
    double tail_s = 1.0;    // time after the score's end (>= 0)
    double rate_hz = 1000.0;
    // The target passes this far below the membrane at the strike (the
    // physics helper tunes it; < 0 is above).
    double strike_depth_m = 0.0;
    // And further by (v - strike_aim_from_mps) times this (s), v the planned
    // impact speed: the hand aims through the head as a drummer throws the
    // stick, so that a fast stroke still reaches it although the arm turns a
    // little early (its tracking lag). Soft strokes aim at the head itself
    // (deeper, they press on it).
    double strike_aim_s = 0.0;
    double strike_aim_from_mps = 0.0;
    // The aim's depth goes no deeper than this (m): a deeper aim carries the
    // hand on into the head during a loud stroke's contact.
    double strike_aim_max_m = 0.05;
    // The stick meets the head this far (m) before the plan's tip reaches its
    // target: each unit is placed later by this over its planned downward
    // impact speed, so that soft strokes touch on the beat too.
    double contact_lead_m = 0.0;
    // Co-articulation: the blend between two units of one hand spans the
    // middle of the gap between their strikes, leaving this fraction of the
    // gap at each end to the units alone (0 < f < 0.5).
    double blend_margin = 0.25;
    // The move across the head from one spot to the next takes the whole
    // gap between their strikes but these fractions of it after the first
    // strike and before the second (the units' shapes still blend over the
    // middle, blend_margin): half as fast as a move over the blend alone,
    // which the arm tracks closely (docs/score.md, "From score to motion").
    double move_margin_after = 0.05;
    double move_margin_before = 0.1;
    // A stroke's stick turns about the vertical toward its piece (the reach);
    // between two strokes the turn is made over their blend, or, where that
    // asks the stick to turn faster than this at its peak (rad/s), over as
    // much more of the move as brings it down to this (docs/kit.md, "Reach").
    double max_turn_rate_rad_s = 15.0;
    // A move between two drums of a kit lifts the tip so that, wherever it
    // is over a drum's head (that head's radius and this margin), it stays
    // above it, and this clearance above any drum but the two it plays
    // (docs/score.md, "A kit"): it never meets a shell from the side.
    double kit_clearance_m = 0.03;
    double kit_margin_m = 0.03;
    // A hand with no stroke for longer than this goes back to its rest tip.
    double idle_return_s = 4.0;
    double return_time_s = 0.6; // the move between the rest tip and a stroke
    // Two strokes of one hand closer than this are refused: the shortest
    // interval the simulated body plays as two strokes (docs/score.md,
    // "Rebound strokes", measured).
    double min_stroke_interval_s = 0.04;
    // Two kicks closer than this are refused: the shortest interval the
    // pedal plays as two strokes (docs/pedal.md).
    double min_foot_interval_s = 0.06;
    // Two chicks of the left foot closer than this are refused: the hi-hat's
    // pedal opens again between them (docs/pedal.md).
    double min_chick_interval_s = 0.1;
    double max_duration_s = 900.0; // longer performances are refused
    // Motor noise (docs/humanize.md): the amount, 0 for none;
    // < 0: the score's `humanize` statement (0 when it has none). The seed
    // picks the noise (each note draws its own stream of it).
    double humanize = -1.0;
    std::uint64_t seed = 1;
    // Rehearsal (docs/score.md, "Rehearsal"): each hand note of the score
    // (index into Score::notes) planned this long before its time (s; a late
    // note's lead > 0). Empty, or a note beyond it: 0. Each lead is held to
    // +-kMaxNoteLead_s, and never brings a stroke closer than
    // min_stroke_interval_s to its hand's previous one.
    std::vector<double> note_lead_s;
};

// The largest lead (either way) PlanOptions::note_lead_s may give a note.
constexpr double kMaxNoteLead_s = 0.015;

// The motor noise at amount 1 (docs/humanize.md): each
// stroke's timing is shifted by a normal draw of SD kHumanizeTimingSd_s and
// its dynamics (the motor command) scaled by 1 + a normal draw of SD
// kHumanizeForceCv (signal-dependent noise: its SD grows with the command).
// Both SDs grow in proportion to the amount.
constexpr double kHumanizeTimingSd_s = 0.0025;
constexpr double kHumanizeForceCv = 0.05;
// The amount a plan uses: options.humanize when >= 0, else the score's.
double humanize_amount(const Score &score, const PlanOptions &options);

// The gesture score, ready for the controller.
struct GesturePlan {
    // Both tips, world. Samples every 1 / rate_hz plus one exactly at each
    // strike, so the sampled trajectory passes through each tip target on
    // its beat.
    TipTrajectory tips;
    std::array<std::vector<Eigen::Vector3d>, 2> stick_dir; // [side][frame], unit, butt -> tip
    std::vector<PlannedNote> notes;                        // in time order
    std::vector<PlannedFootNote> foot_notes;               // the feet's, in time order
    std::vector<PlannedMeter> meters;                      // the score's, in order
    double duration_s = 0.0;
    double score_start_s = 0.0; // plan time of the score's beat 0 (= lead_in_s)
};

// Plans the whole performance before anything plays. Throws ScoreError (at
// the note's line and column) for a note its hand cannot play in time or a
// performance too long, (at the word's column) for a hi-hat's openness on a
// drum that is not a hi-hat, std::invalid_argument for bad options or frame, and
// lets GestureError from the database through.
GesturePlan plan_performance(const Score &score, const GestureDatabase &db,
                             const PerformerFrame &frame, const PlanOptions &options = {});

} // namespace ictus
