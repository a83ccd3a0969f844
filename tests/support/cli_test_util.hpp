// The real ictusd binary run as a user runs it, for the cli tests: its exit
// status and output, and a small valid capture to give it.
#pragma once

#include "support/sim_test_util.hpp"

#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace clitest
{

struct Run {
    int status;
    std::string output; // stdout and stderr
};

inline Run ictusd(const std::string &args)
{
    const std::string cmd = std::string(ICTUSD_PATH) + " " + args + " 2>&1";
    FILE *pipe = popen(cmd.c_str(), "r");
    REQUIRE(pipe != nullptr);
    std::string out;
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, pipe)) > 0)
        out.append(buf, n);
    const int st = pclose(pipe);
    return {WIFEXITED(st) ? WEXITSTATUS(st) : -1, out};
}

// A small valid BVH with the CMU joint names: the right elbow swings.
inline std::string tiny_bvh()
{
    static const std::string path = simtest::write_temp(
        "tiny.bvh", simtest::default_skeleton_bvh(121, 1.0 / 120, [](int f, const std::string &j) {
            if (j == "RightForeArm")
                return Eigen::Vector3d(0, 20.0 * std::sin(2 * M_PI * f / 120.0), 0);
            return Eigen::Vector3d(0, 0, 0);
        }));
    return path;
}

} // namespace clitest
