// Helpers for the tests of the daemon's areas: the default skeleton at any scale,
// motions and BVH text of a skeleton, temporary files, and the data folder.
#pragma once

#include "ictus/character/default_skeleton.hpp"
#include "ictus/mocap/bvh.hpp"
#include "ictus/mocap/motion.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace simtest
{

// The default skeleton (character/default_skeleton.hpp) with `scale` metres per
// CMU BVH unit instead of kCmuBvhScale_m.
inline ictus::Skeleton default_skeleton_at_scale(double scale)
{
    ictus::Skeleton s = ictus::default_skeleton();
    for (ictus::SkeletonJoint &j : s.joints)
        j.offset_m *= scale / ictus::kCmuBvhScale_m;
    return s;
}

// A motion of a skeleton: all rotations from `rotation(frame, joint)`.
inline ictus::Motion
make_motion(const ictus::Skeleton &s, int frames, double rate_hz,
            const std::function<Eigen::Quaterniond(int frame, const std::string &joint)> &rotation)
{
    ictus::Motion m;
    m.frame_rate_hz = rate_hz;
    for (int f = 0; f < frames; ++f) {
        m.root_position_m.push_back(Eigen::Vector3d(0, 1.0, 0));
        std::vector<Eigen::Quaterniond> q;
        for (const auto &j : s.joints)
            q.push_back(j.end_site ? Eigen::Quaterniond::Identity() : rotation(f, j.name));
        m.local_rotation.push_back(q);
    }
    return m;
}

// A slow swing of the right arm: elbow and shoulder 20 degrees at 1 Hz, 2 s
// at 120 Hz (241 frames), every other joint at rest.
inline ictus::Motion right_arm_swing(const ictus::Skeleton &s)
{
    return make_motion(s, 241, 120.0, [](int f, const std::string &j) {
        const double a = 20.0 * M_PI / 180 * std::sin(2 * M_PI * f / 120.0);
        if (j == "RightForeArm")
            return Eigen::Quaterniond(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()));
        if (j == "RightArm")
            return Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * a, Eigen::Vector3d::UnitZ()));
        return Eigen::Quaterniond::Identity();
    });
}

// BVH text of the default skeleton (its offsets in CMU BVH units);
// `zyx_deg(frame, joint)` gives each joint's Z, Y, X rotation channels in degrees.
inline std::string
default_skeleton_bvh(int frames, double frame_time_s,
                     const std::function<Eigen::Vector3d(int, const std::string &)> &zyx_deg)
{
    const ictus::Skeleton skel = ictus::default_skeleton();
    std::ostringstream out;
    std::vector<std::string> order;
    std::function<void(int, int)> write = [&](int index, int depth) {
        const ictus::SkeletonJoint &joint = skel.joints[index];
        const Eigen::Vector3d offset = joint.offset_m / ictus::kCmuBvhScale_m;
        const std::string ind(depth, '\t');
        if (joint.end_site) {
            out << ind << "End Site\n"
                << ind << "{\n"
                << ind << "\tOFFSET " << offset.x() << " " << offset.y() << " " << offset.z()
                << "\n"
                << ind << "}\n";
            return;
        }
        out << ind << (depth == 0 ? "ROOT " : "JOINT ") << joint.name << "\n" << ind << "{\n";
        out << ind << "\tOFFSET " << offset.x() << " " << offset.y() << " " << offset.z() << "\n";
        if (depth == 0)
            out << ind
                << "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n";
        else
            out << ind << "\tCHANNELS 3 Zrotation Yrotation Xrotation\n";
        order.push_back(joint.name);
        for (int child = 0; child < static_cast<int>(skel.joints.size()); ++child)
            if (skel.joints[child].parent == index)
                write(child, depth + 1);
        out << ind << "}\n";
    };
    out << "HIERARCHY\n";
    write(0, 0);
    out << "MOTION\nFrames: " << frames << "\nFrame Time: " << frame_time_s << "\n";
    for (int f = 0; f < frames; ++f) {
        out << "0 17.5 0";
        for (const std::string &name : order) {
            const Eigen::Vector3d a = zyx_deg(f, name);
            out << " " << a.x() << " " << a.y() << " " << a.z();
        }
        out << "\n";
    }
    return out.str();
}

// A path in the system's temporary folder, unique to this process (CTest runs
// test cases as parallel processes).
// Removed when the process exits.
inline std::string temp_path(const std::string &name)
{
    struct Registry {
        std::vector<std::string> paths;
        ~Registry()
        {
            std::error_code ec;
            for (const std::string &p : paths)
                std::filesystem::remove_all(p, ec);
        }
    };
    static Registry registry;
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("ictus_test_sim_" + std::to_string(::getpid()) + "_" + name))
                                 .string();
    registry.paths.push_back(path);
    return path;
}

inline std::string write_temp(const std::string &name, const std::string &text)
{
    const std::string path = temp_path(name);
    std::ofstream(path) << text;
    return path;
}

// The data folder; empty when absent (the caller skips, or fails under CI=true).
inline std::string data_file(const std::string &relative)
{
    const char *env = std::getenv("ICTUS_DATA_DIR");
    const std::string dir = env && *env ? env : ICTUS_DATA_DIR_DEFAULT;
    const std::string path = dir + "/" + relative;
    if (std::ifstream(path).good())
        return path;
    const char *ci = std::getenv("CI");
    if (ci && std::string(ci) == "true")
        FAIL("data file missing under CI: " << path << " (set ICTUS_DATA_DIR)");
    WARN("SKIPPED: data file " << path << " not found (set ICTUS_DATA_DIR)");
    return "";
}

} // namespace simtest
