// tempo_map.cpp -- the score's tempo map (docs/score.md): beats to
// seconds and back through steps and linear ramps, and the live tempo
// change that scales a map, or a score's map, from a beat on.
#include "ictus/score/score.hpp"

#include <cmath>
#include <stdexcept>

namespace ictus
{

TempoMap::TempoMap(double initial_bpm)
{
    Change first;
    first.start_bpm = first.end_bpm = initial_bpm;
    changes_.push_back(first);
}

// Time to advance `beats` into a linear ramp from t0 to t1 bpm over
// `ramp_beats`: the integral of 60 / (t0 + k b) db = 60 / k * ln(tempo / t0).
static double ramp_time_s(double t0_bpm, double t1_bpm, double ramp_beats, double beats)
{
    if (beats <= 0.0)
        return 0.0;
    const double k = (t1_bpm - t0_bpm) / ramp_beats; // bpm per beat
    if (std::abs(k) * beats < 1e-9 * t0_bpm)
        return 60.0 * beats / t0_bpm;
    return 60.0 / k * std::log((t0_bpm + k * beats) / t0_bpm);
}

static double change_time_s(const TempoMap::Change &c, double beats_in)
{
    const double in_ramp = std::min(beats_in, c.ramp_beats);
    double t = ramp_time_s(c.start_bpm, c.end_bpm, c.ramp_beats, in_ramp);
    if (beats_in > c.ramp_beats)
        t += 60.0 * (beats_in - c.ramp_beats) / c.end_bpm;
    return t;
}

void TempoMap::add(double beat, double start_bpm, double end_bpm, double ramp_beats)
{
    if (!(start_bpm > 0.0) || !(end_bpm > 0.0) || !(ramp_beats >= 0.0) || !std::isfinite(beat))
        throw std::invalid_argument("TempoMap::add: tempi must be > 0 and ramp >= 0");
    if (beat < changes_.back().beat)
        throw std::invalid_argument("TempoMap::add: changes must come in beat order");
    Change c;
    c.beat = beat;
    c.start_bpm = start_bpm;
    c.end_bpm = end_bpm;
    c.ramp_beats = ramp_beats;
    if (beat == changes_.back().beat) {
        // Two changes at one beat: the later one wins (`tempo 96` at the
        // start replaces the default).
        c.start_time_s = changes_.back().start_time_s;
        changes_.back() = c;
        return;
    }
    c.start_time_s = time_at_beat(beat);
    changes_.push_back(c);
}

const TempoMap::Change &TempoMap::change_at(double beat) const
{
    // The last change at or before `beat`.
    auto it = std::upper_bound(changes_.begin(), changes_.end(), beat,
                               [](double b, const Change &c) { return b < c.beat; });
    return it == changes_.begin() ? changes_.front() : *(it - 1);
}

double TempoMap::tempo_at_beat(double beat) const
{
    const Change &c = change_at(beat);
    const double in = beat - c.beat;
    if (in <= 0.0)
        return c.start_bpm;
    if (in >= c.ramp_beats)
        return c.end_bpm;
    return c.start_bpm + (c.end_bpm - c.start_bpm) * in / c.ramp_beats;
}

double TempoMap::time_at_beat(double beat) const
{
    const Change &c = change_at(beat);
    const double in = beat - c.beat;
    if (in < 0.0) // before beat 0: the first tempo
        return c.start_time_s + 60.0 * in / c.start_bpm;
    return c.start_time_s + change_time_s(c, in);
}

double TempoMap::beat_at_time(double time_s) const
{
    auto it = std::upper_bound(changes_.begin(), changes_.end(), time_s,
                               [](double t, const Change &c) { return t < c.start_time_s; });
    const Change &c = it == changes_.begin() ? changes_.front() : *(it - 1);
    const double dt = time_s - c.start_time_s;
    if (dt < 0.0)
        return c.beat + dt * c.start_bpm / 60.0;
    const double ramp_s = change_time_s(c, c.ramp_beats);
    if (dt >= ramp_s)
        return c.beat + c.ramp_beats + (dt - ramp_s) * c.end_bpm / 60.0;
    // Inverse of ramp_time_s: tempo = t0 exp(k dt / 60), beats = (tempo - t0) / k.
    const double k = (c.end_bpm - c.start_bpm) / c.ramp_beats;
    if (std::abs(k) * c.ramp_beats < 1e-9 * c.start_bpm)
        return c.beat + dt * c.start_bpm / 60.0;
    return c.beat + c.start_bpm * std::expm1(k * dt / 60.0) / k;
}

TempoMap scale_tempo_from(const TempoMap &map, double from_beat, double factor)
{
    const std::vector<TempoMap::Change> &changes = map.changes();
    auto check = [&](double bpm, double beat, double scaled) {
        if (!(scaled >= kMinTempoBpm && scaled <= kMaxTempoBpm)) {
            char buf[200];
            std::snprintf(buf, sizeof buf,
                          "tempo: the score's %g bpm at beat %g would become %.4g bpm (beyond "
                          "%g..%g)",
                          bpm, beat, scaled, kMinTempoBpm, kMaxTempoBpm);
            throw std::invalid_argument(buf);
        }
    };
    TempoMap out(changes.front().start_bpm);
    const TempoMap::Change *running = &changes.front();
    for (const TempoMap::Change &c : changes) {
        if (c.beat >= from_beat)
            break;
        out.add(c.beat, c.start_bpm, c.end_bpm, c.ramp_beats);
        running = &c;
    }
    for (const TempoMap::Change &c : changes)
        if (c.beat <= from_beat)
            running = &c;
    const double here = map.tempo_at_beat(from_beat);
    const double ramp_left = std::max(0.0, running->beat + running->ramp_beats - from_beat);
    check(here, from_beat, factor * here);
    check(running->end_bpm, running->beat + running->ramp_beats, factor * running->end_bpm);
    out.add(from_beat, factor * here, factor * (ramp_left > 0.0 ? running->end_bpm : here),
            ramp_left);
    for (const TempoMap::Change &c : changes) {
        if (c.beat <= from_beat)
            continue;
        check(c.start_bpm, c.beat, factor * c.start_bpm);
        check(c.end_bpm, c.beat + c.ramp_beats, factor * c.end_bpm);
        out.add(c.beat, factor * c.start_bpm, factor * c.end_bpm, c.ramp_beats);
    }
    return out;
}

Score scale_score_from(const Score &score, double from_beat, double factor)
{
    Score out = score;
    out.tempo = scale_tempo_from(score.tempo, from_beat, factor);
    return out;
}

} // namespace ictus
