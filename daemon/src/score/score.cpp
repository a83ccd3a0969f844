// score.cpp -- the score language (docs/score.md): tokenizer, statement
// parser and the executor that expands repeats into notes (the tempo map:
// tempo_map.cpp).
// Parsing is in two passes so that nothing is produced from a faulty score:
// every statement is parsed and range-checked first (add_line), and only a
// complete, balanced statement list is executed into a Score (finish).
#include "ictus/score/score.hpp"
#include "statement.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>
#include <stdexcept>

namespace ictus
{

const char *to_string(Grace grace)
{
    switch (grace) {
    case Grace::flam:
        return "flam";
    case Grace::drag:
        return "drag";
    case Grace::none:
        break;
    }
    return "none";
}

const char *hihat_openness_word(double openness)
{
    if (openness == kHihatOpen)
        return "open";
    if (openness == kHihatHalf)
        return "half";
    if (openness == kHihatClosed)
        return "closed";
    return "";
}

const std::vector<DynamicsWord> &dynamics_words()
{
    // Evenly spread over the range, mf = the default 0.6 and ff = the loudest.
    static const std::vector<DynamicsWord> words = {{"pp", 0.2}, {"p", 0.3}, {"mp", 0.45},
                                                    {"mf", 0.6}, {"f", 0.8}, {"ff", 1.0}};
    return words;
}

// ---------------------------------------------------------------- statements

using score_detail::Kind;
using score_detail::Roll;
using score_detail::Statement;

namespace
{

struct Token {
    std::string text;
    std::string lower;
    int column = 0;
};

const Nuance kNuances[] = {Nuance::legato,          Nuance::tenuto,   Nuance::accent,
                           Nuance::vertical_accent, Nuance::staccato, Nuance::buzz};

std::string nuance_list()
{
    std::string s;
    for (Nuance n : kNuances)
        s += std::string(s.empty() ? "" : ", ") + to_string(n);
    return s;
}

std::string dynamics_list()
{
    std::string s;
    for (const auto &w : dynamics_words())
        s += std::string(s.empty() ? "" : " ") + w.word;
    return s;
}

std::optional<Nuance> nuance_word(const std::string &lower)
{
    std::string name = lower;
    std::replace(name.begin(), name.end(), '-', '_'); // vertical-accent
    for (Nuance n : kNuances)
        if (name == to_string(n))
            return n;
    return std::nullopt;
}

std::optional<double> dynamics_word(const std::string &lower)
{
    for (const auto &w : dynamics_words())
        if (lower == w.word)
            return w.value;
    return std::nullopt;
}

// A hi-hat note's pedal word (`open`, `half`, `closed`) as membrane~'s openness.
std::optional<double> openness_word(const std::string &lower)
{
    for (double o : {kHihatOpen, kHihatHalf, kHihatClosed})
        if (lower == hihat_openness_word(o))
            return o;
    return std::nullopt;
}

// A foot's note: `RF` (the right foot, on the kick's pedal; docs/pedal.md).
bool foot_word(const std::string &lower)
{
    return lower == "rf" || lower == "right-foot";
}

// The left foot's: `LF`, on the hi-hat's pedal (the chick; docs/pedal.md).
bool left_foot_word(const std::string &lower)
{
    return lower == "lf" || lower == "left-foot";
}

std::optional<Side> hand_word(const std::string &lower)
{
    if (lower == "r" || lower == "right")
        return Side::right;
    if (lower == "l" || lower == "left")
        return Side::left;
    return std::nullopt;
}

// A decimal number as Pd or a person writes it: [+-]digits[.digits][e[+-]digits]
// (also ".5"). No nan, inf or hex: those are malformed here.
bool looks_numeric(const std::string &s)
{
    size_t i = 0;
    if (i < s.size() && (s[i] == '+' || s[i] == '-'))
        ++i;
    size_t digits = 0;
    while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])))
        ++i, ++digits;
    if (i < s.size() && s[i] == '.') {
        ++i;
        while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])))
            ++i, ++digits;
    }
    if (digits == 0)
        return false;
    if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
        ++i;
        if (i < s.size() && (s[i] == '+' || s[i] == '-'))
            ++i;
        size_t exp_digits = 0;
        while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])))
            ++i, ++exp_digits;
        if (exp_digits == 0)
            return false;
    }
    return i == s.size();
}

