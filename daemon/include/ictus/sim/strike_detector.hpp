// strike_detector.hpp -- the interaction manager's strike detection (paper, "Motion-Sound
// Physics Mapping" and Figure 3): from the stick tips' states, step by step,
// the contact episodes of each tip with the drum membrane, each reported when
// it ends as a StrikeEvent (onset time, position, pre-contact velocity, force
// direction and amplitude, impulse, duration, bounce tag).
//
// The contact law is the Scene's: the membrane pushes the tip's bead (a sphere
// of radius r_tip) with a spring-damper normal to the membrane,
//     F_n = max(0, k d + c d'),   k = 2 pi T / ln(R / r_tip)   (scene.hpp),
// where d is the penetration of the bead below the membrane plane. The
// detector evaluates that law on the sampled tip states, so it needs nothing
// from inside ODE. See docs/osc.md for the CSV columns and the OSC layout.
#pragma once

#include "ictus/sim/strike_event.hpp"

#include <limits>

#include <Eigen/Core>
#include <array>
#include <cmath>

namespace ictus
{

// The drum as the detector sees it: a disk in a plane (world frame, y up).
// Membrane coordinates: x_m along world +X, y_m along world -Z, normal +Y
// (right-handed, x_m × y_m = normal); theta = atan2(y_m, x_m) in degrees.
struct MembraneGeometry {
    Eigen::Vector3d center_m = Eigen::Vector3d(0.0, 0.7, 0.45);
    double radius_m = 0.178;
    double stiffness_n_per_m = 5825.0; // k of the contact law
    double damping_n_s_per_m = 10.0;   // c of the contact law
    double friction = 0.3;             // Coulomb coefficient (force direction only)
    double tip_radius_m = 0.007;       // the bead's radius
    int drum_id = 0;
    bool plate = false; // a cymbal: its edge is the plate's, no rim (every strike on its head)
};

struct StrikeDetectorOptions {
    // A new contact of the same hand is a bounce (same stroke) when it starts
    // within bounce_window_s of the previous release AND, since that release,
    // the bead did not rise more than bounce_height_m above the membrane OR
    // the hand did not lift the stick by that much (the held bead,
    // TipSample::held_center_m: a stick rebounding on its fulcrum while the
    // hand stays down strikes again by itself).
    double bounce_height_m = 0.01;
    double bounce_window_s = 0.15;
    // ... OR the hand has not driven the stick toward the membrane in the
    // drive_window_s before the onset: the held bead moved toward it slower
    // than driven_speed_mps all that time (still or rising). The stick then
    // falls back onto the head by itself (a loose grip after a press, the
    // stick turning down on its fulcrum as the hand lifts): the same stroke,
    // however high it had risen. (A stroke's hand may stop just before the
    // contact while the stick whips on: hence the window, not the onset's
    // step alone.)
    double driven_speed_mps = 0.1;
    double drive_window_s = 0.02;
    // How the samples were made, which decides the velocity that crossed the
    // membrane plane (the pre-contact velocity of a strike):
    // true, the Scene's physics steps: each sample's velocity is the one that
    // carried the bead from the previous sample (semi-implicit Euler, p1 =
    // p0 + h v1, and no contact acts in the step that crosses the plane: ODE
    // collides at the step's start), so the crossing velocity is the step's
    // (p1 - p0) / h.
    // false, samples of a continuous trajectory (a kinematic reference, an
    // analytic motion): the last free sample's velocity when it could have
    // carried the bead across within the step, else the step's mean.
    bool semi_implicit_samples = true;
};

// Tip state fed to the detector: the centre of the bead (not the stick's end
// point) and its velocity, world frame, at simulation time time_s.
struct TipSample {
    double time_s = 0.0;
    Eigen::Vector3d center_m = Eigen::Vector3d::Zero();
    Eigen::Vector3d velocity_mps = Eigen::Vector3d::Zero();
    // The bead's centre where the hand holds it (the stick at its fulcrum's
    // rest angle); NaN: the same as center_m (a rigid stick, a trajectory).
    Eigen::Vector3d held_center_m = Eigen::Vector3d::Constant(std::nan(""));
    // The stick's effective mass at the bead along the normal (kg; 0: not
    // known), copied into a strike that begins at this sample.
    double effective_mass_kg = 0.0;
    // The stick's tip (StrikeEvent::stick_tip's code), copied likewise.
    int stick_tip = 0;
    // The force (N, magnitude) the stick puts on the drum's rim and on its
    // head at this sample (stick_drum_forces): a contact episode whose rim
    // force, summed over its samples, is at least its head force is a strike
    // on the rim (StrikeEvent::zone).
    double rim_force_n = 0.0;
    double head_force_n = 0.0;
};

class StrikeDetector
{
  public:
    explicit StrikeDetector(const MembraneGeometry &membrane = {},
                            const StrikeDetectorOptions &options = {});

