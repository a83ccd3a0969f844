// fuzz_check.hpp -- what the harnesses share: an input as text, and a check
// that stops the run (abort, so libFuzzer saves the input as a crash) when a
// reader breaks its own contract without throwing.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace ictus_fuzz
{

[[noreturn]] inline void fail(const char *file, int line, const char *what)
{
    std::fprintf(stderr, "%s:%d: contract broken: %s\n", file, line, what);
    std::abort();
}

// Like assert, but on in every build type and with its own message.
#define ICTUS_FUZZ_CHECK(condition, what)                                                          \
    do {                                                                                           \
        if (!(condition))                                                                          \
            ::ictus_fuzz::fail(__FILE__, __LINE__, what);                                          \
    } while (0)

inline std::string text_of(const std::uint8_t *data, std::size_t size)
{
    return std::string(reinterpret_cast<const char *>(data), size);
}

inline bool finite(const Eigen::Vector3d &v)
{
    return v.allFinite();
}

// A unit quaternion, as every reader promises for rotations.
inline bool unit(const Eigen::Quaterniond &q)
{
    return q.coeffs().allFinite() && std::fabs(q.norm() - 1.0) < 1e-6;
}

} // namespace ictus_fuzz