// Does the token start like a number (so a fault in it is a malformed number,
// not an unknown word)?
bool starts_numeric(const std::string &s)
{
    if (s.empty())
        return false;
    const unsigned char c = s[0];
    return std::isdigit(c) || c == '.' ||
           ((c == '+' || c == '-') && s.size() > 1 &&
            (std::isdigit(static_cast<unsigned char>(s[1])) || s[1] == '.'));
}

// The length of the space at text[i]: 1 for an ASCII one, 2 for a no-break space
// (U+00A0, UTF-8 C2 A0: Option-Space, a copy from a web page), else 0.
size_t space_at(const std::string &text, size_t i)
{
    if (std::isspace(static_cast<unsigned char>(text[i])))
        return 1;
    if (static_cast<unsigned char>(text[i]) == 0xC2 && i + 1 < text.size() &&
        static_cast<unsigned char>(text[i + 1]) == 0xA0)
        return 2;
    return 0;
}

class LineParser
{
  public:
    LineParser(const std::string &source, int line) : source_(source), line_(line) {}

    std::vector<Statement> parse(const std::string &text)
    {
        std::vector<Statement> out;
        std::vector<Token> tokens;
        auto flush = [&]() {
            if (!tokens.empty())
                chord(tokens, out);
            tokens.clear();
        };
        size_t i = 0, counted = 0, continuations = 0;
        while (i < text.size()) {
            const char c = text[i];
            if (c == '#') { // a comment, to the end of its line within the text
                while (i < text.size() && text[i] != '\n' && text[i] != '\r')
                    ++i;
                continue;
            }
            // a line break in a statement sent as one string (a CR, as Windows' or
            // an old Mac's, too) separates statements as a newline does in a file
            if (c == ',' || c == ';' || c == '\n' || c == '\r') {
                flush();
                ++i;
                continue;
            }
            if (const size_t n = space_at(text, i)) {
                i += n;
                continue;
            }
            Token t;
            // The column in characters, as an editor counts them: UTF-8's
            // continuation bytes (10xxxxxx) before the word are not characters.
            for (; counted < i; ++counted)
                if ((static_cast<unsigned char>(text[counted]) & 0xC0) == 0x80)
                    ++continuations;
            t.column = static_cast<int>(i - continuations) + 1;
            // '->' is a word of its own, with or without spaces around it ('96->140')
            if (text.compare(i, 2, "->") == 0) {
                t.text = "->";
                i += 2;
            } else {
                while (i < text.size() && !space_at(text, i) && text[i] != ',' && text[i] != ';' &&
                       text[i] != '#' && text.compare(i, 2, "->") != 0)
                    t.text += text[i++];
            }
            t.lower = t.text;
            for (char &ch : t.lower)
                ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
            tokens.push_back(t);
        }
        flush();
        return out;
    }

  private:
    const std::string &source_;
    int line_;

    // One statement, or a chord: `R on hihat + L on snare + RF`, notes of up to four
    // limbs (the two hands and the two feet) on one beat, each with its own options
    // (a '+' between spaces).
    void chord(const std::vector<Token> &tk, std::vector<Statement> &out) const
    {
        std::vector<std::vector<Token>> parts(1);
        std::vector<int> plus_columns;
        for (const Token &t : tk) {
            if (glued_plus(t))
                fail(t.column, "'" + t.text +
                                   "': '+' joins notes with a space on each side: 'R + L' "
                                   "('R+L' is one note of both hands)");
            if (t.text != "+") {
                parts.back().push_back(t);
                continue;
            }
            if (parts.back().empty())
                fail(t.column, "'+' joins notes played on one beat, one of each limb: "
                               "'R on hihat + L on snare + RF'");
            if (parts.size() == 4)
                fail(t.column, "a fourth '+': two hands and two feet play four notes on one "
                               "beat at most");
            plus_columns.push_back(t.column);
            parts.emplace_back();
        }
        if (parts.size() == 1) {
            out.push_back(statement(tk));
            return;
        }
        if (parts.back().empty())
            fail(plus_columns.back(), "'+' joins notes played on one beat, one of each limb: "
                                      "'R on hihat + L on snare + RF'");
        std::vector<Statement> notes;
        for (const std::vector<Token> &part : parts) {
            const std::string &w = part[0].lower;
            if (!hand_word(w) && !foot_word(w) && !left_foot_word(w))
                fail(part[0].column, "'+' joins notes of one limb each ('R ...', 'L ...', "
                                     "'RF ...' or 'LF ...'), got '" +
                                         part[0].text + "'");
            Statement st = statement(part);
            for (const Statement &other : notes)
                if (other.hand == st.hand && other.foot == st.foot)
                    fail(part[0].column, "two notes joined by '+' are the " + limb_name(st) +
                                             "'s: one limb plays one note at a time");
            notes.push_back(st);
        }
        for (size_t i = 0; i + 1 < notes.size(); ++i)
            notes[i].with_next = true;
        out.insert(out.end(), notes.begin(), notes.end());
    }

