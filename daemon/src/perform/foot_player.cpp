// A foot of a score's performance (foot_player.hpp).
#include "foot_player.hpp"

#include <algorithm>
#include <cmath>

namespace ictus
{

namespace
{

// The kick's pedal for a kit piece: its head's radius, tension and film
// (KitDrum's; the film as thick as its density says, as membrane~'s head);
// the hi-hat's for the left foot (its plate's bending stiffness and radius).
KickPedalParams pedal_params(const KitDrum &d, Side side)
{
    if (side == Side::left)
        return hihat_pedal_params(d.bending_n_m, d.radius_m);
    KickPedalParams p;
    p.head_radius_m = d.radius_m;
    p.head_tension_n_per_m = d.tension_n_per_m;
    p.head_thickness_m = d.density_kg_per_m2 / 1390.0;
    return p;
}

} // namespace

FootPlayer::FootPlayer(const KitDrum &drum, int drum_index, const Eigen::Vector3d &force_dir,
                       Side side)
    : pedal_(pedal_params(drum, side)), drum_(drum_index), side_(side),
      force_dir_(force_dir.normalized()), radius_m_(drum.radius_m)
{
}

void FootPlayer::start(const GesturePlan &plan, double origin_s, double now_s)
{
    pedal_.cancel_pending(now_s);
    notes_ = &plan.foot_notes;
    origin_s_ = origin_s;
    next_ = 0;
    last_scheduled_s_ = -1e9;
}

void FootPlayer::replace(const GesturePlan &plan)
{
    // The notes at or before the last one scheduled are played already.
    notes_ = &plan.foot_notes;
    next_ = 0;
    while (next_ < notes_->size() &&
           origin_s_ + (*notes_)[next_].time_s <= last_scheduled_s_ + 1e-9)
        ++next_;
}

void FootPlayer::stop(double now_s)
{
    pedal_.cancel_pending(now_s);
    next_ = notes_ ? notes_->size() : 0;
}

double FootPlayer::speed_for(double dynamics) const
{
    // As the hands' strokes: the speed grows as dynamics^1.3 (the stroke
    // heights, docs/gestures.md), over the pedal's range.
    const double lo = pedal_.min_speed_mps(), hi = pedal_.max_speed_mps();
    const double d = std::clamp(dynamics, 0.0, 1.0);
    return lo + (hi - lo) * std::pow(d, 1.3);
}

void FootPlayer::advance(double now_s)
{
    while (notes_ && next_ < notes_->size()) {
        const PlannedFootNote &n = (*notes_)[next_];
        const double t = origin_s_ + n.time_s;
        if (t > now_s + kLookAhead_s)
            break;
        ++next_;
        if (n.side != side_)
            continue; // the other foot's
        // A note whose push would have had to begin already is left out
        // (a plan that starts with a kick at once: the lead-in is longer).
        if (t <= pedal_.time_s() + pedal_.params().stroke_max_s || t <= last_scheduled_s_)
            continue;
        pedal_.schedule(t, speed_for(n.dynamics));
        last_scheduled_s_ = t;
    }
    pedal_.advance_to(now_s);
}

void FootPlayer::take_contacts(StrikeDetector &detector, long first_seq)
{
    PedalStrike s;
    while (pedal_.take_onset(s)) {
        if (!s.bounce)
            ++stroke_;
        onset_ = event_for(s);
        onset_.seq = detector.claim_seq(s.time_s, first_seq, side_ == Side::right ? 0 : 1);
        open_seq_ = onset_.seq;
        onset_new_ = true;
    }
    while (pedal_.take_strike(s)) {
        end_ = event_for(s);
        end_.seq = open_seq_;
        end_new_ = true;
        detector.end_claimed(side_ == Side::right ? 0 : 1);
    }
}

bool FootPlayer::take_onset(StrikeEvent &out)
{
    if (!onset_new_)
        return false;
    onset_new_ = false;
    out = onset_;
    out.peak_force_n = 0.0;
    out.impulse_n_s = 0.0;
    out.duration_ms = 0.0;
    return true;
}

bool FootPlayer::take_end(StrikeEvent &out)
{
    if (!end_new_)
        return false;
    end_new_ = false;
    out = end_;
    return true;
}

StrikeEvent FootPlayer::event_for(const PedalStrike &s) const
{
    StrikeEvent e;
    e.hand = side_ == Side::right ? kFootRight : kFootLeft;
    e.drum = drum_;
    e.bounce = s.bounce;
    e.stroke = std::max(stroke_, 0L);
    e.time_s = s.time_s;
    // The head's frame: x across it (the performer's left), y up; the felt
    // meets it above its centre.
    e.r_over_a = kBeaterRadiusFraction;
    e.theta_deg = 90.0;
    e.x_m = 0.0;
    e.y_m = kBeaterRadiusFraction * radius_m_;
    e.normal_velocity_mps = s.speed_mps;
    e.tangential_velocity_mps = 0.0;
    e.peak_force_n = s.peak_force_n;
    e.impulse_n_s = s.impulse_n_s;
    e.duration_ms = s.duration_ms;
    e.force_dir = force_dir_; // the felt pushes the head away from the performer
    e.stick_mass_kg = s.effective_mass_kg;
    e.stick_tip = stick_tip_code("felt");
    e.zone = kZoneHead;
    if (side_ == Side::left) {
        // The chick: the top plate's edge, toward the performer (the plate's
        // frame as a hand's strike on it), pushed down onto the bottom plate;
        // no tip (metal on metal), the sound's mass (kChickSoundMass_kg).
        e.r_over_a = kChickRadiusFraction;
        e.y_m = kChickRadiusFraction * radius_m_;
        e.stick_mass_kg = kChickSoundMass_kg;
        e.stick_tip = 0;
    }
    return e;
}

} // namespace ictus
