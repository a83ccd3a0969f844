// What `ictusd render` reports of a performance (render_report.hpp).
#include "render_report.hpp"

#include "ictus/sim/kick_pedal.hpp"
#include "ictus/sim/strike_event.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>

namespace ictus
{
namespace cli
{

namespace
{

// A kit's foot piece (the kick) as render.json has it: where its upright
// head stands, its head, and the pedal that plays it (docs/pedal.md).
nlohmann::json foot_piece_json(const Performance &p, const KitDrum &k)
{
    const Eigen::Vector3d c = p.foot_piece_center_m();
    const KickPedal *pedal = p.kick_pedal();
    nlohmann::json j = {{"name", k.name},
                        {"preset", k.preset},
                        {"center_m", {c.x(), c.y(), c.z()}},
                        {"radius_m", k.radius_m},
                        {"tension_n_per_m", k.tension_n_per_m},
                        {"bending_n_m", 0.0},
                        {"shell_depth_m", k.shell_depth_m},
                        {"midi_note", k.midi_note},
                        {"stick_tip", "felt"}, // the beater's
                        {"played_by", "right foot"},
                        {"shell_passes", 0}};
    if (pedal)
        j["pedal"] = {{"beater_length_m", pedal->params().beater_length_m},
                      {"effective_mass_kg", pedal->effective_mass_kg()},
                      {"min_speed_mps", pedal->min_speed_mps()},
                      {"max_speed_mps", pedal->max_speed_mps()}};
    return j;
}

// notes.csv's columns of a note's strike: time, error, speed, contact (empty: none).
void write_match(std::ostream &out, const NoteMatch &k)
{
    char buf[128];
    if (k.strike_seq >= 0)
        std::snprintf(buf, sizeof buf, "%.6f,%.3f,%.4f,%.3f,", k.strike_time_s, k.error_ms,
                      k.normal_velocity_mps, k.duration_ms);
    else
        std::snprintf(buf, sizeof buf, ",,,,");
    out << buf;
}

} // namespace

// notes.csv: the planned notes and the strike each one got; with a kit, each
// note's drum last (the strike matched is on it).
void write_notes_csv(std::ostream &out, const GesturePlan &plan, const MatchSummary &m,
                     double origin_s, const Kit &kit)
{
    out << "index,time_s,hand,nuance,grip,dynamics,beats,tempo_bpm,line,strike_seq,strike_time_s,"
           "error_ms,normal_velocity_mps,duration_ms,grace"
        << (kit.empty() ? "\n" : ",drum\n");
    char buf[256];
    for (size_t i = 0; i < plan.notes.size(); ++i) {
        const PlannedNote &n = plan.notes[i];
        const NoteMatch &k = m.notes[i];
        std::snprintf(buf, sizeof buf, "%zu,%.6f,%s,%s,%s,%.3f,%.4f,%.3f,%d,%ld,", i,
                      origin_s + n.written_time_s(), to_string(n.hand), to_string(n.nuance),
                      to_string(n.grip), n.dynamics, n.beats, n.tempo_bpm, n.line, k.strike_seq);
        out << buf;
        write_match(out, k);
        out << (n.grace == Grace::none ? 0 : 1);
        if (!kit.empty() && n.drum >= 0 && n.drum < static_cast<int>(kit.drums.size()))
            out << ',' << kit.drums[static_cast<size_t>(n.drum)].name;
        out << '\n';
    }
    // The feet's notes after the hands': hand "right-foot" (a kit's kick) or
    // "left-foot" (its hi-hat's chick), no nuance or grip.
    for (size_t i = 0; i < plan.foot_notes.size(); ++i) {
        const PlannedFootNote &n = plan.foot_notes[i];
        const NoteMatch &k = m.foot_notes[i];
        std::snprintf(buf, sizeof buf, "%zu,%.6f,%s,,,%.3f,,,%d,%ld,", plan.notes.size() + i,
                      origin_s + n.time_s, n.side == Side::right ? "right-foot" : "left-foot",
                      n.dynamics, n.line, k.strike_seq);
        out << buf;
        write_match(out, k);
        out << 0;
        if (n.drum >= 0 && n.drum < static_cast<int>(kit.drums.size()))
            out << ',' << kit.drums[static_cast<size_t>(n.drum)].name;
        out << '\n';
    }
}

ListedNotes notes_text(const GesturePlan &plan, const MatchSummary &m, const Kit &kit,
                       NoteList which, double end_s, const char *unit)
{
    const bool off_time = which == NoteList::off_time;
    ListedNotes listed_notes;
    // A note within kOffTime_ms of the end is at it: its strike may fall after it.
    auto listed = [&](const NoteMatch &n, double time_s) {
        const bool after = time_s > end_s - 1e-3 * kOffTime_ms;
        const bool is = off_time ? n.strike_seq >= 0 && std::abs(n.error_ms) > kOffTime_ms
                                 : n.strike_seq < 0 && after == (which == NoteList::after_end);
        listed_notes.count += is;
        return is;
    };
    auto error = [&](const NoteMatch &n) {
        std::ostringstream e;
        if (off_time)
            e << std::fixed << std::setprecision(2) << ", " << std::showpos << n.error_ms << " ms";
        return e.str();
    };
    constexpr int kShown = 5;
    std::ostringstream out;
    out << std::fixed << std::setprecision(2);
    int shown = 0;
    auto name = [&](int drum) {
        return drum >= 0 && drum < static_cast<int>(kit.drums.size())
                   ? kit.drums[static_cast<size_t>(drum)].name
                   : std::string();
    };
    auto one = [&](int line, const std::string &who, int drum, double t, const std::string &move) {
        if (shown++ >= kShown)
            return;
        out << (shown > 1 ? ", " : "") << unit << " " << line << " (" << who;
        if (!name(drum).empty())
            out << " on " << name(drum);
        out << " at " << t << " s" << move << ")";
    };
    for (size_t i = 0; i < plan.notes.size(); ++i) {
        if (!listed(m.notes[i], plan.notes[i].written_time_s()))
            continue;
        const PlannedNote &n = plan.notes[i];
        const PlannedNote *prev = nullptr;
        for (size_t k = 0; shown < kShown && k < plan.notes.size(); ++k) { // shown ones only
            const PlannedNote &q = plan.notes[k];
            if (q.hand == n.hand && q.time_s < n.time_s && (!prev || q.time_s > prev->time_s))
                prev = &q;
        }
        std::ostringstream move;
        if (prev && prev->drum != n.drum && !name(prev->drum).empty())
            move << std::fixed << std::setprecision(2) << ", from " << name(prev->drum) << " "
                 << (n.strike_point_m - prev->strike_point_m).norm() << " m away "
                 << n.written_time_s() - prev->written_time_s() << " s before";
        // A flam's or drag's grace stroke is said as one: its line is its note's.
        std::string who = n.hand == Side::right ? "the right hand" : "the left hand";
        if (n.grace != Grace::none)
            who += std::string("'s ") + to_string(n.grace) + " grace stroke";
        one(n.line, who, n.drum, n.written_time_s(), error(m.notes[i]) + move.str());
    }
    for (size_t i = 0; i < plan.foot_notes.size(); ++i)
        if (listed(m.foot_notes[i], plan.foot_notes[i].time_s))
            one(plan.foot_notes[i].line,
                plan.foot_notes[i].side == Side::right ? "the right foot" : "the left foot",
                plan.foot_notes[i].drum, plan.foot_notes[i].time_s, error(m.foot_notes[i]));
    if (shown > kShown)
        out << " and " << shown - kShown << " more";
    listed_notes.text = out.str();
    return listed_notes;
}

// The strikes of no note (a stick that met a piece on its way, a second
// strike of a note): "seq 37 (the right hand on hihat at 4.89 s)" for the
// first few, in onset order, on the simulation clock as in strikes.csv.
std::string extra_strikes_text(const MatchSummary &m, const std::vector<StrikeEvent> &strikes,
                               const Kit &kit)
{
    constexpr size_t kShown = 5;
    static const char *const kLimbs[] = {"the left hand", "the right hand", "the right foot",
                                         "the left foot"};
    std::ostringstream out;
    out << std::fixed << std::setprecision(2);
    for (size_t k = 0; k < m.extra.size() && k < kShown; ++k) {
        const StrikeEvent &e = strikes[m.extra[k]];
        out << (k > 0 ? ", " : "") << "seq " << e.seq << " ("
            << (e.hand >= 0 && e.hand < 4 ? kLimbs[e.hand] : "a limb");
        if (e.drum >= 0 && e.drum < static_cast<int>(kit.drums.size()))
            out << " on " << kit.drums[static_cast<size_t>(e.drum)].name;
        out << " at " << e.time_s << " s)";
    }
    if (m.extra.size() > kShown)
        out << " and " << m.extra.size() - kShown << " more";
    return out.str();
}

nlohmann::json drum_json(const Performance &p)
{
    const DrumParams &d = p.scene().options().drum;
    nlohmann::json j;
    j["center_m"] = {d.center_m.x(), d.center_m.y(), d.center_m.z()};
    j["radius_m"] = d.radius_m;
    j["tension_n_per_m"] = d.tension_n_per_m;
    j["density_kg_per_m2"] = p.options().drum_density_kg_per_m2;
    j["preset"] = p.options().drum_preset.empty() ? nlohmann::json(nullptr)
                                                  : nlohmann::json(p.options().drum_preset);
    j["contact_stiffness_n_per_m"] = p.detector().membrane().stiffness_n_per_m;
    j["contact_damping_n_s_per_m"] = d.contact_damping_n_s_per_m;
    j["contact_stretch_n_per_m3"] = d.stretch_n_per_m3(); // the head's k3 (docs/sound.md)
    j["stick_tip"] = d.stick_tip;                         // "": none
    j["stick_tip_code"] = stick_tip_code(d.stick_tip);    // strikes.csv's stick_tip
    return j;
}

// A kit's drums as placed, and the stick parts that met a shell from the
// side (Scene::shell_passes: none when every stroke reached its head from above).
nlohmann::json kit_json(const Performance &p)
{
    const Scene &scene = p.scene();
    const Kit &kit = p.options().kit;
    nlohmann::json drums = nlohmann::json::array();
    for (int i = 0; i < static_cast<int>(kit.drums.size()); ++i) {
        const KitDrum &k = kit.drums[static_cast<size_t>(i)];
        if (i >= scene.drum_count()) {
            if (k.foot) // the kick: its pedal's, not in the sticks' scene
                drums.push_back(foot_piece_json(p, k));
            continue;
        }
        const DrumParams &d = scene.drum(i);
        drums.push_back({{"name", k.name},
                         {"preset", k.preset},
                         {"center_m", {d.center_m.x(), d.center_m.y(), d.center_m.z()}},
                         {"radius_m", d.radius_m},
                         {"tension_n_per_m", d.tension_n_per_m},
                         {"bending_n_m", k.bending_n_m}, // a cymbal's; 0: a drum
                         {"shell_depth_m", d.shell_depth_m},
                         {"midi_note", k.midi_note},
                         {"stick_tip", scene.options().drum.stick_tip}, // the sticks' ("": none)
                         {"shell_passes", scene.shell_passes(i)}});
    }
    return {{"name", kit.name}, {"drums", drums}, {"shell_passes", scene.shell_passes()}};
}

// render.json's "performance": how the strikes met the notes (docs/perform.md).
nlohmann::json performance_json(const PerformanceOptions &o, const Performance &perf,
                                const MatchSummary &m)
{
    const GesturePlan &plan = *perf.plan();
    nlohmann::json j;
    j["mode"] = to_string(perf.mode());
    const long all_notes = static_cast<long>(plan.notes.size() + plan.foot_notes.size());
    j["notes"] = all_notes;                   // the hands' and the feet's
    j["foot_notes"] = plan.foot_notes.size(); // both feet's
    j["left_foot_notes"] =
        std::count_if(plan.foot_notes.begin(), plan.foot_notes.end(),
                      [](const PlannedFootNote &n) { return n.side == Side::left; });
    j["primary_strikes"] = m.primary_strikes;
    j["bounces"] = m.bounces;
    j["matched_notes"] = m.matched_notes;
    j["missed_notes"] = all_notes - m.matched_notes;
    j["extra_strikes"] = m.extra_strikes;
    j["timing_error_ms"] = {{"mean_abs", m.mean_abs_error_ms}, {"max_abs", m.max_abs_error_ms}};
    double v_lo = 0.0, v_hi = 0.0, d_lo = 0.0, d_hi = 0.0, v_sum = 0.0, d_sum = 0.0;
    long n = 0;
    for (const NoteMatch &k : m.notes) {
        if (k.strike_seq < 0)
            continue;
        if (n == 0) {
            v_lo = v_hi = k.normal_velocity_mps;
            d_lo = d_hi = k.duration_ms;
        }
        v_lo = std::min(v_lo, k.normal_velocity_mps);
        v_hi = std::max(v_hi, k.normal_velocity_mps);
        d_lo = std::min(d_lo, k.duration_ms);
        d_hi = std::max(d_hi, k.duration_ms);
        v_sum += k.normal_velocity_mps;
        d_sum += k.duration_ms;
        ++n;
    }
    j["impact_speed_mps"] = {{"min", v_lo}, {"mean", n ? v_sum / n : 0.0}, {"max", v_hi}};
    j["contact_ms"] = {{"min", d_lo}, {"mean", n ? d_sum / n : 0.0}, {"max", d_hi}};
    j["plan"] = {{"duration_s", plan.duration_s},
                 {"origin_s", perf.plan_origin_s()},
                 {"strike_depth_m", o.score.plan.strike_depth_m},
                 {"strike_aim_s", o.score.plan.strike_aim_s},
                 {"strike_aim_from_mps", o.score.plan.strike_aim_from_mps},
                 {"strike_aim_max_m", o.score.plan.strike_aim_max_m},
                 {"time_advance_s", o.score.time_advance_s},
                 {"lead_in_s", o.score.plan.lead_in_s}};
    const Performance::BodyStats &b = perf.body_stats();
    j["joint_limits"] = {{"kind", "range_of_motion"},
                         {"max_excursion_deg", b.max_limit_excursion_deg},
                         {"joint", b.max_limit_joint}};
    j["trunk"] = {{"max_deg", b.trunk_max_deg}, {"rms_deg", b.trunk_rms_deg()}};
    // The runaway guard (docs/perform.md): times it fired, strikes it held back.
    j["runaways"] = perf.runaways();
    j["whips"] = perf.whips();
    j["withheld_strikes"] = perf.withheld_strikes();
    j["sticks"] = {{"mount", o.scene.sticks == StickMount::fulcrum ? "fulcrum" : "rigid"},
                   {"grip_firmness", o.grip_firmness},
                   {"grip_damping_ratio", o.scene.grip_damping_ratio},
                   {"rebound_s", o.score.rebound_s}};
    const PerformerFrame &f = perf.performer_frame();
    j["performer"] = {{"right", {f.right.x(), f.right.y(), f.right.z()}},
                      {"forward", {f.forward.x(), f.forward.y(), f.forward.z()}}};
    nlohmann::json per_note = nlohmann::json::array();
    for (size_t i = 0; i < plan.notes.size(); ++i) {
        const PlannedNote &p = plan.notes[i];
        const NoteMatch &k = m.notes[i];
        nlohmann::json e = {{"time_s", perf.plan_origin_s() + p.written_time_s()},
                            {"lead_ms", 1e3 * p.lead_s},
                            {"hand", to_string(p.hand)},
                            {"nuance", to_string(p.nuance)},
                            {"dynamics", p.dynamics},
                            {"line", p.line},
                            {"grace", to_string(p.grace)},
                            {"planned_impact_speed_mps", perf.planned_impact_speed_mps(i)}};
        if (k.strike_seq >= 0) {
            e["strike_seq"] = k.strike_seq;
            e["error_ms"] = k.error_ms;
            e["impact_speed_mps"] = k.normal_velocity_mps;
            e["contact_ms"] = k.duration_ms;
        } else {
            e["strike_seq"] = nullptr;
        }
        per_note.push_back(e);
    }
    j["per_note"] = per_note;
    return j;
}

} // namespace cli
} // namespace ictus