    // A word of limbs and '+' written without its spaces ('+L', 'R+', 'RF+LF'): each
    // piece between the '+' a limb's word or nothing; not the hands' 'R+L' or 'L+R'.
    static bool glued_plus(const Token &t)
    {
        if (t.text == "+" || t.text.find('+') == std::string::npos || t.lower == "r+l" ||
            t.lower == "l+r")
            return false;
        size_t from = 0;
        for (;;) {
            const size_t plus = t.lower.find('+', from);
            const std::string piece = t.lower.substr(from, plus - from);
            if (!piece.empty() && !hand_word(piece) && !foot_word(piece) && !left_foot_word(piece))
                return false;
            if (plus == std::string::npos)
                return true;
            from = plus + 1;
        }
    }

    static std::string limb_name(const Statement &st)
    {
        if (st.foot)
            return st.hand == Side::right ? "right foot" : "left foot";
        return st.hand == Side::right ? "right hand" : "left hand";
    }

    [[noreturn]] void fail(int column, const std::string &message) const
    {
        throw ScoreError(source_, line_, column, message);
    }

    double number(const Token &t, const char *what) const
    {
        if (!looks_numeric(t.text))
            fail(t.column, "malformed number '" + t.text + "' for " + what);
        return std::strtod(t.text.c_str(), nullptr);
    }

