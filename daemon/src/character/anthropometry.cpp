// The de Leva (1996) table, male column: mass %, CoM % (from the proximal end;
// for the trunk sub-segments the cranial one) and radii of gyration % about
// the sagittal, transverse and longitudinal axes, with the segment lengths of
// his male sample (mm in the paper, m here). Head row: vertex-cervicale length.
#include "ictus/character/anthropometry.hpp"

namespace ictus
{

namespace
{
const SegmentParameters kMale[] = {
    {"head", 0.0694, 0.5002, 0.303, 0.315, 0.261, 0.2429},
    {"upper_trunk", 0.1596, 0.5066, 0.505, 0.320, 0.465, 0.1707},
    {"middle_trunk", 0.1633, 0.4502, 0.482, 0.383, 0.468, 0.2155},
    {"lower_trunk", 0.1117, 0.6115, 0.615, 0.551, 0.587, 0.1457},
    {"upper_arm", 0.0271, 0.5772, 0.285, 0.269, 0.158, 0.2817},
    {"forearm", 0.0162, 0.4574, 0.276, 0.265, 0.121, 0.2689},
    {"hand", 0.0061, 0.7900, 0.628, 0.513, 0.401, 0.0862},
    {"thigh", 0.1416, 0.4095, 0.329, 0.329, 0.149, 0.4222},
    {"shank", 0.0433, 0.4395, 0.251, 0.246, 0.102, 0.4340},
    {"foot", 0.0137, 0.4415, 0.257, 0.245, 0.124, 0.2581},
};
} // namespace

const SegmentParameters &de_leva_male(DeLevaSegment segment)
{
    return kMale[static_cast<int>(segment)];
}

} // namespace ictus
