// Forward kinematics: joint-local transforms to world positions and rotations.
#ifndef STYLUS_MOTION_KINEMATICS_H_
#define STYLUS_MOTION_KINEMATICS_H_

#include <vector>

#include "motion/motion.h"

namespace stylus::motion {

struct GlobalPose {
  std::vector<Vec3> positions;  // World position of each joint.
  std::vector<Quat> rotations;  // World rotation of each joint's frame.
};

// World transforms of all joints for one local pose (parents before children,
// so one pass suffices; no recursion).
GlobalPose ForwardKinematics(const Skeleton& skeleton, const LocalPose& pose);

// World positions of every joint in every frame: frames x joints.
std::vector<std::vector<Vec3>> GlobalPositions(const Motion& motion);

// GlobalPositions turned so that `up_axis` (0 X, 1 Y, 2 Z) points along +Y
// (a rotation, so left and right stay as they are): what the cadence and the
// gait curves read.
std::vector<std::vector<Vec3>> GlobalPositionsYUp(const Motion& motion, int up_axis);

// Local pose from world rotations and positions (the inverse of
// ForwardKinematics): rotation_j = R_parent^-1 R_j, translation_j =
// R_parent^-1 (p_j - p_parent).
LocalPose LocalFromGlobal(const Skeleton& skeleton, const GlobalPose& global);

// Largest distance between corresponding joints of two motions over all frames
// (both must have the same number of joints and frames).
double MaxPositionDifference(const Motion& a, const Motion& b);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_KINEMATICS_H_
