// Helpers for the sim tests: a hand-made skeleton with the CMU joint names (round
// numbers, not the captured ones), BVH text for it, and the data folder.
#pragma once

#include "ictus/mocap/motion.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

namespace simtest
{

constexpr double kCmuScale = 0.056444;

struct Row {
    const char *name;
    const char *parent; // "" for the root
    double x, y, z;     // OFFSET in BVH units
    bool end_site;
};

// CMU hierarchy and joint names, offsets rounded by hand.
inline const std::vector<Row> &cmu_like_rows()
{
    static const std::vector<Row> rows = {
        {"Hips", "", 0, 0, 0, false},
        {"LHipJoint", "Hips", 0, 0, 0, false},
        {"LeftUpLeg", "LHipJoint", 1.8, -1.7, 0.7, false},
        {"LeftLeg", "LeftUpLeg", 2.3, -6.2, 0, false},
        {"LeftFoot", "LeftLeg", 2.6, -7.0, 0, false},
        {"LeftToeBase", "LeftFoot", 0.2, -0.6, 1.7, false},
        {"LeftToeBase_end", "LeftToeBase", 0, 0, 0.9, true},
        {"RHipJoint", "Hips", 0, 0, 0, false},
        {"RightUpLeg", "RHipJoint", -1.8, -1.7, 0.7, false},
        {"RightLeg", "RightUpLeg", -2.3, -6.2, 0, false},
        {"RightFoot", "RightLeg", -2.6, -7.0, 0, false},
        {"RightToeBase", "RightFoot", -0.2, -0.6, 1.7, false},
        {"RightToeBase_end", "RightToeBase", 0, 0, 0.9, true},
        {"LowerBack", "Hips", 0, 0, 0, false},
        {"Spine", "LowerBack", 0, 1.7, -0.2, false},
        {"Spine1", "Spine", 0, 1.7, 0.2, false},
        {"Neck", "Spine1", 0, 0, 0, false},
        {"Neck1", "Neck", 0, 1.65, 0.1, false},
        {"Head", "Neck1", 0, 1.6, -0.3, false},
        {"Head_end", "Head", 0, 1.7, -0.1, true},
        {"LeftShoulder", "Spine1", 0, 0, 0, false},
        {"LeftArm", "LeftShoulder", 3.1, 1.4, 0.3, false},
        {"LeftForeArm", "LeftArm", 5.1, 0, 0, false},
        {"LeftHand", "LeftForeArm", 3.6, 0, 0, false},
        {"LeftFingerBase", "LeftHand", 0, 0, 0, false},
        {"LeftHandIndex1", "LeftFingerBase", 0.6, 0, 0, false},
        {"LeftHandIndex1_end", "LeftHandIndex1", 0.5, 0, 0, true},
        {"LThumb", "LeftHand", 0, 0, 0, false},
        {"LThumb_end", "LThumb", 0.5, 0, 0.5, true},
        {"RightShoulder", "Spine1", 0, 0, 0, false},
        {"RightArm", "RightShoulder", -3.1, 1.4, 0.3, false},
        {"RightForeArm", "RightArm", -5.1, 0, 0, false},
        {"RightHand", "RightForeArm", -3.6, 0, 0, false},
        {"RightFingerBase", "RightHand", 0, 0, 0, false},
        {"RightHandIndex1", "RightFingerBase", -0.6, 0, 0, false},
        {"RightHandIndex1_end", "RightHandIndex1", -0.5, 0, 0, true},
        {"RThumb", "RightHand", 0, 0, 0, false},
        {"RThumb_end", "RThumb", -0.5, 0, 0.5, true},
    };
    return rows;
}

inline ictus::Skeleton cmu_like_skeleton(double scale = kCmuScale)
{
    ictus::Skeleton s;
    for (const Row &r : cmu_like_rows()) {
        ictus::SkeletonJoint j;
        j.name = r.name;
        j.parent = r.parent[0] ? s.find(r.parent) : -1;
        j.offset_m = Eigen::Vector3d(r.x, r.y, r.z) * scale;
        j.end_site = r.end_site;
        s.joints.push_back(j);
    }
    return s;
}

// A motion of the hand-made skeleton: all rotations from `rotation(frame, joint)`.
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

// BVH text of the hand-made skeleton; `zyx_deg(frame, joint)` gives each
// joint's Z, Y, X rotation channels in degrees.
inline std::string
cmu_like_bvh(int frames, double frame_time_s,
             const std::function<Eigen::Vector3d(int, const std::string &)> &zyx_deg)
{
    const auto &rows = cmu_like_rows();
    std::ostringstream out;
    std::vector<std::string> order;
    std::function<void(const std::string &, int)> write = [&](const std::string &name, int depth) {
        const std::string ind(depth, '\t');
        const Row *row = nullptr;
        for (const Row &r : rows)
            if (name == r.name)
                row = &r;
        if (row->end_site) {
            out << ind << "End Site\n"
                << ind << "{\n"
                << ind << "\tOFFSET " << row->x << " " << row->y << " " << row->z << "\n"
                << ind << "}\n";
            return;
        }
        out << ind << (depth == 0 ? "ROOT " : "JOINT ") << name << "\n" << ind << "{\n";
        out << ind << "\tOFFSET " << row->x << " " << row->y << " " << row->z << "\n";
        if (depth == 0)
            out << ind
                << "\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n";
        else
            out << ind << "\tCHANNELS 3 Zrotation Yrotation Xrotation\n";
        order.push_back(name);
        for (const Row &r : rows)
            if (name == r.parent)
                write(r.name, depth + 1);
        out << ind << "}\n";
    };
    out << "HIERARCHY\n";
    write("Hips", 0);
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
