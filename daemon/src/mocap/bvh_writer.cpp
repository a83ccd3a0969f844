// bvh_writer.cpp -- BVH export: a skeleton and its motion as a Biovision
// Hierarchy file that read_bvh (bvh.cpp) reads back to the same joint frames.
// Used to export the simulated performance for 3D tools without Gem.
#include "ictus/mocap/bvh.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <ostream>
#include <string>
#include <vector>

namespace ictus
{

namespace
{

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

const char *const kRotationChannel[3] = {"Xrotation", "Yrotation", "Zrotation"};

bool is_permutation(const std::array<int, 3> &order)
{
    bool seen[3] = {false, false, false};
    for (int axis : order) {
        if (axis < 0 || axis > 2 || seen[axis])
            return false;
        seen[axis] = true;
    }
    return true;
}

bool finite(const Eigen::Vector3d &v)
{
    return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}

bool finite(const Eigen::Quaterniond &q)
{
    return std::isfinite(q.w()) && std::isfinite(q.x()) && std::isfinite(q.y()) &&
           std::isfinite(q.z()) && q.norm() > 1e-12;
}

// Fixed decimals; "-0.000" is printed as "0.000" so that equal motions give equal bytes.
void put_number(std::string &line, double value, int decimals)
{
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.*f", decimals, value);
    std::string text = buffer;
    if (text[0] == '-' && text.find_first_not_of("-0.") == std::string::npos)
        text.erase(0, 1);
    line += text;
}

class Writer
{
  public:
    Writer(std::ostream &out, const Skeleton &skeleton, const Motion &motion,
           const BvhWriteOptions &options, const std::string &source)
        : out_(out), skeleton_(skeleton), motion_(motion), options_(options), source_(source)
    {
    }

    void write()
    {
        check();
        out_ << "HIERARCHY\n";
        write_joint(0, 0);
        out_ << "MOTION\n";
        out_ << "Frames: " << motion_.frames() << "\n";
        std::string line = "Frame Time: ";
        // Enough decimals for read_bvh to recover an integer rate exactly (it
        // snaps a frame time that matches an integer rate to its last digit).
        put_number(line, 1.0 / motion_.frame_rate_hz, 10);
        out_ << line << "\n";
        for (int f = 0; f < motion_.frames(); ++f)
            write_frame(f);
        if (!out_)
            fail(0, "write failed");
    }

  private:
    [[noreturn]] void fail(int line, const std::string &message) const
    {
        throw MocapError(source_, line, "BVH export: " + message);
    }

    void check()
    {
        const int n = static_cast<int>(skeleton_.joints.size());
        if (!(std::isfinite(options_.units_per_m) && options_.units_per_m > 0.0))
            fail(0,
                 "units_per_m must be finite and > 0, got " + std::to_string(options_.units_per_m));
        if (!is_permutation(options_.rotation_order))
            fail(0, "rotation_order must be a permutation of 0 1 2 (X Y Z)");
        if (options_.decimals < 1 || options_.decimals > 17)
            fail(0, "decimals must be in [1, 17], got " + std::to_string(options_.decimals));
        if (n == 0)
            fail(0, "the skeleton has no joints");
        if (skeleton_.joints[0].parent != -1)
            fail(0, "joint 0 (" + skeleton_.joints[0].name + ") must be the root (parent -1)");
        if (skeleton_.joints[0].end_site)
            fail(0, "the root cannot be an end site");
        children_.assign(static_cast<std::size_t>(n), {});
        for (int j = 1; j < n; ++j) {
            const SkeletonJoint &joint = skeleton_.joints[static_cast<std::size_t>(j)];
            if (joint.parent < 0 || joint.parent >= n || joint.parent == j)
                fail(0, "joint " + std::to_string(j) + " (" + joint.name + ") has parent " +
                            std::to_string(joint.parent) + ": one root only, parents in range");
            if (skeleton_.joints[static_cast<std::size_t>(joint.parent)].end_site)
                fail(0, "end site " +
                            skeleton_.joints[static_cast<std::size_t>(joint.parent)].name +
                            " has a child (" + joint.name + ")");
            if (!joint.end_site && joint.name.empty())
                fail(0, "joint " + std::to_string(j) + " has no name");
            children_[static_cast<std::size_t>(joint.parent)].push_back(j);
        }
        for (const SkeletonJoint &joint : skeleton_.joints)
            if (!finite(joint.offset_m))
                fail(0, "joint " + joint.name + ": OFFSET is not finite");
        // Every joint reached from the root exactly once (no cycles).
        std::vector<int> stack{0};
        int reached = 0;
        while (!stack.empty()) {
            const int j = stack.back();
            stack.pop_back();
            if (++reached > n)
                break;
            for (int c : children_[static_cast<std::size_t>(j)])
                stack.push_back(c);
        }
        if (reached != n)
            fail(0, "the skeleton's parents form a cycle or leave joints unreachable");

        if (!(std::isfinite(motion_.frame_rate_hz) && motion_.frame_rate_hz > 0.0))
            fail(0,
                 "frame rate must be finite and > 0, got " + std::to_string(motion_.frame_rate_hz));
        if (motion_.local_rotation.size() != motion_.root_position_m.size())
            fail(0, "the motion has " + std::to_string(motion_.root_position_m.size()) +
                        " root positions but " + std::to_string(motion_.local_rotation.size()) +
                        " frames of rotations");
        for (int f = 0; f < motion_.frames(); ++f) {
            const auto &rotations = motion_.local_rotation[static_cast<std::size_t>(f)];
            if (static_cast<int>(rotations.size()) != n)
                fail(0, "frame " + std::to_string(f) + " has " + std::to_string(rotations.size()) +
                            " rotations for " + std::to_string(n) + " joints");
            if (!finite(motion_.root_position_m[static_cast<std::size_t>(f)]))
                fail(0, "frame " + std::to_string(f) + ": root position is not finite");
            for (int j = 0; j < n; ++j)
                if (!finite(rotations[static_cast<std::size_t>(j)]))
                    fail(0, "frame " + std::to_string(f) + ", joint " +
                                skeleton_.joints[static_cast<std::size_t>(j)].name +
                                ": rotation is not finite or zero");
        }
    }

