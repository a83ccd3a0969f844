// anthropometry.hpp -- body segment inertial parameters from a published table:
// P. de Leva (1996), "Adjustments to Zatsiorsky-Seluyanov's segment inertia
// parameters", J. Biomech. 29(9):1223-1230, Table 4 (male, joint-centre based).
// Mass as a fraction of body mass, centre of mass as a fraction of the segment
// length from the proximal end, radii of gyration as fractions of the length.
#pragma once

#include <string>

namespace ictus
{

enum class DeLevaSegment {
    head,         // vertex to cervicale (C7), head and neck
    upper_trunk,  // UPT: suprasternale to xiphoid
    middle_trunk, // MPT: xiphoid to omphalion
    lower_trunk,  // LPT: omphalion to mid-hip
    upper_arm,    // shoulder to elbow joint centre
    forearm,      // elbow to wrist (stylion)
    hand,         // wrist to 3rd metacarpale
    thigh,        // hip to knee joint centre
    shank,        // knee to lateral malleolus
    foot,         // heel to toe tip
};

struct SegmentParameters {
    const char *name;
    double mass_fraction;     // of total body mass
    double com_fraction;      // from the proximal (cranial for the trunk) end
    double radius_sagittal;   // about the antero-posterior axis, fraction of length
    double radius_transverse; // about the medio-lateral axis, fraction of length
    double radius_long;       // about the longitudinal axis, fraction of length
    double length_m;          // mean segment length of de Leva's male sample
};

// The table row of one segment (male sample, mean stature 1.741 m, 73.0 kg).
const SegmentParameters &de_leva_male(DeLevaSegment segment);

// Mean stature of de Leva's male sample, m.
constexpr double kDeLevaMaleStature_m = 1.741;

} // namespace ictus