    // A duration: a number or a fraction N/D (whole numbers).
    double duration(const Token &t, const char *what) const
    {
        const size_t slash = t.text.find('/');
        double beats = 0.0;
        if (slash != std::string::npos) {
            const std::string num = t.text.substr(0, slash), den = t.text.substr(slash + 1);
            auto whole = [](const std::string &s) {
                return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
                    return std::isdigit(static_cast<unsigned char>(c));
                });
            };
            if (!whole(num) || !whole(den))
                fail(t.column, "malformed fraction '" + t.text + "' for " + what +
                                   " (write N/D with whole numbers, e.g. 1/2)");
            const double d = std::strtod(den.c_str(), nullptr);
            if (d == 0.0)
                fail(t.column, "fraction '" + t.text + "' divides by zero");
            beats = std::strtod(num.c_str(), nullptr) / d;
        } else {
            beats = number(t, what);
        }
        if (!(beats >= kMinNoteBeats && beats <= kMaxNoteBeats))
            fail(t.column, std::string(what) + " " + t.text + " is out of range (1/32..64 beats)");
        return beats;
    }

    double tempo(const Token &t) const
    {
        const double bpm = number(t, "tempo");
        if (!(bpm >= kMinTempoBpm && bpm <= kMaxTempoBpm))
            fail(t.column, "tempo " + t.text + " is out of range (20..400 bpm)");
        return bpm;
    }

    double dynamics_value(const Token &t) const
    {
        if (auto w = dynamics_word(t.lower))
            return *w;
        if (!starts_numeric(t.text))
            fail(t.column, "unknown dynamics '" + t.text + "' (a number 0..1 or one of " +
                               dynamics_list() + ")");
        const double d = number(t, "dynamics");
        if (!(d >= 0.0 && d <= 1.0))
            fail(t.column, "dynamics " + t.text +
                               " is out of range (0..1; for a duration write 'beats " + t.text +
                               "' or N/D)");
        return d;
    }

    void no_more(const std::vector<Token> &tk, size_t used, const char *what) const
    {
        if (tk.size() > used)
            fail(tk[used].column, "unexpected '" + tk[used].text + "' after " + what);
    }

    const Token &need(const std::vector<Token> &tk, size_t i, const char *message) const
    {
        if (i >= tk.size())
            fail(tk.back().column + static_cast<int>(tk.back().text.size()), message);
        return tk[i];
    }

    // A statement of one value, `KEY VALUE`, of kind `kind`: the value as
    // `parse` reads it (`needed` when it is missing), then nothing after it
    // (`what` names it).
    template <typename Parse>
    auto one_value(const std::vector<Token> &tk, Statement &st, Kind kind, const char *needed,
                   const char *what, const Parse &parse) const
    {
        st.kind = kind;
        const auto value = parse(need(tk, 1, needed));
        no_more(tk, 2, what);
        return value;
    }

    Statement statement(const std::vector<Token> &tk) const
    {
        Statement st;
        st.line = line_;
        st.column = tk[0].column;
        const std::string &key = tk[0].lower;
        if (auto hand = hand_word(key)) {
            st.kind = Kind::note;
            st.hand = *hand;
            note_options(tk, st);
        } else if (foot_word(key) || left_foot_word(key)) {
            st.kind = Kind::note;
            st.hand = foot_word(key) ? Side::right : Side::left;
            st.foot = true;
            note_options(tk, st);
            foot_options(tk, st);
        } else if (key == "r+l" || key == "l+r" || key == "both") {
            st.kind = Kind::note;
            st.both_hands = true;
            note_options(tk, st);
            if (st.ornament != Grace::none)
                fail(st.ornament_column, std::string("a ") + to_string(st.ornament) +
                                             "'s grace strokes are the other hand's; " +
                                             tk[0].text + " plays both: write R " +
                                             to_string(st.ornament) + " or L " +
                                             to_string(st.ornament));
            if (st.r_over_a)
                fail(st.spot_column, "'at' places one stick; " + tk[0].text +
                                         " plays each hand on its default spot");
        } else if (key == "tempo") {
            st.kind = Kind::tempo;
            size_t i = 1;
            const Token &first =
                need(tk, i, "tempo needs beats per minute: 'tempo 96' or 'tempo 96 -> 160 over 8'");
            if (first.lower != "->" && first.lower != "to") {
                st.start_bpm = tempo(first);
                ++i;
            }
            if (i < tk.size() && (tk[i].lower == "->" || tk[i].lower == "to")) {
                const Token &target =
                    need(tk, i + 1, "tempo change needs the target tempo after '->'");
                st.end_bpm = tempo(target);
                const Token &over = need(tk, i + 2, "tempo change needs 'over BEATS'");
                if (over.lower != "over")
                    fail(over.column,
                         "expected 'over BEATS' after the target tempo, got '" + over.text + "'");
                const Token &len =
                    need(tk, i + 3, "tempo change needs the number of beats after 'over'");
                // 1/32..kMaxNoteBeats, as every duration (a longer change: one ramp
                // after another, docs/score.md)
                st.ramp_beats = duration(len, "tempo change length");
                i += 4;
            } else {
                st.end_bpm = *st.start_bpm;
            }
            no_more(tk, i, "the tempo");
        } else if (key == "grip") {
            st.kind = Kind::grip;
            const Token &g = need(tk, 1, "grip needs a name: french or german");
            if (g.lower == "french")
                st.grip = Grip::french;
            else if (g.lower == "german")
                st.grip = Grip::german;
            else
                fail(g.column, "unknown grip '" + g.text + "' (valid: french, german)");
            no_more(tk, 2, "the grip");
        } else if (key == "rest") {
            st.kind = Kind::rest;
            size_t i = 1;
            if (i < tk.size() && tk[i].lower == "beats")
                ++i, need(tk, i, "'beats' needs a duration");
            if (i < tk.size())
                st.beats = duration(tk[i++], "rest");
            no_more(tk, i, "the rest");
        } else if (key == "beats") {
            st.beats =
                one_value(tk, st, Kind::default_beats, "'beats' needs a duration, e.g. 'beats 1/2'",
                          "the duration", [&](const Token &t) { return duration(t, "beats"); });
        } else if (key == "dynamics") {
            dynamics_statement(tk, st);
        } else if (key == "roll") {
            roll_statement(tk, st);
        } else if (key == "meter") {
            meter_statement(tk, st);
        } else if (key == "nuance") {
            st.nuance = one_value(tk, st, Kind::default_nuance,
                                  "'nuance' needs a nuance, e.g. 'nuance accent'", "the nuance",
                                  [&](const Token &t) { return nuance_value(t); });
        } else if (key == "firmness") {
            st.firmness =
                one_value(tk, st, Kind::default_firmness, "'firmness' needs a value 0..1",
                          "the firmness", [&](const Token &t) { return firmness_value(t); });
        } else if (key == "drum") {
            st.kind = Kind::drum;
            drum_name(need(tk, 1, "'drum' needs a drum's name, e.g. 'drum snare'"), st);
            no_more(tk, 2, "the drum's name");
        } else if (key == "humanize") {
            st.humanize =
                one_value(tk, st, Kind::humanize, "'humanize' needs an amount, e.g. 'humanize 1'",
                          "the amount", [&](const Token &t) {
                              const double a = number(t, "humanize");
                              if (!(a >= 0.0 && a <= kMaxHumanize))
                                  fail(t.column, "humanize " + t.text +
                                                     " is out of range (0..4; 1: a "
                                                     "drummer's hand, 0: no noise)");
                              return a;
                          });
        } else if (key == "repeat") {
            st.kind = Kind::repeat;
            const Token &n = need(tk, 1, "repeat needs a count, e.g. 'repeat 4'");
            const double count = number(n, "repeat");
            if (count != std::floor(count) || count < 1 || count > kMaxRepeat)
                fail(n.column, "repeat count " + n.text + " must be a whole number 1..1000");
            st.count = static_cast<int>(count);
            no_more(tk, 2, "the repeat count");
        } else if (key == "end") {
            st.kind = Kind::end;
            no_more(tk, 1, "'end'");
        } else {
            fail(
                tk[0].column,
                "unknown statement '" + tk[0].text +
                    "' (expected a hand R, L, right, left, R+L, a foot RF or LF, or tempo, grip, "
                    "rest, "
                    "beats, dynamics, firmness, nuance, roll, meter, drum, humanize, repeat, end)");
        }
        return st;
    }

    // `dynamics D`, or a hairpin `dynamics [D] -> D2 over BEATS`.
    void dynamics_statement(const std::vector<Token> &tk, Statement &st) const
    {
        st.kind = Kind::default_dynamics;
        size_t i = 1;
        const Token &first = need(tk, i,
                                  "'dynamics' needs a value 0..1 or pp..ff, or a hairpin: "
                                  "'dynamics p -> f over 4'");
        if (first.lower != "->" && first.lower != "to") {
            st.dynamics = dynamics_value(first);
            ++i;
        }
        if (i < tk.size() && (tk[i].lower == "->" || tk[i].lower == "to")) {
            st.dynamics_end =
                dynamics_value(need(tk, i + 1, "a hairpin needs the target dynamics after '->'"));
            const Token &over = need(tk, i + 2, "a hairpin needs 'over BEATS'");
            if (over.lower != "over")
                fail(over.column,
                     "expected 'over BEATS' after the target dynamics, got '" + over.text + "'");
            const Token &len = need(tk, i + 3, "a hairpin needs the number of beats after 'over'");
            st.ramp_beats = duration(len, "hairpin length");
            i += 4;
        }
        no_more(tk, i, "the dynamics");
    }

    // `roll single|double|buzz BEATS`.
    void roll_statement(const std::vector<Token> &tk, Statement &st) const
    {
        st.kind = Kind::roll;
        const Token &k = need(tk, 1,
                              "roll needs a kind and a length in beats: 'roll single 2' (single, "
                              "double or buzz)");
        if (k.lower == "single")
            st.roll = Roll::single;
        else if (k.lower == "double")
            st.roll = Roll::double_stroke;
        else if (k.lower == "buzz")
            st.roll = Roll::buzz;
        else
            fail(k.column, "unknown roll '" + k.text + "' (valid: single, double, buzz)");
        st.ramp_beats = duration(need(tk, 2,
                                      "roll needs its length in beats after the kind: "
                                      "'roll single 2'"),
                                 "roll length");
        no_more(tk, 3, "the roll length");
    }

    // `meter N/D`: N 1..64, D a power of two 1..64.
    void meter_statement(const std::vector<Token> &tk, Statement &st) const
    {
        st.kind = Kind::meter;
        const Token &m = need(tk, 1, "meter needs N/D, e.g. 'meter 3/4'");
        const size_t slash = m.text.find('/');
        auto whole = [](const std::string &s) {
            return !s.empty() && s.size() <= 4 && std::all_of(s.begin(), s.end(), [](char c) {
                return std::isdigit(static_cast<unsigned char>(c));
            });
        };
        if (slash == std::string::npos || !whole(m.text.substr(0, slash)) ||
            !whole(m.text.substr(slash + 1)))
            fail(m.column, "malformed meter '" + m.text +
                               "' (write N/D with whole numbers, e.g. 'meter 3/4')");
        st.numerator = std::atoi(m.text.substr(0, slash).c_str());
        st.denominator = std::atoi(m.text.substr(slash + 1).c_str());
        if (st.numerator < 1 || st.numerator > kMaxMeterNumerator)
            fail(m.column, "meter '" + m.text + "': " + std::to_string(st.numerator) +
                               " beats in a bar is out of range (1..64)");
        const int d = st.denominator;
        if (d < 1 || d > kMaxMeterDenominator || (d & (d - 1)) != 0)
            fail(m.column, "meter '" + m.text + "': the note value " + std::to_string(d) +
                               " must be a power of two (1, 2, 4, 8, 16, 32, 64)");
        no_more(tk, 2, "the meter");
    }

    Nuance nuance_value(const Token &t) const
    {
        const std::optional<Nuance> nuance = nuance_word(t.lower);
        if (!nuance)
            fail(t.column, "unknown nuance '" + t.text + "' (valid: " + nuance_list() + ")");
        return *nuance;
    }

    // A drum's name: letters, digits, '_' and '-' (the kit's names, docs/kit.md).
    void drum_name(const Token &t, Statement &st) const
    {
        const bool ok =
            !t.lower.empty() && t.lower.size() <= 32 &&
            std::all_of(t.lower.begin(), t.lower.end(), [](char c) {
                return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
            });
        if (!ok)
            fail(t.column,
                 "malformed drum name '" + t.text + "' (letters, digits, '_' and '-', at most 32)");
        st.drum = t.lower;
        st.drum_column = t.column;
    }

    double firmness_value(const Token &t) const
    {
        const double f = number(t, "firmness");
        if (!(f >= 0.0 && f <= 1.0))
            fail(t.column, "firmness " + t.text + " is out of range (0..1: 0 loose, 1 firm)");
        return f;
    }

    // What a foot's note cannot have: grace strokes, a spot (the beater meets
    // the head, the plates meet, where the pedal stands), a grip's firmness, a
    // hi-hat's openness (the left foot's chick closes it).
    void foot_options(const std::vector<Token> &tk, Statement &st) const
    {
        const bool right = st.hand == Side::right;
        const std::string what = "'" + tk[0].text +
                                 (right ? "' is the right foot's note on the kick's pedal"
                                        : "' is the left foot's chick on the hi-hat's pedal");
        if (st.ornament != Grace::none)
            fail(st.ornament_column, what + ": a " + std::string(to_string(st.ornament)) +
                                         "'s grace strokes are the hands'");
        if (st.openness)
            fail(st.openness_column,
                 what + ": '" + hihat_openness_word(*st.openness) +
                     (right ? "' is the hi-hat's" : "' is a hand's note's (the chick closes it)"));
        for (const Token &t : tk)
            if (t.lower == "at" || t.lower == "firmness")
                fail(t.column, what + ": '" + t.text + "' is a stick's (the " +
                                   (right ? "beater meets the head" : "plates meet") +
                                   " where the pedal stands)");
    }

    void note_options(const std::vector<Token> &tk, Statement &st) const
    {
        bool has_nuance = false;
        for (size_t i = 1; i < tk.size(); ++i) {
            const Token &t = tk[i];
            if (auto n = nuance_word(t.lower)) {
                if (has_nuance)
                    fail(t.column, "second nuance '" + t.text + "' in one note");
                st.nuance = *n;
                has_nuance = true;
            } else if (t.lower == "flam" || t.lower == "drag") {
                if (st.ornament != Grace::none)
                    fail(t.column, "second ornament '" + t.text +
                                       "' in one note (a note has one flam or one drag)");
                st.ornament = t.lower == "flam" ? Grace::flam : Grace::drag;
                st.ornament_column = t.column;
            } else if (auto d = dynamics_word(t.lower)) {
                if (st.dynamics)
                    fail(t.column, "second dynamics '" + t.text + "' in one note");
                st.dynamics = *d;
            } else if (t.lower == "beats") {
                if (st.beats)
                    fail(t.column, "second duration in one note");
                st.beats = duration(need(tk, i + 1, "'beats' needs a duration"), "note duration");
                ++i;
            } else if (t.lower == "firmness") {
                if (st.firmness)
                    fail(t.column, "second firmness in one note");
                st.firmness = firmness_value(
                    need(tk, i + 1, "'firmness' needs a value 0..1 (0 loose, 1 firm)"));
                ++i;
            } else if (t.lower == "on") {
                if (st.drum)
                    fail(t.column, "second drum in one note");
                drum_name(need(tk, i + 1, "'on' needs a drum's name, e.g. 'on tom1'"), st);
                ++i;
            } else if (auto o = openness_word(t.lower)) {
                if (st.openness)
                    fail(t.column, "second hi-hat openness '" + t.text +
                                       "' in one note (one of open, half, closed)");
                st.openness = *o;
                st.openness_column = t.column;
            } else if (t.lower == "at") {
                if (st.r_over_a)
                    fail(t.column, "second position in one note");
                const Token &r =
                    need(tk, i + 1, "'at' needs r/a and theta in degrees: 'at 0.3 180'");
                const Token &th = need(tk, i + 2, "'at' needs theta in degrees after r/a");
                const double ra = number(r, "r/a");
                if (!(ra >= 0.0 && ra <= kMaxRadiusFraction))
                    fail(r.column, "r/a " + r.text + " is out of range (0..0.95 of the radius)");
                double theta = number(th, "theta");
                if (!std::isfinite(theta) || std::abs(theta) > 1e6)
                    fail(th.column, "theta " + th.text +
                                        " is out of range (-1e6..1e6 degrees, taken modulo 360)");
                // Into (-180, 180] as docs/osc.md reports it.
                theta = std::fmod(theta, 360.0);
                if (theta > 180.0)
                    theta -= 360.0;
                if (theta <= -180.0)
                    theta += 360.0;
                st.r_over_a = ra;
                st.theta_deg = theta;
                st.spot_column = t.column;
                i += 2;
            } else if (t.text.find('/') != std::string::npos && starts_numeric(t.text)) {
                if (st.beats)
                    fail(t.column, "second duration in one note");
                st.beats = duration(t, "note duration");
            } else if (starts_numeric(t.text)) {
                if (st.dynamics)
                    fail(t.column, "second dynamics '" + t.text +
                                       "' in one note (for a duration write 'beats " + t.text +
                                       "' or N/D)");
                st.dynamics = dynamics_value(t);
            } else if (hand_word(t.lower) || foot_word(t.lower) || left_foot_word(t.lower) ||
                       t.lower == "both" || t.lower == "r+l" || t.lower == "l+r") {
                fail(t.column, "'" + t.text +
                                   "' starts another note: separate notes with ',' or a new "
                                   "line ('R, L'), or join notes on one beat with ' + ' ('R + L')");
            } else if (i == 1) {
                fail(t.column, "unknown nuance '" + t.text + "' (valid: " + nuance_list() + ")");
            } else {
                fail(t.column, "unexpected '" + t.text + "' in a note: expected a nuance (" +
                                   nuance_list() + "), dynamics (0..1 or " + dynamics_list() +
                                   "), a duration (N/D or 'beats X'), 'at R/A THETA', "
                                   "'firmness F', 'on DRUM', 'flam', 'drag' or a hi-hat's "
                                   "'open', 'half', 'closed'");
            }
        }
    }
};

} // namespace

