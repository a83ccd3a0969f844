// motor_noise.hpp -- the seeded generator of the performer's motor noise
// (`humanize`, docs/humanize.md): std::mt19937_64 streams,
// each seeded from (seed, stream) by SplitMix64, and standard normal draws
// by the Box-Muller transform on 53-bit uniforms, so a seed gives the same
// numbers with any standard library.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace ictus
{

// SplitMix64 (Steele, Lea & Flood 2014): one step of the mixer.
inline std::uint64_t splitmix64(std::uint64_t x)
{
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

class MotorNoise
{
  public:
    // Stream `stream` of performance seed `seed` (the plan draws stream k
    // for note k; the controller draws its own stream).
    MotorNoise(std::uint64_t seed = 1, std::uint64_t stream = 0)
        : rng_(splitmix64(seed ^ splitmix64(stream + 0x632BE59BD9B4E019ull)))
    {
    }
    // A standard normal draw (Box-Muller; both values of a pair are used).
    double normal()
    {
        if (has_spare_) {
            has_spare_ = false;
            return spare_;
        }
        constexpr double kTwoPi = 6.283185307179586;
        const double u1 = 1.0 - uniform(); // (0, 1]
        const double u2 = uniform();
        const double r = std::sqrt(-2.0 * std::log(u1));
        spare_ = r * std::sin(kTwoPi * u2);
        has_spare_ = true;
        return r * std::cos(kTwoPi * u2);
    }
    double uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; } // [0, 1)

  private:
    std::mt19937_64 rng_;
    double spare_ = 0.0;
    bool has_spare_ = false;
};

} // namespace ictus
