// default_skeleton.hpp -- the default body: the CMU hierarchy with round-number
// offsets, driven by stick-only captures and by scores.
#pragma once

#include "ictus/mocap/motion.hpp"

namespace ictus
{

// A body with the CMU joint names and round-number dimensions (1.75 m), for
// captures that have only the sticks.
Skeleton default_skeleton();

} // namespace ictus
