// The default body: the CMU hierarchy with offsets rounded from subject 80's.
#include "ictus/character/default_skeleton.hpp"
#include "ictus/mocap/bvh.hpp"

#include <Eigen/Core>

namespace ictus
{

Skeleton default_skeleton()
{
    struct Row {
        const char *name;
        const char *parent;
        double x, y, z; // CMU BVH units (kCmuBvhScale_m)
        bool end_site;
    };
    // The CMU hierarchy with offsets rounded from subject 80's (1.75 m).
    static const Row rows[] = {
        {"Hips", "", 0, 0, 0, false},
        {"LHipJoint", "Hips", 0, 0, 0, false},
        {"LeftUpLeg", "LHipJoint", 1.8, -1.7, 0.7, false},
        {"LeftLeg", "LeftUpLeg", 2.3, -6.2, 0, false},
        {"LeftFoot", "LeftLeg", 2.6, -7.0, 0, false},
        {"LeftToeBase", "LeftFoot", 0.2, -0.6, 1.7, false},
        {"LeftToeBase_end", "LeftToeBase", 0, 0, 0.9, true},
        {"RHipJoint", "Hips", 0, 0, 0, false},
        {"RightUpLeg", "RHipJoint", -1.8, -1.7, 0.7, false},
        {"RightLeg", "RightUpLeg", -2.3, -6.2, 0, false},
        {"RightFoot", "RightLeg", -2.6, -7.0, 0, false},
        {"RightToeBase", "RightFoot", -0.2, -0.6, 1.7, false},
        {"RightToeBase_end", "RightToeBase", 0, 0, 0.9, true},
        {"LowerBack", "Hips", 0, 0, 0, false},
        {"Spine", "LowerBack", 0, 1.7, -0.2, false},
        {"Spine1", "Spine", 0, 1.7, 0.2, false},
        {"Neck", "Spine1", 0, 0, 0, false},
        {"Neck1", "Neck", 0, 1.65, 0.1, false},
        {"Head", "Neck1", 0, 1.6, -0.3, false},
        {"Head_end", "Head", 0, 1.7, -0.1, true},
        {"LeftShoulder", "Spine1", 0, 0, 0, false},
        {"LeftArm", "LeftShoulder", 3.1, 1.4, 0.3, false},
        {"LeftForeArm", "LeftArm", 5.1, 0, 0, false},
        {"LeftHand", "LeftForeArm", 3.6, 0, 0, false},
        {"LeftFingerBase", "LeftHand", 0, 0, 0, false},
        {"LeftHandIndex1", "LeftFingerBase", 0.6, 0, 0, false},
        {"LeftHandIndex1_end", "LeftHandIndex1", 0.5, 0, 0, true},
        {"LThumb", "LeftHand", 0, 0, 0, false},
        {"LThumb_end", "LThumb", 0.5, 0, 0.5, true},
        {"RightShoulder", "Spine1", 0, 0, 0, false},
        {"RightArm", "RightShoulder", -3.1, 1.4, 0.3, false},
        {"RightForeArm", "RightArm", -5.1, 0, 0, false},
        {"RightHand", "RightForeArm", -3.6, 0, 0, false},
        {"RightFingerBase", "RightHand", 0, 0, 0, false},
        {"RightHandIndex1", "RightFingerBase", -0.6, 0, 0, false},
        {"RightHandIndex1_end", "RightHandIndex1", -0.5, 0, 0, true},
        {"RThumb", "RightHand", 0, 0, 0, false},
        {"RThumb_end", "RThumb", -0.5, 0, 0.5, true},
    };
    Skeleton s;
    for (const Row &r : rows) {
        SkeletonJoint j;
        j.name = r.name;
        j.parent = *r.parent ? s.find(r.parent) : -1;
        j.offset_m = Eigen::Vector3d(r.x, r.y, r.z) * kCmuBvhScale_m;
        j.end_site = r.end_site;
        s.joints.push_back(j);
    }
    return s;
}

} // namespace ictus