    // Changes take effect for the next contact (an ongoing one keeps its law).
    // Sets the membrane of drum membrane.drum_id (0 .. kMaxDrums - 1; a kit
    // gives each of its drums so, drum 0 first after a reset).
    void set_membrane(const MembraneGeometry &membrane);
    // A new membrane (drum 0, the only one) and no contact history (the
    // scene was rebuilt); strike numbers continue.
    void reset(const MembraneGeometry &membrane);
    const MembraneGeometry &membrane() const { return membranes_[0]; }
    // A kit: each hand's contacts are with the drum under its bead
    // (drum_under()), which it keeps through a contact; a strike carries its
    // index (StrikeEvent::drum).
    int drum_count() const { return drum_count_; }
    const MembraneGeometry &membrane(int drum) const { return membranes_.at(drum); }
    // The drum whose disk the point is over (of two, the one whose membrane
    // is nearest below it), else the one whose rim is nearest in plan view.
    int drum_under(const Eigen::Vector3d &center_m) const;
    // gap_m() to drum `drum`'s membrane.
    double gap_m(const Eigen::Vector3d &center_m, int drum) const;
    const StrikeDetectorOptions &options() const { return options_; }

    // Feeds one sample per hand per physics step, times increasing. Returns
    // true and fills `out` when this sample ends a contact episode of that hand.
    bool update(int hand, const TipSample &sample, StrikeEvent &out);
    // The contact that began in the last update() of `hand`, once: the
    // strike's onset fields (seq, hand, bounce, stroke, time, position,
    // velocities: all a sound needs); peak force, impulse and duration are
    // not known yet (0) and come with update()'s event at the release.
    bool take_onset(int hand, StrikeEvent &out);
    // Ends ongoing contacts (end of a run): true and fills `out` for one of them
    // per call, release at the last sample's time.
    bool flush(StrikeEvent &out);

    // Contact force law at penetration d (m, > 0 inside) and rate d' (m/s),
    // and the gap and disk below, of drum 0 (inside update(): of the hand's drum).
    double normal_force_n(double depth_m, double depth_rate_mps) const;
    // Gap between the bead and the membrane plane (m, < 0: penetrating), and
    // whether the bead is over the membrane disk.
    double gap_m(const Eigen::Vector3d &center_m) const;
    bool over_membrane(const Eigen::Vector3d &center_m) const;
    // Whether the bead is above the plane outside the disk, where its nearest
    // point of the drum's top is the edge circle (update() then takes its gap
    // as the distance to that circle, distance_to_rim_m(): a bead that meets
    // only the edge, a stroke on the hoop).
    bool on_edge_side(const Eigen::Vector3d &center_m) const;
    // The normal of what the bead would meet there: the plane's (up), or on
    // the edge's side the direction from the edge circle's nearest point.
    Eigen::Vector3d contact_normal(const Eigen::Vector3d &center_m) const;
    // Whether the held bead moved toward the membrane at driven_speed_mps or
    // faster from a to b, starting above the membrane plane (false when
    // either has none): a hand pressing its stick into the head (a buzz) is
    // not driving a stroke.
    bool held_driving(const TipSample &a, const TipSample &b) const;
    bool in_contact(int hand) const { return hands_[hand].in_contact; }
    long strikes() const { return next_seq_; }
    // The smallest seq of a contact still under way (strikes() when none): every
    // strike numbered below it has been reported (or was lost to a reset).
    long first_open_seq() const;
    // Strikes numbered from first_seq on that began in the same step, numbered in
    // onset order: two hands whose contacts begin in one step get their seq by
    // their interpolated onset times, not by the order the hands were updated.
    void number_in_onset_order(long first_seq);
    // A seq for a strike found elsewhere (a foot's pedal: slot 0 the right
    // foot's, 1 the left's) with its onset at onset_time_s in this step: the
    // hands' onsets of the step (seq >= first_seq) keep onset order with it.
    // It is open (first_open_seq() counts it) until end_claimed(slot).
    long claim_seq(double onset_time_s, long first_seq, int slot = 0);
    void end_claimed(int slot = 0) { claimed_open_seq_[static_cast<size_t>(slot & 1)] = -1; }
    // Tips that came over the disk from the side below the membrane plane (shell hits, not
    // strikes).
    long side_entries() const { return side_entries_; }

