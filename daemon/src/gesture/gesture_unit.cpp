// gesture_unit.cpp -- nuance names, the unit's interpolant, the database and
// its JSON form (docs/gestures.md, "File format").
#include "ictus/gesture/gesture.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

namespace ictus
{

namespace
{

const char *const kNuanceNames[kNuances] = {"legato",          "tenuto",   "accent",
                                            "vertical_accent", "staccato", "buzz"};

std::string valid_nuances()
{
    std::string s;
    for (int i = 0; i < kNuances; ++i)
        s += std::string(i ? ", " : "") + kNuanceNames[i];
    return s;
}

} // namespace

const char *to_string(Nuance n)
{
    const int i = static_cast<int>(n);
    return i >= 0 && i < kNuances ? kNuanceNames[i] : "?";
}

Nuance nuance_from_string(const std::string &s)
{
    for (int i = 0; i < kNuances; ++i)
        if (s == kNuanceNames[i])
            return static_cast<Nuance>(i);
    if (s == "vertical-accent")
        return Nuance::vertical_accent;
    throw GestureError("unknown nuance '" + s + "' (valid: " + valid_nuances() + ")");
}

int loudness_rank(Nuance n)
{
    for (int i = 0; i < kNuances; ++i)
        if (kLoudnessOrder[i] == n)
            return i;
    return 0;
}

const char *to_string(Side side)
{
    return side == Side::left ? "left" : "right";
}

Side side_from_string(const std::string &s)
{
    if (s == "left" || s == "L" || s == "l")
        return Side::left;
    if (s == "right" || s == "R" || s == "r")
        return Side::right;
    throw GestureError("unknown hand '" + s + "' (valid: left, right)");
}

// ---------------------------------------------------------------------------
// The interpolant: cubic Hermite per segment with Catmull-Rom tangents. The
// strike is a corner (the velocity reverses at impact), so the tangents on
// its two sides are one-sided second-order differences; so are the ends'.

namespace
{

// Tangent (per sample, not per second) at sample k seen from the side
// `from_left` (segment [k-1, k]) or from the right (segment [k, k+1]).
Eigen::Vector3d tangent(const GestureUnit &u, int k, bool from_left)
{
    const auto &p = u.tip_m;
    const int n = u.samples();
    const bool corner = k == u.strike_index;
    const bool use_left = k == n - 1 || (corner && from_left);
    const bool use_right = k == 0 || (corner && !from_left);
    if (use_left) {
        if (k >= 2)
            return 0.5 * (3.0 * p[k] - 4.0 * p[k - 1] + p[k - 2]);
        return p[k] - p[k - 1];
    }
    if (use_right) {
        if (k + 2 <= n - 1)
            return 0.5 * (-3.0 * p[k] + 4.0 * p[k + 1] - p[k + 2]);
        return p[k + 1] - p[k];
    }
    return 0.5 * (p[k + 1] - p[k - 1]);
}

// Segment index and local parameter for time t (clamped).
void locate(const GestureUnit &u, double t_s, int &k, double &s)
{
    const double x = std::clamp(t_s * u.rate_hz, 0.0, static_cast<double>(u.samples() - 1));
    k = std::min(static_cast<int>(std::floor(x)), u.samples() - 2);
    s = x - k;
}

} // namespace

double GestureUnit::duration_s() const
{
    return tip_m.size() < 2 ? 0.0 : (static_cast<double>(tip_m.size()) - 1.0) / rate_hz;
}

double GestureUnit::strike_time_s() const
{
    return strike_index / rate_hz;
}

Eigen::Vector3d GestureUnit::sample(double t_s) const
{
    if (tip_m.empty())
        return Eigen::Vector3d::Zero();
    if (tip_m.size() == 1 || !std::isfinite(t_s))
        return tip_m.front();
    int k;
    double s;
    locate(*this, t_s, k, s);
    const Eigen::Vector3d m0 = tangent(*this, k, false), m1 = tangent(*this, k + 1, true);
    const double s2 = s * s, s3 = s2 * s;
    return (2 * s3 - 3 * s2 + 1) * tip_m[k] + (s3 - 2 * s2 + s) * m0 +
           (-2 * s3 + 3 * s2) * tip_m[k + 1] + (s3 - s2) * m1;
}

Eigen::Vector3d GestureUnit::velocity(double t_s) const
{
    if (tip_m.size() < 2 || !std::isfinite(t_s) || t_s < 0.0 || t_s > duration_s())
        return Eigen::Vector3d::Zero();
    int k;
    double s;
    locate(*this, t_s, k, s);
    const Eigen::Vector3d m0 = tangent(*this, k, false), m1 = tangent(*this, k + 1, true);
    const double s2 = s * s;
    const Eigen::Vector3d d = (6 * s2 - 6 * s) * tip_m[k] + (3 * s2 - 4 * s + 1) * m0 +
                              (-6 * s2 + 6 * s) * tip_m[k + 1] + (3 * s2 - 2 * s) * m1;
    return d * rate_hz;
}

double GestureUnit::impact_speed_mps() const
{
    if (strike_index < 1 || strike_index >= samples())
        return 0.0;
    // The largest downward speed of the interpolant at the knots within two
    // samples before the strike. For model units (strike exactly on a sample,
    // speed growing to it) it is the left derivative at the strike; for
    // captures, whose lowest sample may already lie past the contact, it is
    // the approach speed rather than the chord across the corner.
    double speed = -tangent(*this, strike_index, true).y();
    for (int k = std::max(1, strike_index - 2); k < strike_index; ++k)
        speed = std::max(speed, -tangent(*this, k, true).y());
    return speed * rate_hz;
}

double GestureUnit::preparation_height_m() const
{
    double h = 0.0;
    for (int k = 0; k <= strike_index && k < samples(); ++k)
        h = std::max(h, tip_m[k].y());
    return h;
}

// ---------------------------------------------------------------------------
// The database.

double dynamics_height_factor(double dynamics)
{
    return std::pow(std::clamp(dynamics, 0.04, 1.0), 1.3);
}

GestureDatabase GestureDatabase::builtin()
{
    GestureDatabase db;
    for (Grip g : {Grip::french, Grip::german})
        for (int n = 0; n < kNuances; ++n)
            for (Side h : {Side::left, Side::right})
                db.add(stroke_model(g, static_cast<Nuance>(n), h, 0.6, 0.5));
    return db;
}

void GestureDatabase::add(GestureUnit u)
{
    for (auto &v : units_)
        if (v.grip == u.grip && v.nuance == u.nuance && v.hand == u.hand) {
            v = std::move(u);
            return;
        }
    units_.push_back(std::move(u));
}

const GestureUnit *GestureDatabase::find(Grip g, Nuance n, Side h) const
{
    for (const auto &v : units_)
        if (v.grip == g && v.nuance == n && v.hand == h)
            return &v;
    return nullptr;
}

GestureUnit GestureDatabase::instantiate(Grip g, Nuance n, Side h, double dynamics) const
{
    const GestureUnit *stored = find(g, n, h);
    if (!stored || stored->source == "model") {
        const double period = stored ? stored->period_s : 0.5;
        const double d = std::isfinite(dynamics) ? dynamics : (stored ? stored->dynamics : 0.6);
        return stroke_model(g, n, h, d, period);
    }
    GestureUnit u = *stored;
    if (!std::isfinite(dynamics))
        return u;
    const double d = std::clamp(dynamics, 0.0, 1.0);
    // Heights (and with them vertical velocities) scale with the dynamics
    // rule; timing and the horizontal path are kept.
    const double k = dynamics_height_level(d) / dynamics_height_level(u.dynamics);
    for (auto &p : u.tip_m)
        p.y() *= k;
    u.dynamics = d;
    return u;
}

// ---------------------------------------------------------------------------
// JSON. Written by hand so that every unit header and every sample sits on its
// own line (diffable, and errors can point at lines); read with nlohmann.

namespace
{

std::string num(double v)
{
    // Shortest round-trip representation, as nlohmann writes doubles.
    return nlohmann::json(v).dump();
}

std::string vec3(const Eigen::Vector3d &v)
{
    return "[" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + "]";
}

// The deepest nesting of arrays and objects a database may have: a valid one
// has 5 (the document, "units", a unit, "tip_m", a sample). Deeper text is
// refused before it is parsed, at the line where it goes past the bound.
constexpr int kMaxJsonDepth = 16;

// The largest database read: 16 MiB, some 180000 samples (the built-in one
// is 0.4 MiB; a stroke of a capture at 250 Hz, 0.5 s, about 11 KiB).
constexpr size_t kMaxDatabaseBytes = size_t{16} << 20;

// Skips the string whose opening quote is at text[i]; i ends on its closing
// quote (or the end). Newlines in it are counted into `line`.
void skip_string(const std::string &text, size_t &i, int &line, std::string *out)
{
    for (++i; i < text.size() && text[i] != '"'; ++i) {
        if (text[i] == '\\' && i + 1 < text.size())
            ++i;
        if (text[i] == '\n')
            ++line;
        if (out)
            *out += text[i];
    }
}

// One linear scan: a GestureError naming the line where the nesting goes
// deeper than kMaxJsonDepth.
void check_depth(const std::string &file, const std::string &text)
{
    int depth = 0, line = 1;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (c == '\n') {
            ++line;
        } else if (c == '"') {
            skip_string(text, i, line, nullptr);
        } else if (c == '{' || c == '[') {
            if (++depth > kMaxJsonDepth)
                throw GestureError(
                    file + ":" + std::to_string(line) + ": arrays and objects nested deeper than " +
                    std::to_string(kMaxJsonDepth) + " levels (a gesture database has 5)");
        } else if (c == '}' || c == ']') {
            depth = std::max(0, depth - 1);
        }
    }
}

std::vector<std::string> pointer_parts(const std::string &pointer)
{
    std::vector<std::string> parts;
    size_t at = 0;
    while (at < pointer.size()) {
        const size_t next = pointer.find('/', at + 1);
        parts.push_back(
            pointer.substr(at + 1, next == std::string::npos ? std::string::npos : next - at - 1));
        at = next == std::string::npos ? pointer.size() : next;
    }
    return parts;
}

// The line of the value at a JSON pointer ("/units/3/grip") in text nlohmann
// has already accepted, else of its nearest parent: one linear scan that
// follows only the pointer's path (0 when not even the document is found).
int pointer_line(const std::string &text, const std::string &pointer)
{
    const std::vector<std::string> want = pointer_parts(pointer);
    struct Frame {
        bool array;
        long index;
        bool on_path;     // this container is the value at want[0 .. depth)
        bool key_matches; // an object's current key is want[depth]
    };
    std::vector<Frame> stack;
    int line = 1, found = 0, found_depth = -1;
    bool expect_value = true; // at top level
    // A value starts here: true when it is on the pointer's path.
    auto begin_value = [&]() {
        if (!expect_value)
            return false;
        expect_value = false;
        const size_t d = stack.size();
        bool on = d == 0;
        if (d > 0 && stack.back().on_path && d <= want.size())
            on = stack.back().array ? want[d - 1] == std::to_string(stack.back().index)
                                    : stack.back().key_matches;
        if (on && static_cast<int>(d) > found_depth) {
            found = line;
            found_depth = static_cast<int>(d);
        }
        return on;
    };
    for (size_t i = 0; i < text.size() && found_depth < static_cast<int>(want.size()); ++i) {
        const char c = text[i];
        if (c == '\n') {
            ++line;
        } else if (c == '"') {
            const bool is_key = !stack.empty() && !stack.back().array && !expect_value;
            if (!is_key)
                begin_value(); // on the line of its opening quote
            std::string s;
            skip_string(text, i, line, is_key ? &s : nullptr);
            if (is_key) {
                Frame &f = stack.back();
                const size_t d = stack.size();
                f.key_matches = f.on_path && d <= want.size() && s == want[d - 1];
            }
        } else if (c == ':') {
            expect_value = true;
        } else if (c == ',') {
            if (!stack.empty() && stack.back().array) {
                ++stack.back().index;
                expect_value = true;
            }
        } else if (c == '{' || c == '[') {
            const bool on = begin_value();
            stack.push_back({c == '[', 0, on, false});
            expect_value = c == '[';
        } else if (c == '}' || c == ']') {
            if (!stack.empty())
                stack.pop_back();
            expect_value = false;
        } else if (!std::isspace(static_cast<unsigned char>(c))) {
            begin_value();
        }
    }
    return found;
}

class JsonReader
{
  public:
    JsonReader(std::string file, const std::string &text) : file_(std::move(file)), text_(text) {}
    [[noreturn]] void fail(const std::string &pointer, const std::string &what) const
    {
        // The line of the value, else of its nearest parent.
        const int line = pointer_line(text_, pointer);
        throw GestureError(file_ + ":" + std::to_string(line) + ": " + pointer + ": " + what);
    }
    const nlohmann::json &member(const nlohmann::json &obj, const std::string &ptr,
                                 const char *key) const
    {
        if (!obj.contains(key))
            fail(ptr, std::string("missing \"") + key + "\"");
        return obj.at(key);
    }
    double number(const nlohmann::json &v, const std::string &ptr) const
    {
        if (!v.is_number())
            fail(ptr, "expected a number, got " + v.dump());
        const double x = v.get<double>();
        if (!std::isfinite(x))
            fail(ptr, "not finite");
        return x;
    }
    std::string string(const nlohmann::json &v, const std::string &ptr) const
    {
        if (!v.is_string())
            fail(ptr, "expected a string, got " + v.dump());
        return v.get<std::string>();
    }
    std::vector<Eigen::Vector3d> vectors(const nlohmann::json &v, const std::string &ptr) const
    {
        if (!v.is_array())
            fail(ptr, "expected an array of [x, y, z]");
        std::vector<Eigen::Vector3d> out;
        out.reserve(v.size());
        for (size_t i = 0; i < v.size(); ++i) {
            const std::string p = ptr + "/" + std::to_string(i);
            if (!v[i].is_array() || v[i].size() != 3)
                fail(p, "expected [x, y, z], got " + v[i].dump());
            out.emplace_back(number(v[i][0], p + "/0"), number(v[i][1], p + "/1"),
                             number(v[i][2], p + "/2"));
        }
        return out;
    }

