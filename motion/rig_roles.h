// Humanoid roles of any rig: which joint of a skeleton is the pelvis, the
// chest, each thigh, shin, foot, upper arm, forearm, hand and so on, so that
// a clip on one rig can be retargeted onto another (motion/retarget.h).
//
// Found in three ways, in this order:
//  1. a joint map (`left_foot = mixamorig:LeftFoot`, one role per line) fixes
//     the roles it names;
//  2. names: feet and hands by the common conventions (LeftFoot, Foot_L,
//     foot.L, l_ankle, RightWrist, hand_r, "Bip01 L Foot", with any
//     `namespace:` prefix); the rest of each limb, the pelvis, spine, chest,
//     clavicles, neck and toes from the hierarchy around them;
//  3. when names do not tell: hierarchy and geometry. The pelvis is the
//     shallowest joint with three branches; its largest branch is the spine,
//     the two others the legs; the first joint up the spine with three
//     branches is the chest, its two largest branches the arms. Along a limb
//     the two longest consecutive bones are the upper and lower limb. Left
//     and right come from the first frame's pose: the toes point forward.
#ifndef STYLUS_MOTION_RIG_ROLES_H_
#define STYLUS_MOTION_RIG_ROLES_H_

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "motion/humanoid.h"
#include "motion/kinematics.h"
#include "motion/skeleton.h"

namespace stylus::motion {

enum class Role {
  kPelvis,
  kSpine,
  kChest,
  kNeck,
  kHead,
  kLeftClavicle,
  kLeftUpperArm,
  kLeftForearm,
  kLeftHand,
  kRightClavicle,
  kRightUpperArm,
  kRightForearm,
  kRightHand,
  kLeftThigh,
  kLeftShin,
  kLeftFoot,
  kLeftToe,
  kRightThigh,
  kRightShin,
  kRightFoot,
  kRightToe,
};
inline constexpr int kRoleCount = 21;

// "pelvis", "left_upper_arm", ... (the joint map's spelling).
absl::string_view RoleName(Role role);
// Inverse of RoleName (case-insensitive; '-' and ' ' read as '_').
bool ParseRole(absl::string_view name, Role* role);
// Roles every rig must have; the others are optional (spine, neck,
// clavicles, toes).
bool RoleRequired(Role role);

// role -> joint name, from a joint map file.
using JointMap = std::vector<std::pair<Role, std::string>>;
// Parses a joint map: `role = joint name` lines, `#` comments, blank lines.
// INVALID_ARGUMENT "<source>:<line>: ..." for an unknown role, a role given
// twice or a line without '='.
absl::StatusOr<JointMap> ParseJointMap(absl::string_view text, absl::string_view source);
absl::StatusOr<JointMap> ReadJointMapFile(const std::string& path);

struct RigRoles {
  std::array<int, kRoleCount> joint;  // -1: the rig has no such joint.
  // How each role was found: "joint map", "name", "hierarchy", "geometry",
  // or "end site" (a toe that is the foot's End Site).
  std::array<std::string, kRoleCount> how;
  // A toe without a joint: the foot's first End Site stands for it.
  std::array<bool, 2> toe_is_end_site{};  // left, right
  Vec3 up{0, 1, 0};  // The world's up axis (a unit axis, e.g. +Z for Z-up rigs).

  RigRoles() { joint.fill(-1); }
  int operator[](Role r) const { return joint[static_cast<int>(r)]; }
  bool has(Role r) const { return joint[static_cast<int>(r)] >= 0; }
};

// Finds the roles of `skeleton`; `sample` (the clip's first frame, world
// transforms) gives the geometry: the up axis and, for the fallback, sides.
// INVALID_ARGUMENT names every required role it could not find and says how
// to give them (--joint-map).
absl::StatusOr<RigRoles> FindRigRoles(const Skeleton& skeleton, const GlobalPose& sample,
                                      const JointMap& joint_map = {});

// The roles features and metrics read (motion/humanoid.h) of any rig
// FindRigRoles maps, from `clip`'s first frame: FindHumanoidRoles by names
// where it works, else the rig roles (a toe that is an End Site stands as
// its foot). INVALID_ARGUMENT as FindRigRoles.
absl::StatusOr<HumanoidRoles> HumanoidRolesOf(const Motion& clip);

// The mean rest length of the two legs, thigh to foot.
double LegLength(const Skeleton& skeleton, const RigRoles& roles);

// A table of role, joint and how it was found, one line per role.
std::string DescribeRigRoles(const Skeleton& skeleton, const RigRoles& roles);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_RIG_ROLES_H_