  private:
    struct Hand {
        bool has_previous = false;
        TipSample previous;
        double previous_gap = 0.0;
        bool in_contact = false;
        bool side_entry = false; // came in below the plane from outside the disk
        // The episode under way.
        StrikeEvent event;
        double last_force_n = 0.0;
        double last_time_s = 0.0;
        // The largest force sample and its neighbours (sub-step peak by a parabola).
        double peak_t[3] = {0, 0, 0}, peak_f[3] = {0, 0, 0};
        bool peak_has_before = false, peak_has_after = false;
        Eigen::Vector3d friction_sum = Eigen::Vector3d::Zero(); // sum of F dt, tangential
        // The stick's force on the rim and on the head, summed over the samples.
        double rim_force_sum = 0.0, head_force_sum = 0.0;
        // Since the last release.
        bool released_once = false;
        double release_time_s = 0.0;
        double max_gap_since_release = 0.0;
        double max_held_gap_since_release = 0.0;
        // When the held bead last moved toward the membrane at
        // driven_speed_mps or faster (-inf: never, or no held bead).
        double last_driven_s = -std::numeric_limits<double>::infinity();
        long stroke = -1;
        bool onset_new = false; // take_onset() has not seen this contact yet
        int drum = 0;           // the drum under the bead (kept through a contact)
    };
    const MembraneGeometry &cur() const { return membranes_[static_cast<size_t>(cur_)]; }
    // update()'s parts: a tip below the plane that came in from the side, a
    // contact's onset, a sample inside it, its release, and the heights
    // since the release (the bounce rule's).
    bool update_hand(Hand &h, int hand, const TipSample &s, StrikeEvent &out);
    bool entered_from_side(Hand &h, const TipSample &s, double gap, bool touching);
    void begin_contact(Hand &h, int hand, const TipSample &s, double gap);
    void continue_contact(Hand &h, const TipSample &s, double gap, double depth_rate);
    void end_contact(Hand &h, const TipSample &s, double gap, double depth_rate, StrikeEvent &out);
    void track_release(Hand &h, const TipSample &s, double gap, bool ended);
    void finish(Hand &h, double release_time_s, StrikeEvent &out);
    void to_membrane(const Eigen::Vector3d &world_m, double &x_m, double &y_m) const;

    std::array<MembraneGeometry, kMaxDrums> membranes_{};
    int drum_count_ = 1;
    int cur_ = 0; // the drum update() works on (0 outside it)
    StrikeDetectorOptions options_;
    std::array<Hand, 2> hands_;
    long next_seq_ = 0;
    long side_entries_ = 0;
    std::array<long, 2> claimed_open_seq_{-1, -1}; // claim_seq()'s strikes under way, -1: none
};

class Scene;

// The membrane of a Scene's drum as the detector sees it: the same disk and the
// same contact law (k, c, friction, the sticks' bead radius).
MembraneGeometry membrane_of(const Scene &scene, int drum_id = 0);
// The detector reset to all the scene's drums (reset() with drum 0, then
// set_membrane() with each other): no allocation.
void load_membranes(StrikeDetector &detector, const Scene &scene);

// Feeds the detector both beads of `scene` (Scene::bead_position/velocity) at
// the scene's time, once after each of its steps; writes the strikes ended in
// that step to out[0..n) and returns n (<= 2). `time_offset_s` is added to
// the scene's clock (a run that rebuilt its scene keeps one clock).
int detect_strikes(StrikeDetector &detector, const Scene &scene, StrikeEvent out[2],
                   double time_offset_s = 0.0);

// The distance (m) from a point to the rim of `membrane`: the circle of its
// radius in the membrane plane, where the drum's shell and hoop hold the head.
double distance_to_rim_m(const MembraneGeometry &membrane, const Eigen::Vector3d &point_m);
// Whether the stick of `hand` (0 left, 1 right) of `scene` reaches the rim of
// `membrane` now: its collision geometry (the bead, a sphere of the tip
// radius, and the shaft, a capsule of the shaft radius from the bead back to
// the butt) reaches the rim circle. `bead_on_rim` tells which part: the bead
// (true) or the shaft alone (false).
bool stick_on_rim(const Scene &scene, int hand, const MembraneGeometry &membrane,
                  bool *bead_on_rim = nullptr);
// The forces (N, magnitudes of Scene::drum_contact's) the stick of `hand` puts
// on the rim of `membrane` and on its head now: the bead's goes to the rim when
// the bead reaches the rim circle, else to the head; the shaft's to the rim
// when the shaft reaches it, else to the head (the shaft lying on the head).
// A strike is on the rim when the rim takes at least half of the blow
// (StrikeEvent::zone, docs/rim.md).
struct StickDrumForces {
    double rim_n = 0.0;
    double head_n = 0.0;
};
StickDrumForces stick_drum_forces(const Scene &scene, int hand, const MembraneGeometry &membrane);

} // namespace ictus
