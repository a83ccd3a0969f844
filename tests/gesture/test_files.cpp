// The database's JSON file (exact round trip, errors with file and line) and
// the `gestures` verb (cmd_gestures, run in-process and through ictusd when
// the verb is wired in).
#include "ictus/cli/verbs.hpp"
#include "ictus/gesture/gesture.hpp"

#include <catch2/catch.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

using namespace ictus;
namespace fs = std::filesystem;

namespace
{

struct TempDir {
    fs::path path;
    TempDir()
        : path(fs::temp_directory_path() /
               ("ictus_gesture_" + std::to_string(::getpid()) + "_" + std::to_string(counter()++)))
    {
        fs::create_directories(path);
    }
    ~TempDir() { fs::remove_all(path); }
    std::string file(const std::string &name) const { return (path / name).string(); }
    static int &counter()
    {
        static int c = 0;
        return c;
    }
};

std::string slurp(const std::string &path)
{
    std::ifstream in(path);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

void write(const std::string &path, const std::string &text)
{
    std::ofstream(path) << text;
}

// Line (1-based) of the first occurrence of `needle` in the text.
int line_of(const std::string &text, const std::string &needle, size_t from = 0)
{
    const size_t pos = text.find(needle, from);
    REQUIRE(pos != std::string::npos);
    return 1 + static_cast<int>(std::count(text.begin(), text.begin() + pos, '\n'));
}

int run_verb(std::vector<std::string> args)
{
    args.insert(args.begin(), "gestures");
    std::vector<char *> argv;
    for (auto &a : args)
        argv.push_back(a.data());
    argv.push_back(nullptr);
    ictus::cli::Args parsed(static_cast<int>(args.size()), argv.data());
    return ictus::cli::run_verb("gestures", [&] { return ictus::cli::cmd_gestures(parsed); });
}

} // namespace

TEST_CASE("JSON round trip is exact", "[gesture][json]")
{
    TempDir dir;
    GestureDatabase db = GestureDatabase::builtin();
    // Plus a captured-looking unit without stick directions and awkward numbers.
    GestureUnit u =
        stroke_model(Grip::german, Nuance::tenuto, Side::left, 0.3141592653589793, 0.37);
    u.source = "weird \"name\".csv";
    u.stick_dir.clear();
    u.capture_time_s = 12.345678901234567;
    u.tip_m[1].x() = 1e-300;
    db.add(u);
    const std::string path = dir.file("db.json");
    db.save_json(path);
    const GestureDatabase back = GestureDatabase::load_json(path);
    REQUIRE(back.units().size() == db.units().size());
    for (size_t i = 0; i < db.units().size(); ++i) {
        const GestureUnit &a = db.units()[i], &b = back.units()[i];
        CHECK(a.grip == b.grip);
        CHECK(a.nuance == b.nuance);
        CHECK(a.hand == b.hand);
        CHECK(a.rate_hz == b.rate_hz);
        CHECK(a.strike_index == b.strike_index);
        CHECK(a.dynamics == b.dynamics);
        CHECK(a.period_s == b.period_s);
        CHECK(a.capture_time_s == b.capture_time_s);
        CHECK(a.source == b.source);
        REQUIRE(a.tip_m.size() == b.tip_m.size());
        REQUIRE(a.stick_dir.size() == b.stick_dir.size());
        for (size_t k = 0; k < a.tip_m.size(); ++k)
            REQUIRE(a.tip_m[k] == b.tip_m[k]); // bit-exact
        for (size_t k = 0; k < a.stick_dir.size(); ++k)
            REQUIRE(a.stick_dir[k] == b.stick_dir[k]);
    }
    // Saving again gives the same bytes.
    const std::string path2 = dir.file("db2.json");
    back.save_json(path2);
    CHECK(slurp(path) == slurp(path2));
}

TEST_CASE("bad JSON: errors name the file and the line", "[gesture][json]")
{
    TempDir dir;
    GestureDatabase db;
    db.add(stroke_model(Grip::french, Nuance::legato, Side::right, 0.6));
    db.add(stroke_model(Grip::french, Nuance::accent, Side::right, 0.6));
    const std::string good = dir.file("good.json");
    db.save_json(good);
    const std::string text = slurp(good);

    SECTION("syntax error")
    {
        // Drop a comma inside a sample of the first unit: "[x, y z]".
        const size_t start = text.find("\n[", text.find("\"tip_m\"") + 300) + 1;
        const size_t comma = text.find(", ", text.find(", ", start) + 1);
        REQUIRE(comma < text.find(']', start));
        std::string broken = text;
        broken.replace(comma, 2, " ");
        const int line = line_of(broken, "\n", start - 1) + 1;
        const std::string path = dir.file("syntax.json");
        write(path, broken);
        CHECK_THROWS_WITH(GestureDatabase::load_json(path),
                          Catch::Contains(path + ":" + std::to_string(line) + ": malformed JSON"));
    }
    SECTION("unknown nuance, on the second unit's line, listing the valid names")
    {
        std::string bad = text;
        const size_t second = bad.find("\"nuance\": \"accent\"");
        REQUIRE(second != std::string::npos);
        bad.replace(second, 18, "\"nuance\": \"sforzando\"");
        const std::string path = dir.file("nuance.json");
        write(path, bad);
        const int line = line_of(bad, "sforzando");
        try {
            GestureDatabase::load_json(path);
            FAIL("no error");
        } catch (const GestureError &e) {
            const std::string m = e.what();
            CHECK(m.find(path + ":" + std::to_string(line) + ":") == 0);
            CHECK(m.find("/units/1/nuance") != std::string::npos);
            CHECK(m.find("vertical_accent") != std::string::npos);
            CHECK(m.find("staccato") != std::string::npos);
        }
    }
    SECTION("a sample that is not a number")
    {
        std::string bad = text;
        const size_t pos = bad.find("\n[", bad.find("\"tip_m\"") + 100) + 1;
        const size_t end = bad.find(']', pos);
        bad.replace(pos, end - pos + 1, "[0, \"high\", 0]");
        const int line = line_of(bad, "\"high\"");
        const std::string path = dir.file("sample.json");
        write(path, bad);
        CHECK_THROWS_WITH(GestureDatabase::load_json(path),
                          Catch::Contains(path + ":" + std::to_string(line) + ":") &&
                              Catch::Contains("expected a number"));
    }
    SECTION("strike index out of range, unknown grip, missing file, wrong format")
    {
        std::string bad = text;
        const size_t pos = bad.find("\"strike_index\": ");
        bad.replace(pos, bad.find(',', pos) - pos, "\"strike_index\": 100000");
        const std::string path = dir.file("strike.json");
        write(path, bad);
        CHECK_THROWS_WITH(
            GestureDatabase::load_json(path),
            Catch::Contains(path + ":" + std::to_string(line_of(bad, "100000")) + ":") &&
                Catch::Contains("strike_index"));
        bad = text;
        bad.replace(bad.find("\"grip\": \"french\""), 16, "\"grip\": \"russian\"");
        write(path, bad);
        CHECK_THROWS_WITH(
            GestureDatabase::load_json(path),
            Catch::Contains(path + ":" + std::to_string(line_of(bad, "russian")) + ":") &&
                Catch::Contains("russian"));
        CHECK_THROWS_WITH(GestureDatabase::load_json(dir.file("none.json")),
                          Catch::Contains("none.json:0: cannot open"));
        write(path, "{\"units\": []}");
        CHECK_THROWS_WITH(GestureDatabase::load_json(path), Catch::Contains("ictus-gestures"));
    }
}

TEST_CASE("gestures verb: export, list, import, usage errors", "[gesture][cli]")
{
    TempDir dir;
    const std::string exported = dir.file("builtin.json");
    CHECK(run_verb({"--export", exported}) == 0);
    const GestureDatabase db = GestureDatabase::load_json(exported);
    CHECK(db.units().size() == 2 * kNuances * 2);
    CHECK(run_verb({"--list", "--db", exported}) == 0);
    CHECK(run_verb({"--list"}) == 0);

    // Import: a one-stick CSV of three strokes at 0.5 s.
    const std::string csv = dir.file("take.csv");
    {
        std::ofstream out(csv);
        out << "time,left.x,left.y,left.z,right.x,right.y,right.z\n";
        for (int k = 0; k <= 400; ++k) {
            const double t = k / 250.0;
            const double h = 0.2 * std::abs(std::sin(3.14159265358979 * (t - 0.1) / 0.5));
            out << t << ",0.3,0.9,0.5,-0.3," << 0.7 + h << ",0.5\n";
        }
    }
    const std::string out_db = dir.file("mine.json");
    CHECK(run_verb({"--import", csv, "--grip", "german", "--nuance", "vertical-accent", "--hand",
                    "right", "--db", exported, "--out", out_db}) == 0);
    const GestureDatabase mine = GestureDatabase::load_json(out_db);
    CHECK(mine.units().size() == 2 * kNuances * 2);
    const GestureUnit *u = mine.find(Grip::german, Nuance::vertical_accent, Side::right);
    REQUIRE(u != nullptr);
    CHECK(u->source == "take.csv");
    // |sin| arch: impact speed pi * 0.2 / 0.5 m/s.
    CHECK(u->impact_speed_mps() == Approx(3.14159265358979 * 0.2 / 0.5).epsilon(0.02));

    CHECK(run_verb({"--import", csv, "--grip", "german", "--nuance", "loud", "--hand", "right",
                    "--out", out_db}) == 2);
    CHECK(run_verb({"--import", csv, "--grip", "german", "--nuance", "legato", "--out", out_db}) ==
          2);
    CHECK(run_verb({"--list", "--export", exported}) == 2);
    CHECK(run_verb({"--frobnicate"}) == 2);
    CHECK(run_verb({"--list", "--db", dir.file("missing.json")}) == 1);
    CHECK(run_verb({"--import", dir.file("missing.csv"), "--grip", "french", "--nuance", "legato",
                    "--hand", "left", "--out", out_db}) == 1);
    CHECK(run_verb({"--help"}) == 0);
}
