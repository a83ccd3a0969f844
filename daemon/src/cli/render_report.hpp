// render_report.hpp -- what `ictusd render` reports of a performance
// (private to src/cli): notes.csv, and render.json's drum, kit and
// performance parts (docs/osc.md, docs/perform.md, docs/kit.md).
#pragma once

#include "ictus/perform/kit.hpp"
#include "ictus/perform/performance.hpp"
#include "ictus/perform/strike_match.hpp"

#include <nlohmann/json.hpp>

#include <ostream>

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

} // namespace cli
} // namespace ictus
