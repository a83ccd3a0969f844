// A note's piece of a kit as the planner finds it (kit_notes.hpp).
#include "kit_notes.hpp"

#include "ictus/base/motor_noise.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace ictus
{
namespace score_detail
{

namespace
{

int find_drum(const PerformerFrame &frame, const std::string &name)
{
    for (size_t i = 0; i < frame.drums.size(); ++i)
        if (frame.drums[i].name == name)
            return static_cast<int>(i);
    return -1;
}

// The kit's name for a common spelling of a standard piece, or "".
std::string standard_spelling(const std::string &name)
{
    static const char *const spellings[][2] = {
        {"floor-tom", "floor"}, {"floor_tom", "floor"}, {"floortom", "floor"}, {"hi-hat", "hihat"},
        {"hi_hat", "hihat"},    {"bass-drum", "kick"},  {"bass_drum", "kick"}, {"bassdrum", "kick"},
    };
    for (const auto &s : spellings)
        if (name == s[0])
            return s[1];
    return "";
}

// The name without `-SUFFIX` or `_SUFFIX` at its end, or "" when it has neither.
std::string without_suffix(const std::string &name, const std::string &suffix)
{
    for (const char sep : {'-', '_'}) {
        const std::string tail = sep + suffix;
        if (name.size() > tail.size() &&
            name.compare(name.size() - tail.size(), tail.size(), tail) == 0)
            return name.substr(0, name.size() - tail.size());
    }
    return "";
}

} // namespace

NoteDrum note_drum(const Score &score, const ScoreNote &n, const PerformerFrame &frame)
{
    if (n.drum.empty())
        return {};
    if (const int i = find_drum(frame, n.drum); i >= 0)
        return {i, false};
    if (const int i = find_drum(frame, standard_spelling(n.drum)); i >= 0)
        return {i, false};
    std::string names, cymbals;
    for (const PerformerFrame::Drum &d : frame.drums) {
        names += (names.empty() ? "" : ", ") + d.name;
        if (d.cymbal)
            cymbals += (cymbals.empty() ? "" : ", ") + d.name;
    }
    // A bell's or a rim's piece is found as a note's is: by its name, else by its
    // common spelling (`hi-hat-bell`, `floor-tom-rim`).
    auto piece = [&](const std::string &base) {
        if (base.empty())
            return -1;
        const int i = find_drum(frame, base);
        return i >= 0 ? i : find_drum(frame, standard_spelling(base));
    };
    if (const int i = piece(without_suffix(n.drum, "bell")); i >= 0) {
        if (frame.drums[static_cast<size_t>(i)].cymbal)
            return {i, true};
        throw ScoreError(
            score.source, n.drum_line, n.drum_column,
            "drum '" + n.drum + "': a bell is a cymbal's, and '" +
                frame.drums[static_cast<size_t>(i)].name + "' is not a cymbal (" +
                (cymbals.empty() ? "the kit has none" : "the kit's cymbals: " + cymbals) + ")");
    }
    if (const int rim_i = piece(without_suffix(n.drum, "rim")); rim_i >= 0) {
        const PerformerFrame::Drum &d = frame.drums[static_cast<size_t>(rim_i)];
        if (!d.cymbal && !d.foot)
            return {rim_i, false, true};
        throw ScoreError(
            score.source, n.drum_line, n.drum_column,
            "drum '" + n.drum + "': '" + d.name + "' has no rim to strike (" +
                (d.foot ? "its pedal's beater plays it" : "a cymbal's edge is its own") + ")");
    }
    if (frame.drums.empty())
        throw ScoreError(score.source, n.drum_line, n.drum_column,
                         "drum '" + n.drum +
                             "': there is one drum and no kit (give the performance a kit, "
                             "e.g. --kit standard: docs/perform.md)");
    throw ScoreError(score.source, n.drum_line, n.drum_column,
                     "unknown drum '" + n.drum + "' (the kit: " + names +
                         (cymbals.empty() ? "" : "; a cymbal's bell: NAME-bell") +
                         "; a drum's rim: NAME-rim)");
}

int drum_index(const Score &score, const ScoreNote &n, const PerformerFrame &frame)
{
    return note_drum(score, n, frame).index;
}

int note_drum_spot(const Score &score, const ScoreNote &n, const PerformerFrame &frame,
                   double &r_over_a, double &theta_deg, const Eigen::Vector3d *arriving_from)
{
    const NoteDrum drum = note_drum(score, n, frame);
    const bool cymbal = drum.index < static_cast<int>(frame.drums.size()) &&
                        frame.drums[static_cast<size_t>(drum.index)].cymbal;
    if (!n.spot_given && (drum.bell || cymbal)) {
        r_over_a = drum.bell ? kBellRadiusFraction : kCymbalRadiusFraction;
        theta_deg = kCymbalThetaDeg[static_cast<int>(n.hand)];
        if (arriving_from && !drum.bell) {
            const Eigen::Vector3d to =
                *arriving_from - frame.drums[static_cast<size_t>(drum.index)].membrane_center_m;
            const double face = std::atan2(-to.z(), to.x()) * 180.0 / M_PI; // docs/osc.md
            theta_deg += std::clamp(std::remainder(face - theta_deg, 360.0), -kCymbalFaceMostDeg,
                                    kCymbalFaceMostDeg);
        }
    }
    if (drum.rim && (!n.spot_given || n.spot_column > 0)) {
        const PerformerFrame::Drum &d = frame.drums[static_cast<size_t>(drum.index)];
        if (n.spot_given && n.r_over_a < kRimAtLeastRadiusFraction) {
            char r[32];
            std::snprintf(r, sizeof r, "%g", n.r_over_a);
            throw ScoreError(score.source, n.line, n.spot_column,
                             "'at " + std::string(r) + "' on drum '" + n.drum +
                                 "': a rim is struck at its edge, and r/a " + r +
                                 " is on the head (a rim note's 'at' gives the angle, with r/a "
                                 "0.9 to 0.95; the head there: 'on " +
                                 d.name + " at ...')");
        }
        r_over_a = 1.0 - kRimInset_m / d.membrane_radius_m;
        if (!n.spot_given) {
            const Eigen::Vector3d to =
                frame.shoulder_m[static_cast<size_t>(n.hand)] - d.membrane_center_m;
            theta_deg = std::atan2(-to.z(), to.x()) * 180.0 / M_PI; // docs/osc.md: y_m is -z
        }
    }
    return drum.index;
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

void check_one_pedal(const Score &score, const ScoreNote &n, const PlannedNote &p,
                     const PlannedNote &other, const PerformerFrame &frame)
{
    if (other.drum != p.drum || other.openness == p.openness || other.score_note < 0)
        return;
    const ScoreNote &o = score.notes[static_cast<size_t>(other.score_note)];
    if (score.note_time_s(o) != score.note_time_s(n))
        return;
    const std::string word = hihat_openness_word(p.openness);
    const std::string was = hihat_openness_word(other.openness);
    auto none = [](double written) { return written < 0.0 ? " (no pedal word)" : ""; };
    throw ScoreError(score.source, n.line, n.openness_column > 0 ? n.openness_column : n.column,
                     "hi-hat '" + frame.drums[static_cast<size_t>(p.drum)].name + "' " + word +
                         none(n.openness) + " and " + was + " at once: the " +
                         (o.hand == Side::right ? "right" : "left") +
                         " hand's note on it at this instant (line " + std::to_string(o.line) +
                         ") is " + was + none(o.openness) +
                         ", and its pedal sets one openness (give both notes the same word)");
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
