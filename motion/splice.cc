#include "motion/splice.h"

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace stylus::motion {
namespace {

void AddSubtree(const Skeleton& skeleton, int joint, std::vector<bool>* in) {
  (*in)[joint] = true;
  for (int child : skeleton.children(joint)) AddSubtree(skeleton, child, in);
}

std::vector<bool> ArmJoints(const Skeleton& skeleton, int upper_arm) {
  std::vector<bool> in(skeleton.num_joints(), false);
  AddSubtree(skeleton, upper_arm, &in);
  const int clavicle = skeleton.joint(upper_arm).parent;
  if (clavicle >= 0 && skeleton.children(clavicle).size() == 1) in[clavicle] = true;
  return in;
}

}  // namespace

std::string BodyPartName(BodyPart part) {
  switch (part) {
    case BodyPart::kLegs:
      return "legs";
    case BodyPart::kTorso:
      return "torso";
    case BodyPart::kLeftArm:
      return "left-arm";
    case BodyPart::kRightArm:
      return "right-arm";
  }
  return "?";
}

absl::StatusOr<BodyPart> ParseBodyPart(absl::string_view name) {
  for (BodyPart p : kBodyParts) {
    if (name == BodyPartName(p)) return p;
  }
  return absl::InvalidArgumentError(
      absl::StrCat("unknown body part '", name, "' (legs, torso, left-arm or right-arm)"));
}

std::vector<int> BodyPartJoints(const Skeleton& skeleton, const HumanoidRoles& roles,
                                BodyPart part) {
  const int n = skeleton.num_joints();
  std::vector<bool> in(n, false);
  if (part == BodyPart::kLegs) {
    in = LegJoints(skeleton, roles);
  } else if (part == BodyPart::kLeftArm) {
    in = ArmJoints(skeleton, roles.left_shoulder);
  } else if (part == BodyPart::kRightArm) {
    in = ArmJoints(skeleton, roles.right_shoulder);
  } else {
    // The torso: below the pelvis, in no leg and no arm.
    const std::vector<bool> legs = LegJoints(skeleton, roles),
                            left = ArmJoints(skeleton, roles.left_shoulder),
                            right = ArmJoints(skeleton, roles.right_shoulder);
    std::vector<bool> below(n, false);
    for (int child : skeleton.children(roles.pelvis)) AddSubtree(skeleton, child, &below);
    for (int j = 0; j < n; ++j) in[j] = below[j] && !legs[j] && !left[j] && !right[j];
  }
  std::vector<int> joints;
  for (int j = 0; j < n; ++j) {
    if (in[j]) joints.push_back(j);
  }
  return joints;
}

absl::StatusOr<Motion> SpliceJoints(const Motion& base, const Motion& donor,
                                    const std::vector<int>& joints, const std::string& base_name,
                                    const std::string& donor_name) {
  if (!base.skeleton.SameTopology(donor.skeleton)) {
    return absl::InvalidArgumentError(absl::StrCat(donor_name, " is on another skeleton than ",
                                                   base_name, ": ",
                                                   base.skeleton.DescribeMismatch(donor.skeleton)));
  }
  if (donor.num_frames < base.num_frames) {
    return absl::InvalidArgumentError(absl::StrCat(donor_name, " has ", donor.num_frames,
                                                   " frames, fewer than the ", base.num_frames,
                                                   " of ", base_name));
  }
  Motion out = base;
  for (int j : joints) {
    if (j < 0 || j >= base.skeleton.num_joints()) {
      return absl::InvalidArgumentError(absl::StrCat("no joint ", j, " in ", base_name));
    }
    const int start = base.skeleton.channel_start(j);
    const int count = static_cast<int>(base.skeleton.joint(j).channels.size());
    for (int f = 0; f < base.num_frames; ++f) {
      std::copy(donor.frame(f) + start, donor.frame(f) + start + count, out.frame(f) + start);
    }
  }
  return out;
}

}  // namespace stylus::motion