// ---------------------------------------------------------------- builder

struct ScoreBuilder::State {
    std::string source;
    std::vector<Statement> statements; // parsed, not yet executed
    std::vector<size_t> open_repeats;  // indices into statements
    int calls = 0;
    std::optional<ScoreError> first_error;
};

ScoreBuilder::ScoreBuilder(std::string source_name) : state_(std::make_unique<State>())
{
    state_->source = std::move(source_name);
}
ScoreBuilder::~ScoreBuilder() = default;
ScoreBuilder::ScoreBuilder(ScoreBuilder &&) noexcept = default;
ScoreBuilder::ScoreBuilder(const ScoreBuilder &other)
    : state_(std::make_unique<State>(*other.state_))
{
}
ScoreBuilder &ScoreBuilder::operator=(ScoreBuilder &&) noexcept = default;

int ScoreBuilder::statements() const
{
    return state_->calls;
}
double ScoreBuilder::first_tempo_bpm() const
{
    double bpm = kDefaultTempoBpm;
    for (const Statement &st : state_->statements) {
        if (st.kind == Kind::note || st.kind == Kind::roll || st.kind == Kind::rest)
            break;
        if (st.kind == Kind::tempo && st.start_bpm)
            bpm = *st.start_bpm;
    }
    return bpm;
}
std::size_t ScoreBuilder::parsed_statements() const
{
    return state_->statements.size();
}
bool ScoreBuilder::failed() const
{
    return state_->first_error.has_value();
}