  private:
    std::string file_;
    const std::string &text_;
};

} // namespace

void GestureDatabase::save_json(const std::string &path) const
{
    std::ofstream out(path);
    if (!out)
        throw GestureError(path + ":0: cannot open for writing");
    out << "{\n\"format\": \"ictus-gestures\",\n\"version\": 1,\n\"units\": [\n";
    for (size_t i = 0; i < units_.size(); ++i) {
        const GestureUnit &u = units_[i];
        out << "{\"grip\": \"" << to_string(u.grip) << "\", \"nuance\": \"" << to_string(u.nuance)
            << "\", \"hand\": \"" << to_string(u.hand) << "\", \"rate_hz\": " << num(u.rate_hz)
            << ", \"strike_index\": " << u.strike_index << ", \"dynamics\": " << num(u.dynamics)
            << ", \"period_s\": " << num(u.period_s)
            << ", \"capture_time_s\": " << num(u.capture_time_s)
            << ", \"source\": " << nlohmann::json(u.source).dump() << ",\n\"tip_m\": [\n";
        for (size_t k = 0; k < u.tip_m.size(); ++k)
            out << vec3(u.tip_m[k]) << (k + 1 < u.tip_m.size() ? ",\n" : "\n");
        out << "],\n\"stick_dir\": [\n";
        for (size_t k = 0; k < u.stick_dir.size(); ++k)
            out << vec3(u.stick_dir[k]) << (k + 1 < u.stick_dir.size() ? ",\n" : "\n");
        out << "]}" << (i + 1 < units_.size() ? ",\n" : "\n");
    }
    out << "]\n}\n";
    if (!out)
        throw GestureError(path + ":0: write failed");
}

