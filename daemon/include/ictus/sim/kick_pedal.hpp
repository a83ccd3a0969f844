// A bass-drum pedal played by a foot (docs/pedal.md): one degree of freedom, the beater's
// angle about its axle, held back by a return spring against its rest stop, pulled toward
// the head by a footboard through a one-sided chain, thrown into the bass drum's head and
// met there by the project's contact law (externals/core/stick_tip.h: the felt tip in
// series with the head's point stiffness and stretching). Standalone: no ODE, no scene.
// The same model plays the hi-hat's pedal (hihat_pedal_params(), docs/pedal.md "The
// hi-hat's pedal"): the top plate on its rod, the travel L phi, closed on the bottom plate.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <vector>

namespace ictus
{

/// The pedal, the beater, the head and the foot's limits (docs/pedal.md has each value's
/// source or says it is a choice). Angles in rad, from the beater's rest stop toward the head.
struct KickPedalParams {
    // The beater.
    double beater_length_m = 0.20;   // axle to the felt's centre
    double felt_mass_kg = 0.040;     // the felt head (a point mass at beater_length_m)
    double shaft_mass_kg = 0.044;    // a uniform steel rod, axle to felt (inertia m L^2 / 3)
    double felt_radius_m = 0.030;    // the felt's radius where it meets the head
    double axle_inertia_kg_m2 = 0.0; // cam, sprocket, hub: added to the beater's inertia
    // The return spring at the axle: torque -(preload + stiffness * phi).
    double spring_stiffness_n_m_per_rad = 0.40;
    double spring_preload_n_m = 0.20;
    double axle_damping_n_m_s = 0.0005; // viscous, torque -c * phi_dot
    // Geometry and drive.
    double phi_head_rad = 0.7853981633974483; // 45 degrees: the felt touches the head
    double chain_ratio = 5.0;                 // beater angle per footboard angle (chain taut)
    // The head (the `kick` preset): radius, tension, film thickness, film modulus and
    // Poisson's ratio (modulus 0: a linear head, no stretching).
    double head_radius_m = 0.2794;
    double head_tension_n_per_m = 556.0;
    double head_thickness_m = 0.345 / 1390.0;
    double head_modulus_pa = 4.5e9;
    double head_poisson = 0.38;
    // A plate instead of a head (the hi-hat's pedal): > 0 is the struck surface's linear
    // point stiffness (N/m), used instead of the membrane's (no stretching).
    double surface_stiffness_n_per_m = 0.0;
    // The tip between beater and surface: true the felt's law in series with the surface;
    // false the surface alone, linear, with Hunt-Crossley's mu (s/m) (metal on metal).
    bool felt_tip = true;
    double surface_mu_s_per_m = 0.0;
    // Integration and the foot.
    double substep_s = 1.0 / 48000.0;
    double min_speed_mps = 1.0;   // the softest note schedule() plans
    double max_speed_mps = 6.0;   // the hardest (reachable 60 ms after any other note)
    double stroke_min_s = 0.025;  // the shortest ankle stroke (footboard down)
    double stroke_max_s = 0.120;  // the longest (the softest notes with room to spare)
    double throw_fraction = 0.85; // the foot takes the beater at most this far of phi_head
};

/// The hi-hat's pedal as a KickPedal (docs/pedal.md, "The hi-hat's pedal"): the top plate,
/// its clutch and rod as a point mass on a lever of length L (its travel L phi, closed at
/// L phi_head = the gap), the return spring's net force (spring less the weight) and
/// stiffness as torques, the plates meeting by the plate's point stiffness 16 pi D / R^2 of
/// each plate in series (bending_n_m D, radius_m R: the kit's hi-hat), no felt.
KickPedalParams hihat_pedal_params(double bending_n_m, double radius_m);

/// A strike of the beater on the head: one contact episode.
struct PedalStrike {
    double time_s = 0.0;    // onset (interpolated within the substep)
    double speed_mps = 0.0; // the felt's speed normal to the head just before contact, > 0
    double peak_force_n = 0.0;
    double impulse_n_s = 0.0;
    double duration_ms = 0.0;
    double effective_mass_kg = 0.0; // the beater's inertia about the axle / L^2
    bool bounce = false;            // a re-contact of the same push (no new push between)
};

class KickPedal
{
  public:
    /// Validates p (SimError naming the field and its range).
    explicit KickPedal(const KickPedalParams &p = KickPedalParams());
    const KickPedalParams &params() const { return p_; }

    /// Plans the foot so that the beater's first contact of this push is at impact_time_s
    /// with speed impact_speed_mps (clamped to [min, max]); returns the speed it will reach.
    /// SimError for a time already past (or before a pending note), or non-finite arguments.
    double schedule(double impact_time_s, double impact_speed_mps);
    double min_speed_mps() const { return p_.min_speed_mps; }
    double max_speed_mps() const { return p_.max_speed_mps; }

