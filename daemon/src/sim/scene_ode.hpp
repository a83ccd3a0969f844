// ODE's vectors and quaternions as Eigen's, for the scene's files
// (scene_build.cpp, scene_step.cpp, scene_state.cpp). Private to sim.
#pragma once

#include <ode/ode.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace ictus
{
namespace ode
{

inline Eigen::Quaterniond to_eigen(const dReal *q)
{
    return Eigen::Quaterniond(q[0], q[1], q[2], q[3]);
}
inline void to_ode(const Eigen::Quaterniond &q, dQuaternion out)
{
    out[0] = q.w();
    out[1] = q.x();
    out[2] = q.y();
    out[3] = q.z();
}
inline Eigen::Vector3d to_eigen3(const dReal *v)
{
    return Eigen::Vector3d(v[0], v[1], v[2]);
}

} // namespace ode
} // namespace ictus
