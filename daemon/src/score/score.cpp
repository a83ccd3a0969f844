// score.cpp -- the score language (docs/score.md): tokenizer, statement
// parser and the executor that expands repeats into notes (the tempo map:
// tempo_map.cpp).
// Parsing is in two passes so that nothing is produced from a faulty score:
// every statement is parsed and range-checked first (add_line), and only a
// complete, balanced statement list is executed into a Score (finish).
#include "ictus/score/score.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace ictus
{

namespace
{
// A message quotes the score's words as typed: control bytes in them (a NUL
// cut the message short on a terminal, and in C strings) are shown as \xNN.
std::string printable(const std::string &message)
{
    std::string out;
    for (const char c : message) {
        const auto u = static_cast<unsigned char>(c);
        if ((u < 0x20 && c != '\t') || u == 0x7f) {
            static const char hex[] = "0123456789abcdef";
            out += "\\x";
            out += hex[u >> 4];
            out += hex[u & 15];
        } else {
            out += c;
        }
    }
    return out;
}
} // namespace

ScoreError::ScoreError(const std::string &source, int line, int column, const std::string &message)
    : std::runtime_error(source + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " +
                         printable(message)),
      source_(source), line_(line), column_(column), message_(printable(message))
{
}

const std::vector<DynamicsWord> &dynamics_words()
{
    // Evenly spread over the range, mf = the default 0.6 and ff = the loudest.
    static const std::vector<DynamicsWord> words = {{"pp", 0.2}, {"p", 0.3}, {"mp", 0.45},
                                                    {"mf", 0.6}, {"f", 0.8}, {"ff", 1.0}};
    return words;
}

// ---------------------------------------------------------------- statements

namespace
{

struct Token {
    std::string text;
    std::string lower;
    int column = 0;
};

enum class Kind {
    note,
    rest,
    tempo,
    grip,
    default_beats,
    default_dynamics,
    default_firmness,
    default_nuance,
    repeat,
    end,
    humanize
};

struct Statement {
    Kind kind = Kind::note;
    int line = 0;
    int column = 0;
    // note
    Side hand = Side::right;
    bool both_hands = false;        // R+L: one stroke of each hand on the same beat
    std::optional<Nuance> nuance;   // note, default_nuance
    std::optional<double> beats;    // note, rest, default_beats
    std::optional<double> dynamics; // note, default_dynamics
    std::optional<double> r_over_a, theta_deg;
    std::optional<double> firmness; // note, default_firmness
    // tempo: start_bpm absent means "from the current tempo"
    std::optional<double> start_bpm;
    double end_bpm = 0.0;
    double ramp_beats = 0.0;
    Grip grip = Grip::french;
    int count = 0; // repeat
    double humanize = 0.0;
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
                out.push_back(statement(tokens));
            tokens.clear();
        };
        size_t i = 0;
        while (i < text.size()) {
            const char c = text[i];
            if (c == '#')
                break;
            if (c == ',' || c == ';' || c == '\n') {
                flush();
                ++i;
                continue;
            }
            if (std::isspace(static_cast<unsigned char>(c))) {
                ++i;
                continue;
            }
            Token t;
            t.column = static_cast<int>(i) + 1;
            while (i < text.size() && !std::isspace(static_cast<unsigned char>(text[i])) &&
                   text[i] != ',' && text[i] != ';' && text[i] != '#')
                t.text += text[i++];
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
        } else if (key == "r+l" || key == "l+r" || key == "both") {
            st.kind = Kind::note;
            st.both_hands = true;
            note_options(tk, st);
            if (st.r_over_a)
                fail(tk[0].column, "'at' places one stick; " + tk[0].text +
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
                st.ramp_beats = duration(len, "tempo change length");
                if (st.ramp_beats > kMaxRampBeats)
                    fail(len.column,
                         "tempo change length " + len.text + " is out of range (1/32..1024 beats)");
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
            st.dynamics =
                one_value(tk, st, Kind::default_dynamics, "'dynamics' needs a value 0..1 or pp..ff",
                          "the dynamics", [&](const Token &t) { return dynamics_value(t); });
        } else if (key == "nuance") {
            st.nuance = one_value(tk, st, Kind::default_nuance,
                                  "'nuance' needs a nuance, e.g. 'nuance accent'", "the nuance",
                                  [&](const Token &t) { return nuance_value(t); });
        } else if (key == "firmness") {
            st.firmness =
                one_value(tk, st, Kind::default_firmness, "'firmness' needs a value 0..1",
                          "the firmness", [&](const Token &t) { return firmness_value(t); });
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
            fail(tk[0].column,
                 "unknown statement '" + tk[0].text +
                     "' (expected a hand R, L, right, left, R+L, or tempo, grip, rest, "
                     "beats, dynamics, firmness, nuance, humanize, repeat, end)");
        }
        return st;
    }

    Nuance nuance_value(const Token &t) const
    {
        const std::optional<Nuance> nuance = nuance_word(t.lower);
        if (!nuance)
            fail(t.column, "unknown nuance '" + t.text + "' (valid: " + nuance_list() + ")");
        return *nuance;
    }

    double firmness_value(const Token &t) const
    {
        const double f = number(t, "firmness");
        if (!(f >= 0.0 && f <= 1.0))
            fail(t.column, "firmness " + t.text + " is out of range (0..1: 0 loose, 1 firm)");
        return f;
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
                    fail(th.column, "theta " + th.text + " is out of range");
                // Into (-180, 180] as docs/osc.md reports it.
                theta = std::fmod(theta, 360.0);
                if (theta > 180.0)
                    theta -= 360.0;
                if (theta <= -180.0)
                    theta += 360.0;
                st.r_over_a = ra;
                st.theta_deg = theta;
                i += 2;
            } else if (t.text.find('/') != std::string::npos && starts_numeric(t.text)) {
                if (st.beats)
                    fail(t.column, "second duration in one note");
                st.beats = duration(t, "note duration");
            } else if (starts_numeric(t.text)) {
                if (st.dynamics)
                    fail(t.column, "second dynamics '" + t.text + "' in one note");
                st.dynamics = dynamics_value(t);
            } else if (i == 1) {
                fail(t.column, "unknown nuance '" + t.text + "' (valid: " + nuance_list() + ")");
            } else {
                fail(t.column, "unexpected '" + t.text + "' in a note: expected a nuance (" +
                                   nuance_list() + "), dynamics (0..1 or " + dynamics_list() +
                                   "), a duration (N/D or 'beats X'), 'at R/A THETA' or "
                                   "'firmness F'");
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
    // Balance repeat/end on a copy first, so a stray 'end' changes nothing.
    std::vector<size_t> open = state_->open_repeats;
    size_t index = state_->statements.size();
    for (const Statement &st : parsed) {
        if (st.kind == Kind::repeat)
            open.push_back(index);
        else if (st.kind == Kind::end) {
            if (open.empty())
                throw ScoreError(state_->source, st.line, st.column, "'end' without 'repeat'");
            open.pop_back();
        }
        ++index;
    }
    state_->statements.insert(state_->statements.end(), parsed.begin(), parsed.end());
    state_->open_repeats = open;
}

void ScoreBuilder::set_default_nuance(Nuance nuance)
{
    Statement st;
    st.kind = Kind::default_nuance;
    st.nuance = nuance;
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

    Score score;
    score.source = s.source;
    double beat = 0.0;
    Grip grip = Grip::french;
    double default_beats = kDefaultNoteBeats;
    double default_dynamics = kDefaultDynamics;
    double default_firmness = -1.0; // the performance's
    Nuance default_nuance = Nuance::legato;
    struct Loop {
        size_t body; // first statement of the body
        int left;    // passes still to play after this one
    };
    std::vector<Loop> loops;
    auto advance = [&](const Statement &st, double beats) {
        beat += beats;
        if (beat > kMaxScoreBeats)
            throw ScoreError(s.source, st.line, st.column,
                             "the score is longer than 100000 beats (check the repeat counts)");
    };
    long steps = 0;
    for (size_t pc = 0; pc < s.statements.size(); ++pc) {
        const Statement &st = s.statements[pc];
        if (++steps > kMaxScoreSteps)
            throw ScoreError(s.source, st.line, st.column,
                             "the score executes more than 1000000 statements (check the repeat "
                             "counts: repeats nested around no note or rest)");
        switch (st.kind) {
        case Kind::note: {
            if (score.notes.size() >= static_cast<size_t>(kMaxScoreNotes))
                throw ScoreError(s.source, st.line, st.column,
                                 "the score has more than 100000 notes (check the repeat counts)");
            ScoreNote n;
            n.beat = beat;
            n.beats = st.beats.value_or(default_beats);
            n.nuance = st.nuance.value_or(default_nuance);
            n.grip = grip;
            n.dynamics = st.dynamics.value_or(default_dynamics);
            n.r_over_a = st.r_over_a.value_or(kDefaultRadiusFraction);
            n.firmness = st.firmness.value_or(default_firmness);
            n.line = st.line;
            n.column = st.column;
            for (Side hand : {Side::right, Side::left}) {
                if (!st.both_hands && hand != st.hand)
                    continue;
                n.hand = hand;
                n.theta_deg = st.theta_deg.value_or(kDefaultThetaDeg[static_cast<int>(hand)]);
                score.notes.push_back(n);
            }
            advance(st, n.beats);
            break;
        }
        case Kind::rest:
            advance(st, st.beats.value_or(default_beats));
            break;
        case Kind::tempo: {
            const double start = st.start_bpm.value_or(score.tempo.tempo_at_beat(beat));
            score.tempo.add(beat, start, st.end_bpm, st.ramp_beats);
            break;
        }
        case Kind::grip:
            grip = st.grip;
            break;
        case Kind::default_beats:
        case Kind::default_dynamics:
        case Kind::default_firmness:
        case Kind::default_nuance:
            // A default statement carries its one value; the others stay.
            default_beats = st.beats.value_or(default_beats);
            default_dynamics = st.dynamics.value_or(default_dynamics);
            default_firmness = st.firmness.value_or(default_firmness);
            default_nuance = st.nuance.value_or(default_nuance);
            break;
        case Kind::humanize:
            score.humanize = st.humanize;
            break;
        case Kind::repeat:
            loops.push_back({pc + 1, st.count - 1});
            break;
        case Kind::end:
            if (loops.back().left > 0) {
                --loops.back().left;
                pc = loops.back().body - 1;
            } else {
                loops.pop_back();
            }
            break;
        }
    }
    score.length_beats = beat;
    return score;
}

Score parse_score(const std::string &text, const std::string &source_name)
{
    ScoreBuilder builder(source_name);
    // Lines end in LF, CRLF or a lone CR (old Mac editors): a score saved
    // with CRs alone would otherwise be one line, and its first statement's
    // error would name the second's word. A UTF-8 byte order mark, which
    // Windows editors write, is not part of the first statement.
    std::size_t start = text.compare(0, 3, "\xEF\xBB\xBF") == 0 ? 3 : 0;
    int number = 0;
    while (start < text.size()) {
        const std::size_t end = text.find_first_of("\r\n", start);
        if (end == std::string::npos) {
            builder.add_line(text.substr(start), ++number);
            break;
        }
        builder.add_line(text.substr(start, end - start), ++number);
        start = end + (text.compare(end, 2, "\r\n") == 0 ? 2 : 1);
    }
    return builder.finish();
}

Score load_score(const std::string &path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw ScoreError(path, 0, 0, "cannot read the score file");
    std::ostringstream text;
    text << in.rdbuf();
    return parse_score(text.str(), path);
}

const char *default_score_text()
{
    // The paper's Figure 5: legato and accent beats of both hands under a
    // tempo change (here an accelerando then a ritardando), ~15 s.
    return R"(# ictus default score: legato and accent beats under a tempo change
# (the paper's Figure 5). See docs/score.md for the language.
tempo 90
grip french
R legato, L legato, R legato, L legato
R accent f, L legato, R accent f, L legato
tempo 90 -> 160 over 8
R legato, L accent f, R legato, L accent f
R legato, L legato, R accent ff, L accent ff
R legato 1/2, L legato 1/2, R legato 1/2, L legato 1/2, R accent f, L accent f
R tenuto p, L tenuto p, R staccato, L staccato
tempo 160 -> 100 over 6
R legato, L legato, R vertical_accent f, L vertical_accent f
R accent ff, L accent ff
)";
}

} // namespace ictus
