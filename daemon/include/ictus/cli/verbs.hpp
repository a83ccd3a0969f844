// verbs.hpp -- the verbs of ictusd, each in its own file (verb_*.cpp), and
// the option groups two verbs share. Every verb takes the arguments after its
// name and returns the exit status (args.hpp).
#pragma once

#include "ictus/character/character.hpp"
#include "ictus/cli/args.hpp"
#include "ictus/mocap/bvh.hpp"
#include "ictus/perform/performance.hpp"

#include <string>

namespace ictus
{
namespace cli
{

int cmd_track(Args &args);    // verb_track.cpp
int cmd_limits(Args &args);   // verb_limits.cpp
int cmd_run(Args &args);      // verb_run.cpp
int cmd_render(Args &args);   // verb_render.cpp
int cmd_gestures(Args &args); // verb_gestures.cpp

// track and limits: how a BVH clip is read and its reference motion cleaned.
struct ClipOptions {
    double scale = kCmuBvhScale_m;
    int skip = 1;
    ReferenceFilter filter;
};
// When `option` is one of the clip options, reads its value into `clip` and
// returns true; false otherwise (nothing consumed). verb_limits.cpp.
bool parse_clip_option(const std::string &option, Args &args, ClipOptions &clip);
// A limit's minimum half-width per axis, degrees (track --limit-min-deg, limits --min-deg).
double parse_min_half_width_deg(const std::string &option, const std::string &text);
// A BVH file, its warnings printed to stderr.
BvhFile load_bvh(const std::string &path, double scale, int skip);

// run and render: the motion source, the character, the drum, score mode.
// Returns false when `option` is not one of them. verb_render.cpp.
bool parse_performance_option(const std::string &option, Args &args, PerformanceOptions &o,
                              double &duration_s);

} // namespace cli
} // namespace ictus
