// strike_event.hpp -- a strike as the rest of the chain sees it: one contact
// episode of a stick tip with the membrane, and its fields declared once
// (name, integer or real, decimals in files). strikes.csv, the events file
// for Pd and the /ictus/strike and /ictus/strike/end OSC messages are each a
// list of these fields (docs/osc.md gives the layouts).
#pragma once

#include <Eigen/Core>
#include <iosfwd>
#include <string>

namespace ictus
{

// A scene holds at most this many drums (a kit, docs/perform.md "A kit"); a
// strike's drum is its index, 0 .. kMaxDrums - 1 (0: the one drum).
constexpr int kMaxDrums = 8;

// One contact episode of a stick tip with the membrane (one row of strikes.csv).
struct StrikeEvent {
    long seq = 0;        // 0, 1, 2 ... in order of onset within a run
    int hand = 0; // the limb: 0 left hand, 1 right hand, 2 right foot (kFootRight), 3 left foot
                  // (kFootLeft)
    int drum = 0;        // the drum's index in the scene (0: the one drum, a kit's first)
    bool bounce = false; // a re-contact of the same stroke
    long stroke = 0;     // per hand: increments on every non-bounce strike
    double time_s = 0.0; // onset, simulation clock, interpolated within the step
    double x_m = 0.0;    // onset position of the bead's lowest point, membrane frame
    double y_m = 0.0;
    double r_over_a = 0.0;                // distance from the centre / membrane radius
    double theta_deg = 0.0;               // atan2(y, x), (-180, 180]
    double normal_velocity_mps = 0.0;     // just before contact, > 0 towards the membrane
    double tangential_velocity_mps = 0.0; // just before contact, magnitude in the plane
    double peak_force_n = 0.0;            // peak normal force (parabola through the samples)
    double impulse_n_s = 0.0;             // integral of F_n over the episode
    double duration_ms = 0.0;             // onset to release (both interpolated)
    Eigen::Vector3d force_dir = Eigen::Vector3d(0.0, -1.0, 0.0); // on the membrane, world, unit
    // The stick's effective mass at the bead along the membrane normal at the
    // onset (the stick on its fulcrum, the grip and the hand: Scene::
    // effective_mass_kg), kg: what a sound model's stick (contact~) weighs.
    double stick_mass_kg = 0.0;
    // The stick's tip (externals/core/stick_tip.h): 0 none (the head's spring
    // alone), 1 wood, 2 nylon, 3 felt (the tip table's index + 1).
    int stick_tip = 0;
    // Where the stick landed: 0 the head, 1 the rim (the stick touched the
    // drum's top edge during the contact, Scene's StickDrumContact::
    // rim_points; docs/osc.md). Known at the release.
    int zone = 0;
    // The hi-hat's pedal for this strike, 0 closed .. 1 open (the note it
    // plays: PlannedNote::openness, given by the performance); < 0: none (not
    // a hi-hat). Not one of the fields below: strikes.csv and /ictus/strike
    // stay as they are; it goes to the sound as its own line and message
    // before the strike when it changes (write_pedal_line, /ictus/kit/pedal).
    double pedal_openness = -1.0;
};
constexpr int kZoneHead = 0, kZoneRim = 1;
// StrikeEvent::hand: the limb that struck. The right foot plays the kick's
// pedal (docs/pedal.md); its strikes are the felt beater's.
constexpr int kHandLeft = 0, kHandRight = 1, kFootRight = 2, kFootLeft = 3;

// The fields of a StrikeEvent, in strikes.csv's column order (and the OSC message's).
enum class StrikeField {
    seq,
    hand,
    drum,
    bounce,
    stroke,
    time_s,
    x_m,
    y_m,
    r_over_a,
    theta_deg,
    normal_velocity_mps,
    tangential_velocity_mps,
    peak_force_n,
    impulse_n_s,
    duration_ms,
    force_dir_x,
    force_dir_y,
    force_dir_z,
    stick_mass_kg,
    stick_tip,
    zone,
};
constexpr int kStrikeFieldCount = static_cast<int>(StrikeField::zone) + 1;

// A strike's stick_tip code for a tip name (stick_tip.h: "wood", "nylon", "felt";
// "" or another name: 0, none), and the name for a code ("" for 0 or out of range).
int stick_tip_code(const std::string &name);
std::string stick_tip_name(int code);

struct StrikeFieldInfo {
    const char *name; // column name, with its unit
    bool integer;     // an integer (seq, hand, ...) or a real
    int decimals;     // fixed decimals of a real in the files
    bool in_osc;      // part of the /ictus/strike message (at the onset)
    bool in_osc_end;  // part of the /ictus/strike/end message (at the release)
};
const StrikeFieldInfo &strike_field_info(StrikeField field);
// A field's value (integers exactly, as doubles).
double strike_field(const StrikeEvent &event, StrikeField field);
long strike_field_integer(const StrikeEvent &event, StrikeField field);

// The layouts: strikes.csv has every field in StrikeField's order; the
// /ictus/strike OSC message those with in_osc and /ictus/strike/end those with
// in_osc_end, in the same order; the events file's `hit` line these, after "hit":
extern const StrikeField kEventsStrikeFields[13];

// strikes.csv: a header line and one line per event, fixed precision (so that
// equal runs give equal bytes).
void write_strikes_csv_header(std::ostream &out);
void write_strike_csv_row(std::ostream &out, const StrikeEvent &event);

// The events file for Pd ([qlist] / [text sequence] format): one line per strike,
//   <delay_ms since previous line> hit <kEventsStrikeFields>;
// The first delay is from time 0. Fixed precision, see docs/osc.md.
void write_events_line(std::ostream &out, const StrikeEvent &event, double previous_time_s);
// A hi-hat's pedal in the events file, before the strike that plays it:
//   <delay_ms since previous line> pedal <drum> <openness>;
// (ictus-render.pd gives it to that drum's membrane~ as `openness`).
void write_pedal_line(std::ostream &out, int drum, double openness, double time_s,
                      double previous_time_s);

} // namespace ictus