    void write_joint(int j, int depth)
    {
        const SkeletonJoint &joint = skeleton_.joints[static_cast<std::size_t>(j)];
        const std::string indent(static_cast<std::size_t>(depth), '\t');
        if (joint.end_site)
            out_ << indent << "End Site\n";
        else
            out_ << indent << (j == 0 ? "ROOT " : "JOINT ") << joint.name << "\n";
        out_ << indent << "{\n";
        std::string line = indent + "\tOFFSET";
        for (int k = 0; k < 3; ++k) {
            line += ' ';
            put_number(line, joint.offset_m[k] * options_.units_per_m, options_.decimals);
        }
        out_ << line << "\n";
        if (!joint.end_site) {
            out_ << indent << "\tCHANNELS " << (j == 0 ? 6 : 3);
            if (j == 0)
                out_ << " Xposition Yposition Zposition";
            for (int axis : options_.rotation_order)
                out_ << ' ' << kRotationChannel[axis];
            out_ << "\n";
            order_.push_back(j);
        }
        for (int c : children_[static_cast<std::size_t>(j)])
            write_joint(c, depth + 1);
        out_ << indent << "}\n";
    }

    void write_frame(int f)
    {
        std::string line;
        const Eigen::Vector3d moved =
            motion_.root_position_m[static_cast<std::size_t>(f)] - skeleton_.joints[0].offset_m;
        for (int k = 0; k < 3; ++k) {
            put_number(line, moved[k] * options_.units_per_m, options_.decimals);
            line += ' ';
        }
        const auto &rotations = motion_.local_rotation[static_cast<std::size_t>(f)];
        for (std::size_t i = 0; i < order_.size(); ++i) {
            const Eigen::Vector3d angles =
                euler_angles(rotations[static_cast<std::size_t>(order_[i])].normalized(),
                             options_.rotation_order);
            for (int k = 0; k < 3; ++k) {
                put_number(line, angles[k] * kRadToDeg, options_.decimals);
                if (i + 1 < order_.size() || k < 2)
                    line += ' ';
            }
        }
        out_ << line << "\n";
    }

    std::ostream &out_;
    const Skeleton &skeleton_;
    const Motion &motion_;
    const BvhWriteOptions &options_;
    const std::string &source_;
    std::vector<std::vector<int>> children_;
    std::vector<int> order_; // channelled joints in file order
};

} // namespace

void write_bvh(std::ostream &out, const Skeleton &skeleton, const Motion &motion,
               const BvhWriteOptions &options, const std::string &source_name)
{
    Writer(out, skeleton, motion, options, source_name).write();
}

void write_bvh(const std::string &path, const Skeleton &skeleton, const Motion &motion,
               const BvhWriteOptions &options)
{
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out)
        throw MocapError(path, 0, "cannot open for writing");
    write_bvh(out, skeleton, motion, options, path);
    out.close();
    if (!out)
        throw MocapError(path, 0, "write failed (disk full?)");
}

} // namespace ictus
