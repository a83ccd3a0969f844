// fuzz_gestures.cpp -- libFuzzer harness of the gesture database reader
// (gesture/gesture.hpp, GestureDatabase::parse_json: what `--gestures DB.json`
// and `ictusd gestures --list --db` read).
//
// A refusal (GestureError) is a pass when it names the file and a line of the
// text ("fuzz.json:LINE: ..."). An accepted database must keep the reader's
// promises: each unit at least 2 finite samples, its strike on one of them,
// stick directions absent or one per sample, rate in (0, 100000] Hz, dynamics
// in [0, 1]; and each unit must play: sample(), velocity() and
// impact_speed_mps() finite, and instantiate() at three dynamics finite. A
// crash, a sanitizer report or a run over the -timeout is a finding. See
// docs/fuzzing.md.
#include "fuzz_check.hpp"

#include "ictus/gesture/gesture.hpp"

#include <algorithm>
#include <cstdlib>

using namespace ictus;

namespace
{

constexpr std::size_t kMaxInputBytes = 64 * 1024;

// "fuzz.json:LINE: ...", LINE within the text's lines (0: the whole file).
bool names_a_line(const std::string &message, const std::string &text)
{
    const std::string prefix = "fuzz.json:";
    if (message.compare(0, prefix.size(), prefix) != 0)
        return false;
    char *end = nullptr;
    const long line = std::strtol(message.c_str() + prefix.size(), &end, 10);
    const long lines = 1 + static_cast<long>(std::count(text.begin(), text.end(), '\n'));
    return end && *end == ':' && line >= 0 && line <= lines;
}

void check_unit(const GestureDatabase &db, const GestureUnit &u)
{
    const int n = u.samples();
    ICTUS_FUZZ_CHECK(n >= 2, "a unit with fewer than 2 samples");
    ICTUS_FUZZ_CHECK(u.strike_index >= 0 && u.strike_index < n, "strike index off the samples");
    ICTUS_FUZZ_CHECK(u.stick_dir.empty() || static_cast<int>(u.stick_dir.size()) == n,
                     "stick directions not one per sample");
    ICTUS_FUZZ_CHECK(u.rate_hz > 0.0 && u.rate_hz <= 100000.0, "rate out of (0, 100000] Hz");
    ICTUS_FUZZ_CHECK(u.dynamics >= 0.0 && u.dynamics <= 1.0, "dynamics out of [0, 1]");
    for (const Eigen::Vector3d &p : u.tip_m)
        ICTUS_FUZZ_CHECK(ictus_fuzz::finite(p), "a sample not finite");
    // Samples up to 1e308 are accepted; their interpolant may overflow, so
    // finiteness is asked of it only within a physical range.
    bool physical = true;
    for (const Eigen::Vector3d &p : u.tip_m)
        physical = physical && p.cwiseAbs().maxCoeff() < 1e3;
    if (!physical)
        return;
    const double d = u.duration_s();
    for (double t : {0.0, 0.37 * d, u.strike_time_s(), d}) {
        ICTUS_FUZZ_CHECK(ictus_fuzz::finite(u.sample(t)), "sample() not finite");
        ICTUS_FUZZ_CHECK(ictus_fuzz::finite(u.velocity(t)), "velocity() not finite");
    }
    ICTUS_FUZZ_CHECK(std::isfinite(u.impact_speed_mps()), "impact speed not finite");
    for (double dyn : {0.0, 0.5, 1.0}) {
        const GestureUnit v = db.instantiate(u.grip, u.nuance, u.hand, dyn);
        for (const Eigen::Vector3d &p : v.tip_m)
            ICTUS_FUZZ_CHECK(ictus_fuzz::finite(p), "an instantiated sample not finite");
    }
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size)
{
    if (size > kMaxInputBytes)
        return -1; // not kept in the corpus
    const std::string text = ictus_fuzz::text_of(data, size);
    GestureDatabase db;
    try {
        db = GestureDatabase::parse_json(text, "fuzz.json");
    } catch (const GestureError &e) {
        ICTUS_FUZZ_CHECK(names_a_line(e.what(), text), "an error without the file and a line");
        return 0;
    }
    for (const GestureUnit &u : db.units())
        check_unit(db, u);
    return 0;
}
