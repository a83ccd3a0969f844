// joint_limit_ref.hpp -- a joint limit as data that the controller and the
// IK can apply without knowing its kind (character_limits.hpp makes them).
#pragma once

#include <Eigen/Geometry>

namespace ictus
{

// A joint limit seen through a function pointer and the object it reads, so that any type
// with `Eigen::Quaterniond clamp(const Eigen::Quaterniond &) const` (e.g. the QuaternionLimit
// learnt from mocap by Algorithm 1) can be plugged in without inheritance and without the heap
// allocation a std::function may make. The referenced limit must outlive every chain holding
// this reference (the character owns both).
struct JointLimitRef {
    using ClampFn = Eigen::Quaterniond (*)(const void *limit,
                                           const Eigen::Quaterniond &local_rotation);
    const void *limit = nullptr;
    ClampFn clamp_fn = nullptr;

    bool active() const { return clamp_fn != nullptr; }
    // The rotation itself when there is no limit.
    Eigen::Quaterniond clamp(const Eigen::Quaterniond &local_rotation) const
    {
        return clamp_fn ? clamp_fn(limit, local_rotation) : local_rotation;
    }

    template <class Limit> static JointLimitRef to(const Limit &limit)
    {
        JointLimitRef ref;
        ref.limit = &limit;
        ref.clamp_fn = [](const void *p, const Eigen::Quaterniond &q) -> Eigen::Quaterniond {
            return static_cast<const Limit *>(p)->clamp(q);
        };
        return ref;
    }
};

} // namespace ictus
