// Body parts of a humanoid, and splicing one clip's body part onto another
// (an animator's layering: the legs of one take under the arms of another).
// Evaluation uses it to ask whether a content judge reads an action from the
// body part that performs it, or also from the rest of the body
// (docs/notes/contrastive.md).
#ifndef STYLUS_MOTION_SPLICE_H_
#define STYLUS_MOTION_SPLICE_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "motion/humanoid.h"
#include "motion/motion.h"

namespace stylus::motion {

enum class BodyPart { kLegs, kTorso, kLeftArm, kRightArm };
inline constexpr BodyPart kBodyParts[] = {BodyPart::kLegs, BodyPart::kTorso, BodyPart::kLeftArm,
                                          BodyPart::kRightArm};

// "legs", "torso", "left-arm", "right-arm".
std::string BodyPartName(BodyPart part);
// INVALID_ARGUMENT listing the names above for anything else.
absl::StatusOr<BodyPart> ParseBodyPart(absl::string_view name);

// The joints of a part, by their humanoid roles: the legs are the hips and
// everything below them; an arm is the upper-arm joint's subtree and its
// parent when that parent is a clavicle (a joint with no other child); the
// torso is every other joint between the pelvis and the head (spine, chest,
// neck, head). The pelvis and the joints above it belong to no part: they
// carry the character's path.
std::vector<int> BodyPartJoints(const Skeleton& skeleton, const HumanoidRoles& roles,
                                BodyPart part);

// `base` with the channels of `joints` taken from `donor`, frame by frame
// (donor frame f into base frame f). INVALID_ARGUMENT, naming both clips by
// `base_name` and `donor_name`, when their skeletons differ in topology or the
// donor has fewer frames than the base.
absl::StatusOr<Motion> SpliceJoints(const Motion& base, const Motion& donor,
                                    const std::vector<int>& joints,
                                    const std::string& base_name = "base",
                                    const std::string& donor_name = "donor");

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_SPLICE_H_
