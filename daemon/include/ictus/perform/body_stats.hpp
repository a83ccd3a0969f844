// body_stats.hpp -- how the body moved in a score performance: how far any
// joint went outside its range of motion and how far the trunk turned
// (`ictusd render`'s performance.json; docs/perform.md, "Joint limits" and
// "The trunk").
#pragma once

#include "ictus/character/character.hpp"
#include "ictus/character/range_of_motion.hpp"

#include <Eigen/Geometry>

#include <string>
#include <vector>

namespace ictus
{

struct BodyStats {
    // How far any joint went outside its range of motion (the simulated
    // pose: range_of_motion.hpp), degrees, and which.
    double max_limit_excursion_deg = 0.0;
    std::string max_limit_joint;
    long steps = 0;
    // How far the trunk (thorax relative to the pelvis) turned from its rest, degrees.
    double trunk_max_deg = 0.0;
    double trunk_sum_sq_deg2 = 0.0;
    double trunk_rms_deg() const;
    // Counts one step in the pose `local` (joint rotations of `model`);
    // `lumbar` and `thorax` are the trunk's joints.
    void add_step(const CharacterModel &model, const RangeOfMotion &range_of_motion, int lumbar,
                  int thorax, const std::vector<Eigen::Quaterniond> &local);
};

} // namespace ictus
