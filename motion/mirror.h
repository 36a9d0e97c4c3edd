// Left-right mirroring of motions (data augmentation: a raise of the left
// hand becomes a raise of the right hand on the same skeleton).
//
// The world is reflected across its x = 0 plane and every joint takes the
// motion of its counterpart on the other side (UpperArm_L <-> UpperArm_R,
// found by name; joints on the centre line are their own counterpart). With
// a world reflection M and world joint rotations G, the mirrored motion has
// G'(m(j)) = M G(j) B(j), where B(j) is a constant reflection of joint j's
// local frame that maps its counterpart's child offsets onto its own (a rig
// whose joint frames are not mirror images of each other, such as Bandai's,
// needs a different one per joint). So local rotations become
// R'(m(j)) = B(parent) R(j) B(j) and translations t'(m(j)) = B(parent) t(j).
// B(j) is searched among the reflections that flip one axis or all three
// (a child placed by its position channels, off its offset, does not
// constrain it); where the offsets leave a choice, the parent's reflection
// is taken if it fits, else the one whose mirrored rotations best match the
// counterpart's own on sample motions (docs/motion.md, "Mirroring").
#ifndef STYLUS_MOTION_MIRROR_H_
#define STYLUS_MOTION_MIRROR_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/motion.h"
#include "motion/skeleton.h"

namespace stylus::motion {

struct MirrorMap {
  std::vector<int> counterpart;  // Per joint: the joint on the other side (or itself).
  std::vector<Vec3> flip;        // Per joint: B(j) as diagonal signs (their product is -1).
};

// The mirror of `skeleton`, with rotations chosen on `samples` (motions on
// that skeleton; may be empty, then the parent's reflection is preferred).
// INVALID_ARGUMENT when a sided joint has no counterpart (naming which) or
// when the rig is not left-right symmetric at a joint (its children's
// offsets do not mirror onto its counterpart's within 5% of their length).
absl::StatusOr<MirrorMap> PlanMirror(const Skeleton& skeleton,
                                     const std::vector<const Motion*>& samples);

// `motion` mirrored by `map` (made by PlanMirror for its skeleton): same
// skeleton, frames and channel layout.
Motion MirrorMotion(const Motion& motion, const MirrorMap& map);

// The largest distance, over frames and joints, between a joint of
// `mirrored` and the mirror image (x -> -x) of its counterpart in `original`
// (world positions, the file's units): how exactly `mirrored` is the mirror.
double MaxMirrorError(const Motion& original, const Motion& mirrored, const MirrorMap& map);

// A content label with its sides swapped: "raise-up-left-hand" ->
// "raise-up-right-hand", "walk-turn-right" -> "walk-turn-left"; labels
// without a side are returned as they are.
std::string MirrorLabel(const std::string& label);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_MIRROR_H_