void ScoreBuilder::reset()
{
    std::string source = state_->source;
    *state_ = State();
    state_->source = source;
}

void ScoreBuilder::add_line(const std::string &text, int line)
{
    LineParser parser(state_->source, line);
    std::vector<Statement> parsed = parser.parse(text); // throws before anything changes
    // Balance repeat/end first, so a stray 'end' changes nothing: the line's
    // own repeats, and how many of those already open its ends close (the
    // time a line takes does not grow with the depth of the repeats open).
    std::vector<size_t> opened;
    size_t closed = 0; // of state_->open_repeats, from its end
    size_t index = state_->statements.size();
    for (const Statement &st : parsed) {
        if (st.kind == Kind::repeat) {
            opened.push_back(index);
        } else if (st.kind == Kind::end) {
            if (!opened.empty())
                opened.pop_back();
            else if (closed < state_->open_repeats.size())
                ++closed;
            else
                throw ScoreError(state_->source, st.line, st.column, "'end' without 'repeat'");
        }
        ++index;
    }
    state_->statements.insert(state_->statements.end(), parsed.begin(), parsed.end());
    std::vector<size_t> &open = state_->open_repeats;
    open.resize(open.size() - closed);
    open.insert(open.end(), opened.begin(), opened.end());
}

void ScoreBuilder::set_default_nuance(Nuance nuance)
{
    Statement st;
    st.kind = Kind::default_nuance;
    st.nuance = nuance;
    state_->statements.push_back(st);
}

void ScoreBuilder::set_start_tempo(double bpm)
{
    if (!(bpm >= 20.0 && bpm <= 400.0))
        throw ScoreError(state_->source, 0, 0,
                         "the starting tempo " + std::to_string(bpm) +
                             " is out of range (20..400 bpm)");
    Statement st;
    st.kind = Kind::tempo;
    st.start_bpm = bpm;
    st.end_bpm = bpm;
    state_->statements.push_back(st);
}

void ScoreBuilder::add_statement(const std::string &text)
{
    const int line = ++state_->calls;
    try {
        add_line(text, line);
    } catch (const ScoreError &e) {
        if (!state_->first_error)
            state_->first_error = e;
        throw;
    }
}

Score ScoreBuilder::finish() const
{
    const State &s = *state_;
    if (s.first_error)
        throw ScoreError(s.first_error->source(), s.first_error->line(), s.first_error->column(),
                         s.first_error->message() +
                             " (the score is refused; reset and send it again)");
    if (!s.open_repeats.empty()) {
        const Statement &r = s.statements[s.open_repeats.back()];
        throw ScoreError(s.source, r.line, r.column, "'repeat' without 'end'");
    }
    return score_detail::execute_statements(s.source, s.statements);
}

} // namespace ictus