GestureDatabase GestureDatabase::load_json(const std::string &path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in)
        throw GestureError(path + ":0: cannot open");
    // At most kMaxDatabaseBytes and one byte more, to know it is more
    // (/dev/zero, a FIFO: no size to ask for first).
    std::string text;
    char buf[65536];
    while (text.size() <= kMaxDatabaseBytes && in.read(buf, sizeof buf).gcount() > 0)
        text.append(buf, static_cast<size_t>(in.gcount()));
    if (in.bad())
        throw GestureError(path + ":0: read error");
    if (text.size() > kMaxDatabaseBytes)
        throw GestureError(path + ":0: larger than " + std::to_string(kMaxDatabaseBytes >> 20) +
                           " MiB, the bound of a gesture database");
    return parse_json(text, path);
}

GestureDatabase GestureDatabase::parse_json(const std::string &text, const std::string &path)
{
    if (text.size() > kMaxDatabaseBytes)
        throw GestureError(path + ":0: larger than " + std::to_string(kMaxDatabaseBytes >> 20) +
                           " MiB, the bound of a gesture database");
    check_depth(path, text);
    nlohmann::json doc;
    try {
        doc = nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error &e) {
        const size_t byte = std::min<size_t>(e.byte, text.size());
        const int line =
            1 + static_cast<int>(std::count(text.begin(), text.begin() + byte - (byte > 0), '\n'));
        throw GestureError(path + ":" + std::to_string(line) + ": malformed JSON: " + e.what());
    } catch (const nlohmann::json::exception &e) {
        // A number past a double's range ("number overflow parsing '1e999'"):
        // the line of the first such text.
        const std::string what = e.what();
        const size_t open = what.find('\''), close = what.rfind('\'');
        const size_t at =
            open < close ? text.find(what.substr(open + 1, close - open - 1)) : std::string::npos;
        const int line =
            at == std::string::npos
                ? 0
                : 1 + static_cast<int>(std::count(text.begin(), text.begin() + at, '\n'));
        throw GestureError(path + ":" + std::to_string(line) + ": " + what);
    }
    const JsonReader r(path, text);
    if (!doc.is_object())
        r.fail("", "expected an object {\"format\": \"ictus-gestures\", \"units\": [...]}");
    if (!doc.contains("format") || doc["format"] != "ictus-gestures")
        r.fail("/format", "expected \"format\": \"ictus-gestures\"");
    const auto &units = r.member(doc, "", "units");
    if (!units.is_array())
        r.fail("/units", "expected an array of units");
    GestureDatabase db;
    for (size_t i = 0; i < units.size(); ++i) {
        const std::string p = "/units/" + std::to_string(i);
        const auto &j = units[i];
        if (!j.is_object())
            r.fail(p, "expected a unit object");
        GestureUnit u;
        try {
            u.grip = grip_from_string(r.string(r.member(j, p, "grip"), p + "/grip"));
        } catch (const CharacterError &e) {
            r.fail(p + "/grip", e.what());
        }
        try {
            u.nuance = nuance_from_string(r.string(r.member(j, p, "nuance"), p + "/nuance"));
            u.hand = side_from_string(r.string(r.member(j, p, "hand"), p + "/hand"));
        } catch (const GestureError &e) {
            if (std::string(e.what()).find("nuance") != std::string::npos)
                r.fail(p + "/nuance", e.what());
            r.fail(p + "/hand", e.what());
        }
        u.rate_hz = r.number(r.member(j, p, "rate_hz"), p + "/rate_hz");
        if (u.rate_hz <= 0.0 || u.rate_hz > 100000.0)
            r.fail(p + "/rate_hz", "must be in (0, 100000] Hz");
        const double si = r.number(r.member(j, p, "strike_index"), p + "/strike_index");
        u.dynamics = r.number(r.member(j, p, "dynamics"), p + "/dynamics");
        if (u.dynamics < 0.0 || u.dynamics > 1.0)
            r.fail(p + "/dynamics", "must be in [0, 1]");
        if (j.contains("period_s")) {
            u.period_s = r.number(j["period_s"], p + "/period_s");
            if (u.period_s <= 0.0)
                r.fail(p + "/period_s", "must be > 0");
        }
        if (j.contains("capture_time_s"))
            u.capture_time_s = r.number(j["capture_time_s"], p + "/capture_time_s");
        if (j.contains("source"))
            u.source = r.string(j["source"], p + "/source");
        u.tip_m = r.vectors(r.member(j, p, "tip_m"), p + "/tip_m");
        if (u.tip_m.size() < 2)
            r.fail(p + "/tip_m", "needs at least 2 samples");
        if (j.contains("stick_dir"))
            u.stick_dir = r.vectors(j["stick_dir"], p + "/stick_dir");
        if (!u.stick_dir.empty() && u.stick_dir.size() != u.tip_m.size())
            r.fail(p + "/stick_dir", "has " + std::to_string(u.stick_dir.size()) +
                                         " samples, tip_m has " + std::to_string(u.tip_m.size()));
        if (si != std::floor(si) || si < 0 || si >= static_cast<double>(u.tip_m.size()))
            r.fail(p + "/strike_index",
                   "must be an integer in [0, " + std::to_string(u.tip_m.size() - 1) + "]");
        u.strike_index = static_cast<int>(si);
        db.add(std::move(u));
    }
    return db;
}

} // namespace ictus
