// How the body moved in a score performance (body_stats.hpp).
#include "ictus/perform/body_stats.hpp"

#include "ictus/base/rotation.hpp"

#include <algorithm>
#include <cmath>

namespace ictus
{

double BodyStats::trunk_rms_deg() const
{
    return steps > 0 ? std::sqrt(trunk_sum_sq_deg2 / static_cast<double>(steps)) : 0.0;
}

void BodyStats::add_step(const CharacterModel &model, const RangeOfMotion &range_of_motion,
                         int lumbar, int thorax, const std::vector<Eigen::Quaterniond> &local)
{
    int joint = -1;
    const double e = range_of_motion.max_excursion_rad(local, &joint) * 180.0 / M_PI;
    if (e > max_limit_excursion_deg) {
        max_limit_excursion_deg = e;
        max_limit_joint = model.joint_name(joint);
    }
    // The thorax relative to the pelvis: lumbar then thorax joint.
    const double trunk =
        rotation_angle_between(Eigen::Quaterniond::Identity(), local[lumbar] * local[thorax]) *
        180.0 / M_PI;
    trunk_max_deg = std::max(trunk_max_deg, trunk);
    trunk_sum_sq_deg2 += trunk * trunk;
    ++steps;
}

} // namespace ictus
