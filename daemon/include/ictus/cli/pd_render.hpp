// `ictusd render --wav FILE`: the render's events.txt played by Pd in batch
// mode on the same drum (patches/ictus-render.pd, docs/pd-osc.md), as
// scripts/main.sh does it. Pd is a separate program: found on PATH (or
// given), run as a child process, its output kept in a log.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace ictus
{
namespace cli
{

struct PdRenderOptions {
    std::string pd = "pd";   // the binary: a name looked up on PATH, or a path
    std::string library;     // folder with the externals and ictus-render.pd ("": found)
    std::string events;      // absolute path of events.txt
    std::string wav;         // absolute path of the WAV to write
    std::string log;         // where Pd's output goes (pd.log)
    double seconds = 10.0;   // length of the WAV
    double radius_m = 0.178; // the drum: render-drum radius / tension / density
    double tension_n_per_m = 3000.0;
    double density_kg_per_m2 = 0.26;
    std::string preset; // render-drum preset NAME first, when not empty (membrane~)
    // A kit's drums after the first (drum 0 is the drum above): each played
    // by its own ictus-kit-drum N (N = 1, 2 ...), configured by render-kit-N
    // messages: preset, radius, tension, pan (+: the left channel), dsp 1.
    struct KitDrumSound {
        std::string preset;
        double radius_m = 0.178;
        double tension_n_per_m = 3000.0;
        double pan = 0.0;
        // A foot's piece (the kick): its beater's tip on the contact~ the
        // foot plays (ictus-drum plays hand 2 on the right one); "": none.
        std::string foot_tip;
    };
    std::vector<KitDrumSound> kit;
    std::string stick_tip; // render-drum left|right tip NAME, when not empty (contact~)
    // The head's stretching k3 (N/m^3, DrumParams::stretch_n_per_m3): render-drum
    // left|right stretch K3, so that contact~ has the physics' head; <= 0: contact~'s own.
    double stretch_n_per_m3 = 0.0;
    int sample_rate = 48000;
    std::string mix = "stereo"; // render-mix
    int bits = 32;              // render-bits
    double gain_db = 0.0;       // render-gain
};

// What Pd reported at the end (ictus-render's report line), and its error lines.
struct PdRenderResult {
    double peak_in_dbfs = 0.0;
    double peak_out_dbfs = 0.0;
    std::string errors; // Pd's error lines, one a line ("" when none)
    double wall_s = 0.0;
    bool interrupted = false; // stopped by SIGINT, SIGTERM or SIGHUP: no WAV left
};

// The Pd library folder: `given` if not empty (checked), else the first of
// <ictusd's folder>/ictus (a build tree) and <ictusd's folder>/../lib/pd-externals/ictus
// (cmake --install) that holds ictus-render.pd. std::runtime_error naming
// what was looked for.
std::string find_pd_library(const std::string &given);

// Pd parses a -send message into atoms: a path with a space, a comma, a
// semicolon, a dollar, a backslash or a brace would arrive cut or changed.
// std::runtime_error "WHAT: 'path' has ...".
void check_pd_path(const char *what, const std::string &path);

// --wav's path: a file name ending in .wav or .WAV (or .wave, .WAVE: the names Pd
// writes as given; none of render's other outputs ends so), not a folder, in a folder that exists
// or is `made_dir` (render's --out, made before Pd runs: Pd makes no folder), and one Pd's messages
// carry (check_pd_path). std::runtime_error naming the path.
void check_wav_path(const std::string &path, const std::string &made_dir = "");

// The path of `pd` (a name is looked up on PATH); std::runtime_error when
// there is none, saying how to get it.
std::string find_pd_binary(const std::string &pd);

// Runs Pd; `progress` is called about every 2 s of wall time while it runs
// (elapsed seconds). Throws std::runtime_error when Pd cannot start, exits
// with an error, times out, or writes no WAV. Interrupted (SIGINT, SIGTERM,
// SIGHUP: g_interrupted), Pd is stopped, the cut WAV removed, and the result
// says `interrupted`. Pd is a child that ends with ictusd (PR_SET_PDEATHSIG).
PdRenderResult run_pd_render(const PdRenderOptions &o, const std::function<void(double)> &progress);

} // namespace cli
} // namespace ictus
