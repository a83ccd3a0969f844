// verbs.hpp -- the verbs of ictusd, each in its own file (verb_*.cpp). Every
// verb takes the arguments after its name and returns the exit status
// (args.hpp); the option groups they share are in options.hpp.
#pragma once

#include "ictus/cli/args.hpp"
#include "ictus/cli/options.hpp"

namespace ictus
{
namespace cli
{

int cmd_track(Args &args);    // verb_track.cpp
int cmd_limits(Args &args);   // verb_limits.cpp
int cmd_run(Args &args);      // verb_run.cpp
int cmd_render(Args &args);   // verb_render.cpp
int cmd_gestures(Args &args); // verb_gestures.cpp

// render --out DIR (out_dir.cpp): DIR is created, or else must be empty, so
// that no file of an earlier render passes for this one's; with `force` a used
// folder is taken and render's own files in it are removed, no other.
void prepare_render_out_dir(const std::string &dir, bool force);

// run --out DIR (out_dir.cpp, beside render's rule): DIR is created; a
// folder holding a file render writes other than strikes.csv (a render's
// folder) is refused, std::runtime_error naming it, so that no render's
// events.txt or render.json passes for this run's; with `force` those files
// are removed first. Another file, an earlier run's strikes.csv, stays.
void prepare_run_out_dir(const std::string &dir, bool force);

} // namespace cli
} // namespace ictus
