// mocap_test_util.hpp -- helpers shared by the mocap tests: temp files, the
// data folder, and rotation matrices written out by hand (independent of the
// quaternion code under test).
#pragma once

#include <Eigen/Core>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace mocap_test
{

constexpr double kPi = 3.14159265358979323846;
inline double deg(double degrees)
{
    return degrees * kPi / 180.0;
}

// Writes `text` byte for byte to a fresh file in the temp folder; removed on destruction.
class TempFile
{
  public:
    TempFile(const std::string &stem, const std::string &text)
    {
        static int counter = 0;
        path_ = (std::filesystem::temp_directory_path() /
                 ("ictus_mocap_" + std::to_string(::getpid()) + "_" + std::to_string(counter++) +
                  "_" + stem))
                    .string();
        std::ofstream out(path_, std::ios::binary);
        out << text;
    }
    ~TempFile() { std::filesystem::remove(path_); }
    TempFile(const TempFile &) = delete;
    TempFile &operator=(const TempFile &) = delete;
    const std::string &path() const { return path_; }

  private:
    std::string path_;
};

inline std::string data_dir()
{
    if (const char *env = std::getenv("ICTUS_DATA_DIR"))
        if (*env)
            return env;
    return ICTUS_DATA_DIR_DEFAULT;
}

// Path of a data file, or "" after SKIP/FAIL per the team rule (FAIL when CI=true).
inline std::string data_file(const std::string &relative)
{
    const std::string path = data_dir() + "/" + relative;
    if (std::filesystem::exists(path))
        return path;
    const char *ci = std::getenv("CI");
    const std::string message =
        "data file " + path + " is missing (set ICTUS_DATA_DIR to the folder holding cmu/)";
    if (ci && std::string(ci) == "true")
        FAIL(message);
    WARN("SKIPPED: " << message);
    return "";
}

// Right-handed rotation matrices, element by element.
inline Eigen::Matrix3d rot_x(double a)
{
    Eigen::Matrix3d m;
    m << 1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a);
    return m;
}
inline Eigen::Matrix3d rot_y(double a)
{
    Eigen::Matrix3d m;
    m << std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a);
    return m;
}
inline Eigen::Matrix3d rot_z(double a)
{
    Eigen::Matrix3d m;
    m << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
    return m;
}
inline Eigen::Matrix3d rot_axis(char axis, double a)
{
    return axis == 'X' ? rot_x(a) : axis == 'Y' ? rot_y(a) : rot_z(a);
}

} // namespace mocap_test
