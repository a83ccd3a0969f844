// A note's piece of a kit as the planner finds it (kit_notes.hpp).
#include "kit_notes.hpp"

#include "ictus/base/motor_noise.hpp"

#include <algorithm>
#include <string>

namespace ictus
{
namespace score_detail
{

// The index of the note's drum in the frame's kit; a ScoreError where the
// drum was named when the kit has none of that name.
int drum_index(const Score &score, const ScoreNote &n, const PerformerFrame &frame)
{
    if (n.drum.empty())
        return 0;
    std::string names;
    for (size_t i = 0; i < frame.drums.size(); ++i) {
        if (frame.drums[i].name == n.drum)
            return static_cast<int>(i);
        names += (i ? ", " : "") + frame.drums[i].name;
    }
    if (frame.drums.empty())
        throw ScoreError(score.source, n.drum_line, n.drum_column,
                         "drum '" + n.drum +
                             "': there is one drum and no kit (give the performance a kit, "
                             "e.g. --kit standard: docs/perform.md)");
    throw ScoreError(score.source, n.drum_line, n.drum_column,
                     "unknown drum '" + n.drum + "' (the kit: " + names + ")");
}

// The note's pedal on a hi-hat (closed when it names none), -1 on another
// drum; a ScoreError at the word when it names one on a drum without a pedal.
double note_openness(const Score &score, const ScoreNote &n, const PerformerFrame &frame, int drum)
{
    const bool kit = drum >= 0 && drum < static_cast<int>(frame.drums.size());
    if (kit && frame.drums[static_cast<size_t>(drum)].pedal)
        return n.openness >= 0.0 ? n.openness : kHihatClosed;
    if (n.openness < 0.0)
        return -1.0;
    std::string hihats;
    for (const PerformerFrame::Drum &d : frame.drums)
        if (d.pedal)
            hihats += (hihats.empty() ? "" : ", ") + d.name;
    throw ScoreError(
        score.source, n.line, n.openness_column,
        std::string("'") + hihat_openness_word(n.openness) + "' is a hi-hat's pedal, and drum '" +
            (kit ? frame.drums[static_cast<size_t>(drum)].name : n.drum) + "' is not a hi-hat (" +
            (hihats.empty() ? "the kit has none" : "the kit's hi-hat: " + hihats) + ")");
}

// A foot's note: its time (with the motor noise of `humanize`, as a hand's)
// and its drum: the right foot's the kit's foot piece, the left foot's its
// hi-hat (the first, or the one it names); a ScoreError where the kit has none
// or it names another piece.
PlannedFootNote foot_note(const Score &score, const ScoreNote &n, size_t k,
                          const PerformerFrame &frame, const PlanOptions &opt)
{
    PlannedFootNote f;
    f.time_s = opt.lead_in_s + score.note_time_s(n);
    f.dynamics = n.dynamics;
    f.side = n.hand;
    f.line = n.line;
    f.column = n.column;
    const double amount = humanize_amount(score, opt);
    if (amount > 0.0) {
        MotorNoise noise(opt.seed, k + 1);
        f.time_s += amount * kHumanizeTimingSd_s * noise.normal();
        f.dynamics =
            std::clamp(n.dynamics * (1.0 + amount * kHumanizeForceCv * noise.normal()), 0.0, 1.0);
    }
    // The right foot's piece is the kick (Drum::foot), the left foot's the
    // hi-hat (Drum::pedal).
    const bool right = n.hand == Side::right;
    auto plays = [&](const PerformerFrame::Drum &d) { return right ? d.foot : d.pedal; };
    const std::string foot = right ? "the right foot" : "the left foot";
    const std::string pedal = right ? "a kick's pedal" : "a hi-hat's pedal";
    std::string feet;
    for (size_t i = 0; i < frame.drums.size(); ++i)
        if (plays(frame.drums[i]))
            feet += (feet.empty() ? "" : ", ") + frame.drums[i].name;
    if (n.drum.empty()) {
        for (size_t i = 0; i < frame.drums.size(); ++i)
            if (plays(frame.drums[i])) {
                f.drum = static_cast<int>(i);
                return f;
            }
        throw ScoreError(score.source, n.line, n.column,
                         foot + " plays " + pedal + ", and " +
                             std::string(frame.drums.empty() ? "there is no kit"
                                                             : (right ? "this kit has no kick"
                                                                      : "this kit has no hi-hat")) +
                             (right ? " (--kit full has one: docs/kit.md)"
                                    : " (--kit standard-cymbals and full have one: docs/kit.md)"));
    }
    f.drum = drum_index(score, n, frame);
    if (!plays(frame.drums[static_cast<size_t>(f.drum)]))
        throw ScoreError(score.source, n.drum_line, n.drum_column,
                         "drum '" + n.drum + "' is not " + foot + "'s; " + foot + " plays " +
                             (feet.empty() ? pedal + ", and this kit has none" : feet));
    return f;
}

} // namespace score_detail
} // namespace ictus
