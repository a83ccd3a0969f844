// The interaction manager's strike detection (strike_detector.hpp).
#include "ictus/sim/strike_detector.hpp"

#include "ictus/sim/scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <ostream>

namespace ictus
{

namespace
{
const Eigen::Vector3d kNormal = Eigen::Vector3d::UnitY(); // membrane normal (world y up)

// Vertex of the parabola through three samples, when it is a maximum inside
// them; else the middle sample. Sampled at 1 kHz a 3-6 ms contact has only a
// few force samples, and the largest of them underestimates the peak
// (ode-findings.md); the parabola recovers most of the difference.
double parabola_peak(const double t[3], const double f[3])
{
    const double h0 = t[1] - t[0], h1 = t[2] - t[1];
    if (!(h0 > 0.0 && h1 > 0.0))
        return f[1];
    const double s0 = (f[1] - f[0]) / h0, s1 = (f[2] - f[1]) / h1;
    const double a = (s1 - s0) / (t[2] - t[0]);
    if (!(a < 0.0))
        return f[1];
    // f(t) = f0 + s0 (t - t0) + a (t - t0)(t - t1); f'(t*) = 0.
    const double ts = 0.5 * (t[0] + t[1]) - s0 / (2.0 * a);
    if (ts < t[0] || ts > t[2])
        return f[1];
    const double peak = f[0] + s0 * (ts - t[0]) + a * (ts - t[0]) * (ts - t[1]);
    return std::isfinite(peak) ? std::max(peak, f[1]) : f[1];
}

// The velocity with which the bead crossed the membrane plane between the
// last free sample (gap g0 >= 0) and the first touching one (gap g1 < 0),
// for the two kinds of samples (StrikeDetectorOptions::semi_implicit_samples).
// Either way its normal part is > 0: the step's mean has (g0 - g1) / dt > 0
// since the gap changed sign. The old rule, the free sample's velocity
// regardless, gave re-contacts after a lift smaller than one step's motion a
// negative normal velocity: the still rising bead's.
Eigen::Vector3d approach_velocity(const TipSample &free, double g0, const TipSample &touching,
                                  bool semi_implicit, const Eigen::Vector3d &normal)
{
    const double dt = touching.time_s - free.time_s;
    if (!(dt > 0.0)) // times not increasing (bad input): no speed measurable, never a negative one
        return Eigen::Vector3d::Zero();
    const Eigen::Vector3d mean = (touching.center_m - free.center_m) / dt;
    if (semi_implicit)
        return mean; // the velocity the bead crossed with (p1 = p0 + h v1)
    // A continuous trajectory: the free sample's velocity is free of contact
    // force, exact for a uniform flight, within one step's acceleration
    // otherwise; but only if it could have brought the bead across (towards
    // the membrane, by at least g0). If not (still rising, hovering,
    // creeping), the approach that crossed began inside the step: its mean.
    const double free_approach_mps = -free.velocity_mps.dot(normal);
    if (free_approach_mps > 0.0 && free_approach_mps * dt >= g0)
        return free.velocity_mps;
    return mean;
}
} // namespace

StrikeDetector::StrikeDetector(const MembraneGeometry &membrane,
                               const StrikeDetectorOptions &options)
    : options_(options)
{
    membranes_[0] = membrane;
}

void StrikeDetector::set_membrane(const MembraneGeometry &membrane)
{
    const int d = std::clamp(membrane.drum_id, 0, kMaxDrums - 1);
    membranes_[static_cast<size_t>(d)] = membrane;
    membranes_[static_cast<size_t>(d)].drum_id = d;
    drum_count_ = std::max(drum_count_, d + 1);
}

int StrikeDetector::drum_under(const Eigen::Vector3d &c) const
{
    if (drum_count_ == 1)
        return 0;
    int best = 0;
    double best_out = std::numeric_limits<double>::infinity(), best_gap = best_out;
    for (int d = 0; d < drum_count_; ++d) {
        const MembraneGeometry &m = membranes_[static_cast<size_t>(d)];
        const double out =
            std::max(0.0, std::hypot(c.x() - m.center_m.x(), c.z() - m.center_m.z()) - m.radius_m);
        const double gap = std::abs(gap_m(c, d));
        if (out < best_out || (out == 0.0 && best_out == 0.0 && gap < best_gap)) {
            best = d;
            best_out = out;
            best_gap = gap;
        }
    }
    return best;
}

double StrikeDetector::gap_m(const Eigen::Vector3d &center_m, int drum) const
{
    const MembraneGeometry &m = membranes_.at(static_cast<size_t>(drum));
    return (center_m - m.center_m).dot(kNormal) - m.tip_radius_m;
}

long StrikeDetector::first_open_seq() const
{
    long first = next_seq_;
    for (const Hand &h : hands_)
        if (h.in_contact)
            first = std::min(first, h.event.seq);
    for (long c : claimed_open_seq_)
        if (c >= 0)
            first = std::min(first, c);
    return first;
}

void StrikeDetector::number_in_onset_order(long first_seq)
{
    Hand &a = hands_[0], &b = hands_[1];
    if (!a.in_contact || !b.in_contact || a.event.seq < first_seq || b.event.seq < first_seq)
        return;
    if ((a.event.seq < b.event.seq) != (a.event.time_s < b.event.time_s) &&
        a.event.time_s != b.event.time_s)
        std::swap(a.event.seq, b.event.seq);
}

long StrikeDetector::claim_seq(double onset_time_s, long first_seq, int slot)
{
    long seq = next_seq_++;
    // The hands' onsets of this step after this one move one seq later: the
    // new strike takes the earliest of their seqs (onset order).
    std::array<Hand *, 2> later{};
    int n = 0;
    for (Hand &h : hands_)
        if (h.in_contact && h.event.seq >= first_seq && h.event.time_s > onset_time_s)
            later[static_cast<size_t>(n++)] = &h;
    if (n == 2 && later[1]->event.seq < later[0]->event.seq)
        std::swap(later[0], later[1]);
    if (n == 1) {
        std::swap(seq, later[0]->event.seq);
    } else if (n == 2) {
        const long first = later[0]->event.seq;
        later[0]->event.seq = later[1]->event.seq;
        later[1]->event.seq = seq;
        seq = first;
    }
    claimed_open_seq_[static_cast<size_t>(slot & 1)] = seq;
    return seq;
}

void StrikeDetector::reset(const MembraneGeometry &membrane)
{
    membranes_[0] = membrane;
    membranes_[0].drum_id = 0;
    drum_count_ = 1;
    hands_ = {};
}

double StrikeDetector::normal_force_n(double depth_m, double depth_rate_mps) const
{
    // One-sided spring-damper: the membrane pushes, never pulls.
    return std::max(0.0,
                    cur().stiffness_n_per_m * depth_m + cur().damping_n_s_per_m * depth_rate_mps);
}

double StrikeDetector::gap_m(const Eigen::Vector3d &center_m) const
{
    return (center_m - cur().center_m).dot(kNormal) - cur().tip_radius_m;
}

bool StrikeDetector::on_edge_side(const Eigen::Vector3d &center_m) const
{
    return (center_m - cur().center_m).dot(kNormal) > 0.0 && !over_membrane(center_m);
}

Eigen::Vector3d StrikeDetector::contact_normal(const Eigen::Vector3d &center_m) const
{
    if (!on_edge_side(center_m))
        return kNormal;
    const Eigen::Vector3d d = center_m - cur().center_m;
    const Eigen::Vector3d plan = d - d.dot(kNormal) * kNormal;
    const Eigen::Vector3d off = d - cur().radius_m * plan.normalized(); // from the edge's point
    return off.norm() > 0.0 ? Eigen::Vector3d(off.normalized()) : kNormal;
}

bool StrikeDetector::over_membrane(const Eigen::Vector3d &center_m) const
{
    double x, y;
    to_membrane(center_m, x, y);
    return x * x + y * y <= cur().radius_m * cur().radius_m;
}

void StrikeDetector::to_membrane(const Eigen::Vector3d &world_m, double &x_m, double &y_m) const
{
    const Eigen::Vector3d d = world_m - cur().center_m;
    x_m = d.x();
    y_m = -d.z();
}

bool StrikeDetector::held_driving(const TipSample &a, const TipSample &b) const
{
    return a.held_center_m.allFinite() && b.held_center_m.allFinite() && b.time_s > a.time_s &&
           gap_m(a.held_center_m) > 0.0 &&
           -(b.held_center_m - a.held_center_m).dot(kNormal) / (b.time_s - a.time_s) >=
               options_.driven_speed_mps;
}

bool StrikeDetector::update(int hand, const TipSample &s, StrikeEvent &out)
{
    Hand &h = hands_[static_cast<size_t>(hand & 1)];
    if (drum_count_ > 1 && !h.in_contact && !h.side_entry) {
        const int d = drum_under(s.center_m);
        if (d != h.drum && h.has_previous)
            h.previous_gap = gap_m(h.previous.center_m, d);
        h.drum = d;
    }
    cur_ = h.drum;
    const bool ended = update_hand(h, hand, s, out);
    cur_ = 0;
    return ended;
}

bool StrikeDetector::update_hand(Hand &h, int hand, const TipSample &s, StrikeEvent &out)
{
    // Over the disk, or beside it above the plane, where the bead's nearest
    // point of the drum is the edge circle (the sphere against ODE's solid
    // cylinder); below the plane beside it is the shell's side.
    const bool edge = on_edge_side(s.center_m);
    const double gap =
        edge ? distance_to_rim_m(cur(), s.center_m) - cur().tip_radius_m : gap_m(s.center_m);
    const bool touching = gap < 0.0 && (edge || over_membrane(s.center_m));
    const double depth_rate = -s.velocity_mps.dot(edge ? contact_normal(s.center_m) : kNormal);
    bool ended = false;
    if (entered_from_side(h, s, gap, touching))
        return false;
    if (!h.in_contact && touching)
        begin_contact(h, hand, s, gap);
    if (h.in_contact && touching) {
        continue_contact(h, s, gap, depth_rate);
    } else if (h.in_contact && !touching) {
        end_contact(h, s, gap, depth_rate, out);
        ended = true;
    }
    if (!h.in_contact)
        track_release(h, s, gap, ended);
    if (h.has_previous && held_driving(h.previous, s))
        h.last_driven_s = s.time_s;
    h.previous = s;
    h.previous_gap = gap;
    h.has_previous = true;
    return ended;
}

// A tip that comes in over the disk already below the membrane plane entered
// from the side: that is the shell (or rim), not a strike on the membrane. It
// is ignored until the tip is above the plane again, or out of the disk in
// plan (gone out the way it came: a stick that passed under a cymbal's edge
// on its way down to a drum plays that drum). So is a tip first seen below
// the plane (no approach was observed), uncounted. True while ignored.
bool StrikeDetector::entered_from_side(Hand &h, const TipSample &s, double gap, bool touching)
{
    if (!h.in_contact && touching && !h.side_entry) {
        if (!h.has_previous) {
            h.side_entry = true;
        } else if (h.previous_gap < 0.0) {
            h.side_entry = true;
            ++side_entries_;
        }
    }
    if (!h.side_entry)
        return false;
    if (gap >= 0.0 || !over_membrane(s.center_m))
        h.side_entry = false;
    h.previous = s;
    h.previous_gap = gap;
    return true;
}

// Onset: where the gap crosses zero between the last free sample and this one
// (here previous_gap >= 0 > gap: entered_from_side() left the other cases).
void StrikeDetector::begin_contact(Hand &h, int hand, const TipSample &s, double gap)
{
    const TipSample &before = h.previous;
    const double g0 = h.previous_gap;
    const double frac = g0 > 0.0 ? g0 / (g0 - gap) : 0.0;
    const double t_on = before.time_s + frac * (s.time_s - before.time_s);
    const Eigen::Vector3d p_on =
        before.center_m + frac * (s.center_m - before.center_m) - cur().tip_radius_m * kNormal;
    StrikeEvent &e = h.event;
    e = StrikeEvent();
    e.hand = hand & 1;
    e.drum = cur().drum_id;
    e.time_s = t_on;
    to_membrane(p_on, e.x_m, e.y_m);
    // A bead that met the edge from outside the disk touched it on the edge.
    const double rho = std::hypot(e.x_m, e.y_m);
    if (rho > cur().radius_m) {
        e.x_m *= cur().radius_m / rho;
        e.y_m *= cur().radius_m / rho;
    }
    e.r_over_a = std::hypot(e.x_m, e.y_m) / cur().radius_m;
    e.theta_deg = std::atan2(e.y_m, e.x_m) * 180.0 / M_PI;
    if (e.theta_deg <= -180.0)
        e.theta_deg += 360.0;
    // Normal to what the bead met: the plane, or the edge (its circle's nearest point).
    const Eigen::Vector3d n =
        contact_normal(before.center_m + frac * (s.center_m - before.center_m));
    const Eigen::Vector3d v = approach_velocity(before, g0, s, options_.semi_implicit_samples, n);
    e.normal_velocity_mps = -v.dot(n);
    // On the plane this is > 0 (approach_velocity()). The edge's normal turns
    // within the step: if the bead moved along it, the gap's own rate (> 0).
    if (!(e.normal_velocity_mps > 0.0) && s.time_s > before.time_s)
        e.normal_velocity_mps = (g0 - gap) / (s.time_s - before.time_s);
    e.tangential_velocity_mps = (v - v.dot(n) * n).norm();
    // Driven: the hand moved the stick toward the membrane within the
    // drive window, the onset's own step included (the held bead; a
    // rigid stick or a trajectory has none: always driven).
    const bool driven = !s.held_center_m.allFinite() || held_driving(h.previous, s) ||
                        s.time_s - h.last_driven_s <= options_.drive_window_s + 1e-9;
    e.bounce = h.released_once && (t_on - h.release_time_s) <= options_.bounce_window_s &&
               (h.max_gap_since_release < options_.bounce_height_m ||
                h.max_held_gap_since_release < options_.bounce_height_m || !driven);
    e.stick_mass_kg = s.effective_mass_kg;
    e.stick_tip = s.stick_tip;
    h.rim_force_sum = 0.0;
    h.head_force_sum = 0.0;
    if (!e.bounce)
        ++h.stroke;
    e.stroke = std::max(h.stroke, 0L);
    e.seq = next_seq_++;
    // The force law at the onset (the damper acts at once).
    const double f_on = normal_force_n(0.0, e.normal_velocity_mps);
    h.last_force_n = f_on;
    h.last_time_s = t_on;
    h.friction_sum.setZero();
    h.peak_t[1] = t_on;
    h.peak_f[1] = f_on;
    h.peak_has_before = false;
    h.peak_has_after = false;
    h.in_contact = true;
    h.onset_new = true;
}

// A sample inside the contact: the force law's impulse (trapezoids), the
// friction along the sliding direction, and the largest force sample with its
// neighbours (for the sub-step peak).
void StrikeDetector::continue_contact(Hand &h, const TipSample &s, double gap, double depth_rate)
{
    const double f = normal_force_n(-gap, depth_rate);
    const double dt = s.time_s - h.last_time_s;
    h.rim_force_sum += s.rim_force_n;
    h.head_force_sum += s.head_force_n;
    h.event.impulse_n_s += 0.5 * (h.last_force_n + f) * dt;
    // Kinetic friction on the membrane along the tip's sliding direction.
    const Eigen::Vector3d vt = s.velocity_mps - s.velocity_mps.dot(kNormal) * kNormal;
    if (vt.norm() > 1e-6)
        h.friction_sum += cur().friction * 0.5 * (h.last_force_n + f) * dt * vt.normalized();
    if (f > h.peak_f[1]) {
        h.peak_t[0] = h.last_time_s;
        h.peak_f[0] = h.last_force_n;
        h.peak_has_before = true;
        h.peak_t[1] = s.time_s;
        h.peak_f[1] = f;
        h.peak_has_after = false;
    } else if (!h.peak_has_after && h.peak_t[1] == h.last_time_s) {
        h.peak_t[2] = s.time_s;
        h.peak_f[2] = f;
        h.peak_has_after = true;
    }
    h.last_force_n = f;
    h.last_time_s = s.time_s;
}

// Release where the gap crosses zero again (at once when the tip left the disk
// sideways): the last trapezoid and the event finished into `out`.
void StrikeDetector::end_contact(Hand &h, const TipSample &s, double gap, double depth_rate,
                                 StrikeEvent &out)
{
    double frac = 1.0;
    const double g0 = std::min(h.previous_gap, 0.0);
    if (gap >= 0.0 && g0 < 0.0)
        frac = -g0 / (gap - g0);
    const double t_rel = h.previous.time_s + frac * (s.time_s - h.previous.time_s);
    const double f_rel = normal_force_n(0.0, depth_rate);
    // The step that ends the episode: its contacts were during it.
    h.rim_force_sum += s.rim_force_n;
    h.head_force_sum += s.head_force_n;
    const double dt = t_rel - h.last_time_s;
    h.event.impulse_n_s += 0.5 * (h.last_force_n + f_rel) * dt;
    if (!h.peak_has_after && h.peak_t[1] == h.last_time_s) {
        h.peak_t[2] = t_rel;
        h.peak_f[2] = f_rel;
        h.peak_has_after = true;
    }
    finish(h, t_rel, out);
}

// Out of contact: how high the bead and the held bead rose since the release
// (from this sample on when the contact ended just now).
void StrikeDetector::track_release(Hand &h, const TipSample &s, double gap, bool ended)
{
    const double held_gap = s.held_center_m.allFinite() ? gap_m(s.held_center_m) : gap;
    if (ended) {
        h.max_gap_since_release = std::max(gap, 0.0);
        h.max_held_gap_since_release = std::max(held_gap, 0.0);
    } else {
        h.max_gap_since_release = std::max(h.max_gap_since_release, gap);
        h.max_held_gap_since_release = std::max(h.max_held_gap_since_release, held_gap);
    }
}

bool StrikeDetector::take_onset(int hand, StrikeEvent &out)
{
    Hand &h = hands_[hand & 1];
    if (!h.onset_new)
        return false;
    h.onset_new = false;
    out = h.event;
    out.peak_force_n = 0.0;
    out.impulse_n_s = 0.0;
    out.duration_ms = 0.0;
    out.force_dir = Eigen::Vector3d(0.0, -1.0, 0.0);
    return true;
}

void StrikeDetector::finish(Hand &h, double release_time_s, StrikeEvent &out)
{
    StrikeEvent &e = h.event;
    e.duration_ms = (release_time_s - e.time_s) * 1e3;
    e.peak_force_n =
        (h.peak_has_before && h.peak_has_after) ? parabola_peak(h.peak_t, h.peak_f) : h.peak_f[1];
    // Force on the membrane: the normal impulse pushes it down, friction drags it along.
    const Eigen::Vector3d total = -e.impulse_n_s * kNormal + h.friction_sum;
    e.force_dir =
        total.norm() > 0.0 ? Eigen::Vector3d(total.normalized()) : Eigen::Vector3d(-kNormal);
    // The samples are the physics' equal steps: the sums' ratio is the impulses'.
    e.zone = h.rim_force_sum > 0.0 && h.rim_force_sum >= h.head_force_sum ? kZoneRim : kZoneHead;
    out = e;
    h.in_contact = false;
    h.released_once = true;
    h.release_time_s = release_time_s;
}

bool StrikeDetector::flush(StrikeEvent &out)
{
    for (Hand &h : hands_)
        if (h.in_contact) {
            finish(h, h.last_time_s, out);
            return true;
        }
    return false;
}

// ---- a Scene's strikes -------------------------------------------------------

MembraneGeometry membrane_of(const Scene &scene, int drum_id)
{
    MembraneGeometry m;
    const DrumParams &d = scene.drum(drum_id);
    m.center_m = d.center_m;
    m.radius_m = d.radius_m;
    m.tip_radius_m = scene.model().options().stick.tip_radius_m;
    m.stiffness_n_per_m = scene.drum_contact_stiffness_n_per_m(drum_id);
    m.damping_n_s_per_m = d.contact_damping_n_s_per_m;
    m.friction = d.friction;
    m.drum_id = drum_id;
    m.plate = d.plate_bending_n_m > 0.0;
    return m;
}

double distance_to_rim_m(const MembraneGeometry &membrane, const Eigen::Vector3d &point_m)
{
    const Eigen::Vector3d d = point_m - membrane.center_m;
    const double h = d.dot(kNormal);
    const double rho = (d - h * kNormal).norm();
    return std::hypot(rho - membrane.radius_m, h);
}

bool stick_on_rim(const Scene &scene, int hand, const MembraneGeometry &membrane, bool *bead_on_rim)
{
    const Side side = static_cast<Side>(hand & 1);
    const StickParams &sp = scene.model().options().stick;
    const StickInHand &st = scene.model().stick(side);
    const Eigen::Vector3d bead = scene.bead_position(side);
    const bool bead_reaches = distance_to_rim_m(membrane, bead) < sp.tip_radius_m;
    if (bead_on_rim)
        *bead_on_rim = bead_reaches;
    if (bead_reaches)
        return true;
    // The shaft's segment (Scene's capsule): from one shaft radius behind the
    // bead's centre to one shaft radius before the butt. The distance to the
    // circle along it: 64 samples, then a golden-section search around the
    // nearest (the distance is smooth along the segment).
    const Eigen::Vector3d back = -scene.stick_axis(side);
    const double r = sp.shaft_radius_m;
    const double len = (st.tip_m - sp.tip_radius_m * st.axis - st.butt_m).norm() - 2.0 * r;
    auto dist = [&](double s) { return distance_to_rim_m(membrane, bead + (r + s) * back); };
    constexpr int kSamples = 64;
    int best = 0;
    double best_d = dist(0.0);
    for (int i = 1; i <= kSamples; ++i) {
        const double d = dist(len * i / kSamples);
        if (d < best_d) {
            best_d = d;
            best = i;
        }
    }
    double lo = len * std::max(best - 1, 0) / kSamples,
           hi = len * std::min(best + 1, kSamples) / kSamples;
    constexpr double kGolden = 0.6180339887498949;
    for (int it = 0; it < 40; ++it) {
        const double a = hi - kGolden * (hi - lo), b = lo + kGolden * (hi - lo);
        if (dist(a) < dist(b))
            hi = b;
        else
            lo = a;
    }
    return std::min(best_d, dist(0.5 * (lo + hi))) < r;
}

StickDrumForces stick_drum_forces(const Scene &scene, int hand, const MembraneGeometry &membrane)
{
    StickDrumForces f;
    const StickDrumContact &c = scene.drum_contact(static_cast<Side>(hand & 1));
    if (c.bead_points + c.shaft_points == 0)
        return f;
    bool bead_on_rim = false;
    const bool on_rim = !membrane.plate && stick_on_rim(scene, hand, membrane, &bead_on_rim);
    const double bead_n = c.bead_force_n.norm(), shaft_n = c.shaft_force_n.norm();
    (bead_on_rim ? f.rim_n : f.head_n) += bead_n;
    (on_rim ? f.rim_n : f.head_n) += shaft_n;
    return f;
}

void load_membranes(StrikeDetector &detector, const Scene &scene)
{
    detector.reset(membrane_of(scene, 0));
    for (int i = 1; i < scene.drum_count(); ++i)
        detector.set_membrane(membrane_of(scene, i));
}

int detect_strikes(StrikeDetector &detector, const Scene &scene, StrikeEvent out[2],
                   double time_offset_s)
{
    int n = 0;
    const long first_seq = detector.strikes();
    for (int hand = 0; hand < 2; ++hand) {
        const Side side = static_cast<Side>(hand);
        TipSample s;
        s.time_s = time_offset_s + scene.time_s();
        s.center_m = scene.bead_position(side);
        s.velocity_mps = scene.bead_velocity(side);
        s.held_center_m = scene.held_bead_position(side);
        // Only near the head, where a contact may begin (a 7 x 7 solve).
        const int drum = detector.drum_under(s.center_m);
        const StickDrumForces f = stick_drum_forces(scene, hand, detector.membrane(drum));
        s.rim_force_n = f.rim_n;
        s.head_force_n = f.head_n;
        if (detector.gap_m(s.center_m, drum) < 0.02) {
            s.effective_mass_kg = scene.effective_mass_kg(side, Eigen::Vector3d::UnitY(), drum);
            s.stick_tip = stick_tip_code(scene.options().drum.stick_tip); // the sticks' tip
        }
        if (detector.update(hand, s, out[n]))
            ++n;
    }
    detector.number_in_onset_order(first_seq);
    return n;
}

} // namespace ictus
