// The --out folders of render and run (verbs.hpp).
#include "ictus/cli/verbs.hpp"

#include <algorithm>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictus
{
namespace cli
{
namespace
{

// The files render writes into --out, all it may remove (--force);
// performance.wav is --wav's name in README and scripts/main.sh.
const char *const kRenderOutputs[] = {"strikes.csv",     "events.txt", "render.json",
                                      "tips.csv",        "notes.csv",  "performance.bvh",
                                      "performance.mid", "pd.log",     "performance.wav"};

} // namespace

// --out: created, or else empty, so that no file of an earlier render (a
// score's notes.csv beside a clip's strikes) passes for this one's. With
// --force a used folder is taken: render's own files in it are removed, no
// other.
void prepare_render_out_dir(const std::string &dir, bool force)
{
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec)
        throw std::runtime_error("--out: cannot create '" + dir + "': " + ec.message());
    std::vector<std::string> found;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
        found.push_back(it->path().filename().string());
    if (ec)
        throw std::runtime_error("--out: cannot read '" + dir + "': " + ec.message());
    if (found.empty())
        return;
    if (!force) {
        std::sort(found.begin(), found.end());
        std::string shown;
        for (size_t i = 0; i < found.size() && i < 3; ++i)
            shown += (i ? ", " : "") + found[i];
        if (found.size() > 3)
            shown += ", ...";
        throw std::runtime_error("--out: '" + dir + "' is not empty (" + shown +
                                 "): give a new or empty folder, or --force to replace "
                                 "render's own files in it");
    }
    for (const char *name : kRenderOutputs) {
        fs::remove(fs::path(dir) / name, ec); // a symbolic link itself, never its target
        if (ec)
            throw std::runtime_error("--out: cannot remove '" + (fs::path(dir) / name).string() +
                                     "': " + ec.message());
    }
}

void prepare_run_out_dir(const std::string &dir, bool force)
{
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec)
        throw std::runtime_error("--out: cannot create '" + dir + "': " + ec.message());
    for (const char *name : kRenderOutputs) {
        const fs::path p = fs::path(dir) / name;
        if (std::string(name) == "strikes.csv" || !fs::exists(fs::symlink_status(p, ec)))
            continue;
        if (!force)
            throw std::runtime_error("--out: '" + dir + "' holds a render's " + name +
                                     ": give a new folder, or --force to remove render's own "
                                     "files in it");
        fs::remove(p, ec);
        if (ec)
            throw std::runtime_error("--out: cannot remove '" + p.string() + "': " + ec.message());
    }
}

} // namespace cli
} // namespace ictus