    /// Advances from the current time to t_s (>= current) in internal substeps.
    void advance_to(double t_s);
    /// The oldest strike whose contact ended; false when there is none.
    bool take_strike(PedalStrike &out);
    /// The oldest contact begun (its onset fields: time, speed, effective mass, bounce; the
    /// rest 0), each once, before take_strike() has it; false when there is none.
    bool take_onset(PedalStrike &out);
    /// The time (s) of the oldest contact begun and not taken yet by take_onset(); +inf when
    /// there is none.
    double next_onset_s() const;
    /// Drops the pushes not begun by t_s (a performance that stops): the foot stays up.
    void cancel_pending(double t_s);
    /// The beater's effective mass at the felt, I / L^2 (kg).
    double effective_mass_kg() const
    {
        return inertia_ / (p_.beater_length_m * p_.beater_length_m);
    }

    double time_s() const { return t_; }
    double beater_angle_rad() const { return s_.phi; }
    double footboard_angle_rad() const;
    double phi_head_rad() const { return p_.phi_head_rad; }

    // Beyond the planned API: the state, for tests and for a caller that starts mid-motion.
    double beater_velocity_rad_s() const { return s_.omega; }
    /// The beater's kinetic energy plus the spring's potential energy relative to the stop (J).
    double energy_j() const;
    /// The beater's inertia about the axle (kg m^2).
    double inertia_kg_m2() const { return inertia_; }
    /// Puts the beater at phi (in [0, phi_head]) with angular velocity omega; pending
    /// pushes are kept but were planned for the old state (notes may miss their marks).
    /// SimError for values out of range or non-finite.
    void set_beater(double phi_rad, double omega_rad_s);
    /// The contact force (N) at the felt's depth d (m, > 0 into the head) and its rate (m/s).
    double contact_force_n(double depth_m, double depth_rate_mps) const;

  private:
    // One push of the foot (foot_at): from the foot's state at t0 up to the angle a, reached
    // with the speed vt, over rise_s; a stop over stop_s; the release to 0 over rise_s.
    struct Push {
        double t0 = 0.0, rise_s = 0.05, stop_s = 0.01, a = 0.0, vt = 0.0;
        double p0 = 0.0, v0 = 0.0, acc0 = 0.0;
        double impact_time_s = 0.0; // planned first contact
        bool credited = false;      // its first contact has happened
    };
    struct State {
        long long n = 0; // substeps taken from t = 0
        double phi = 0.0, omega = 0.0;
        bool in_contact = false;
        PedalStrike cur; // the contact episode being measured
    };
    struct FootState {
        double pos, vel, acc;
    };

    struct Plan {
        bool found = false;
        Push push;
        double speed = 0.0, onset = -1.0;
    };

    // A push found from rest (the beater on its stop, the foot up, no contact): the same
    // push, shifted in time, plays the same speed from rest at any time (up to the substep
    // grid), so schedule() tries it first for that speed.
    struct RestPlan {
        bool valid = false;
        double speed = 0.0;  // the speed asked (clamped)
        double lead_s = 0.0; // impact time - the push's start
        Push push;           // its shape (t0 and impact time are set when used)
    };
    bool at_rest(double t) const;
    bool plan_from_rest(const KickPedal &base, double t_lo, double t_imp, double v, Plan &out);

    FootState foot_at(double t, std::size_t upto) const;
    void step();
    void record(const PedalStrike &s);
    double onset_first_contact(double horizon_s, double &speed, State *pre);
    double stop_time(double rise) const { return std::min(0.5 * rise, 0.015); }
    Plan plan_at(const KickPedal &base, KickPedal &pre, double t0, double t_imp, double v,
                 double rise) const;
    Plan plan_rise(const KickPedal &base, double t_lo, double t_imp, double v, double rise) const;

    KickPedalParams p_;
    double inertia_ = 0.0, k1_ = 0.0, k3_ = 0.0;
    double tip_k_ = 0.0, tip_alpha_ = 0.0, tip_mu_ = 0.0;
    double t_ = 0.0;
    State s_;
    std::vector<Push> pushes_;
    // Finished strikes: a fixed ring (no allocation in step()); the oldest is dropped when full.
    static constexpr std::size_t kRing = 256;
    std::array<PedalStrike, kRing> ring_{};
    std::size_t ring_head_ = 0, ring_count_ = 0;
    std::array<RestPlan, 16> rest_plans_{};
    std::size_t rest_next_ = 0; // the slot the next one takes (round robin)
    // The onsets not yet taken (a ring of the same kind).
    std::array<PedalStrike, 8> onsets_{};
    std::size_t onset_head_ = 0, onset_count_ = 0;
    // The planner's anchor: the state at the last planned first contact (pushes after it
    // cannot change what happens before it), so planning starts there, not at time_s().
    bool anchor_valid_ = false;
    State anchor_;
};

} // namespace ictus
