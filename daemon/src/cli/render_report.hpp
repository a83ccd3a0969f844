// render_report.hpp -- what `ictusd render` reports of a performance
// (private to src/cli): notes.csv, and render.json's drum, kit and
// performance parts (docs/osc.md, docs/perform.md, docs/kit.md).
#pragma once

#include "ictus/perform/kit.hpp"
#include "ictus/perform/performance.hpp"
#include "ictus/perform/strike_match.hpp"

#include <nlohmann/json.hpp>

#include <ostream>
#include <string>
#include <vector>

namespace ictus
{
namespace cli
{

// notes.csv: the planned notes and the strike each one got (the foot's after the hands').
void write_notes_csv(std::ostream &out, const GesturePlan &plan, const MatchSummary &m,
                     double origin_s, const Kit &kit);
// render.json's "drum": the one drum (or a kit's first) and its contact law.
nlohmann::json drum_json(const Performance &p);
// render.json's "kit": its drums as placed (a foot piece with its pedal).
nlohmann::json kit_json(const Performance &p);
// render.json's "performance": how the strikes met the notes.
nlohmann::json performance_json(const PerformanceOptions &o, const Performance &perf,
                                const MatchSummary &m);

constexpr double kOffTime_ms = 5.0; // docs/perform.md: a note is right within +-5 ms

// Which notes notes_text lists: those not struck before the render's end, those
// struck more than kOffTime_ms from their time, those at or after the end (a
// --duration shorter than the score: never played, so not missed).
enum class NoteList { missed, off_time, after_end };

// The notes of `which` kind, hands' and feet's (end_s: the plan time at which the
// render stopped): how many, and "line L (the right hand on crash at 7.43 s, from
// floor 1.2 m away 0.27 s before)" ("note N" for a MIDI part's: unit) for the
// first few in plan order (off time with the error: "..., +12.40 ms"); a hand's
// move into the note is given when it came from another piece (most notes lost
// on a kit asked the arm for a move it cannot make in the time).
struct ListedNotes {
    long count = 0;
    std::string text;
};
ListedNotes notes_text(const GesturePlan &plan, const MatchSummary &m, const Kit &kit,
                       NoteList which, double end_s, const char *unit);

// The strikes of no note (a stick that met a piece on its way, a second
// strike of a note): "seq 37 (the right hand on hihat at 4.89 s)" for the
// first few, in onset order, on the simulation clock as in strikes.csv.
std::string extra_strikes_text(const MatchSummary &m, const std::vector<StrikeEvent> &strikes,
                               const Kit &kit);

} // namespace cli
} // namespace ictus
