// Humanoid roles: which joints of a skeleton are the pelvis, hips, shoulders,
// ankles and toes. Features (facing direction, root trajectory) and foot contacts
// need them; they are found from joint names, so any rig that names its sides
// (Foot_L, LeftFoot, l_ankle, ...) works.
#ifndef STYLUS_MOTION_HUMANOID_H_
#define STYLUS_MOTION_HUMANOID_H_

#include <vector>

#include "absl/status/statusor.h"
#include "motion/skeleton.h"

namespace stylus::motion {

struct HumanoidRoles {
  int pelvis = -1;  // Common parent of the two hips.
  int left_hip = -1, right_hip = -1;
  int left_shoulder = -1, right_shoulder = -1;  // Upper-arm joints.
  int left_ankle = -1, right_ankle = -1;
  int left_toe = -1, right_toe = -1;
  double leg_length = 0;  // Hip to ankle plus ankle to toe along the offsets.
  int up_axis = 1;        // Y is up (BVH convention).
};

// Finds the roles by name; INVALID_ARGUMENT names the role it could not find.
absl::StatusOr<HumanoidRoles> FindHumanoidRoles(const Skeleton& skeleton);

// The child of `joint` with the most joints below it: where a limb goes on
// (not a twist bone or a prop); -1 for a joint without children.
int MainChild(const Skeleton& skeleton, int joint);

// Sum of the offsets from joint `from` down to its descendant `to` (the
// rest length of the chain between them).
double ChainLength(const Skeleton& skeleton, int from, int to);

// Per joint of `skeleton`: whether it is one of the hips or below one (the
// legs, down to the toes).
std::vector<bool> LegJoints(const Skeleton& skeleton, const HumanoidRoles& roles);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_HUMANOID_H_
