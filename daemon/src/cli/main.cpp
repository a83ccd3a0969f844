// ictusd -- the ictus simulation daemon: a physically simulated percussionist.
// Verbs: track (tracking of a mocap clip, paper eq. 1 and Algorithm 2),
// limits (joint limits learned from a clip, Algorithm 1), run and render (the
// performance, docs/osc.md and docs/perform.md), gestures (the gesture
// database, docs/gestures.md). Each verb is in its own verb_*.cpp; the exit
// status is args.hpp's.
#include "ictus/cli/args.hpp"
#include "ictus/cli/verbs.hpp"

#include <iostream>
#include <string>

namespace
{

void usage(std::ostream &out)
{
    out << "ictusd -- the ictus simulation daemon (a physically simulated percussionist)\n"
           "\n"
           "usage: ictusd VERB [options]\n"
           "       ictusd --help | --version | VERB --help | VERB --version\n"
           "\n"
           "verbs:\n"
           "  track    drive the character with a motion capture, in joint space (PD, eq. 1)\n"
           "           or Cartesian space (IK, Algorithm 2), and report errors and speed\n"
           "  limits   learn joint limits from a motion capture (Euler statistics and\n"
           "           Algorithm 1), print them and write them as JSON\n"
           "  run      perform in real time: physics on the wall clock, strikes and poses\n"
           "           out over OSC, control in over OSC (docs/osc.md)\n"
           "  render   perform offline, as fast as possible and deterministic: strikes.csv\n"
           "           and an events file for Pd's batch render (docs/osc.md)\n"
           "  gestures the gesture database: list, export, or import units segmented\n"
           "           from a capture (ictusd gestures --help)\n"
           "\n"
           "examples:\n"
           "  ictusd track --mode joint --mocap ../shared/data/cmu/80_13.bvh --out run1\n"
           "  ictusd track --mode joint --mocap clip.bvh --duration 600 --grip german --quiet\n"
           "  ictusd limits ../shared/data/cmu/80_13.bvh --out limits.json\n"
           "  ictusd render --mocap ../shared/data/cmu/80_13.bvh --out perf\n"
           "  ictusd run --mocap ../shared/data/cmu/80_13.bvh --target osc.udp://127.0.0.1:9000\n"
           "  ictusd gestures --list\n"
           "\n"
           "an option's value that is a word (--mode joint, --kit full) is taken in any\n"
           "case, as the score's words are\n"
           "\n"
           "exit status: 0 ok, 1 error in a file or the data, 2 usage error,\n"
           "             3 the simulation diverged (and was reset), 130 interrupted\n";
}

// The project's version (CMake's project(VERSION)), as "ictusd 0.1.0".
void version(std::ostream &out)
{
    out << "ictusd " << ICTUS_VERSION << "\n";
}

bool is_verb(const std::string &word)
{
    return word == "track" || word == "limits" || word == "run" || word == "render" ||
           word == "gestures";
}

} // namespace

int main(int argc, char **argv)
{
    using namespace ictus::cli;
    if (argc < 2) {
        usage(std::cerr);
        return 2;
    }
    const std::string verb = argv[1];
    if (verb == "--help" || verb == "-h" || verb == "help") {
        usage(std::cout);
        return 0;
    }
    // `ictusd --version`, and `ictusd VERB --version` alone (elsewhere on a
    // verb's line it is that verb's unknown option).
    if (verb == "--version" ||
        (argc == 3 && is_verb(verb) && std::string(argv[2]) == "--version")) {
        version(std::cout);
        return 0;
    }
    install_signal_handlers();
    Args args(argc - 1, argv + 1); // the arguments after the verb
    if (verb == "track")
        return run_verb("track", [&] { return cmd_track(args); });
    if (verb == "limits")
        return run_verb("limits", [&] { return cmd_limits(args); });
    if (verb == "run")
        return run_verb("run", [&] { return cmd_run(args); });
    if (verb == "render")
        return run_verb("render", [&] { return cmd_render(args); });
    if (verb == "gestures")
        return run_verb("gestures", [&] { return cmd_gestures(args); });
    std::cerr << "ictusd: unknown verb '" << verb
              << "' (verbs: track, limits, run, render, gestures; see ictusd --help)\n";
    return 2;
}
