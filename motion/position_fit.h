// Joint rotations from joint positions: models that generate positions (the
// `cyclic` family) need rotations to write BVH. The fit keeps bone lengths
// exact (positions are rebuilt from the skeleton's offsets) and takes each
// bone's twist from the rotations already in the features (e.g. the content
// clip's), so only the swing that moves a bone onto its target changes.
#ifndef STYLUS_MOTION_POSITION_FIT_H_
#define STYLUS_MOTION_POSITION_FIT_H_

#include "motion/features.h"
#include "motion/humanoid.h"
#include "motion/skeleton.h"

namespace stylus::motion {

// `features` holds real (not normalized) values in the layout of
// motion/features.h. For every frame, walking down from the pelvis (which
// stays where its position channels put it): each joint's rotation is turned
// so that its children's bones point at the children's target positions
// (joints with several children, such as the pelvis and chest, take the
// rotation that best aligns all of them, weighted by bone length); leaf
// joints keep their rotation. Hinges (a joint with one child, alone under a
// parent that is no hinge, whose starting rotations all turn about one axis
// of the parent's frame through the clip: knees in captured motion) keep
// that axis: the parent is fitted as a two-bone chain, the hinge angle set
// by the end joint's target distance and the chain pointed at the end's
// target, then turned about that line towards the hinge's own target. The
// rotation channels then hold the fitted rotations (each frame in the
// previous frame's hemisphere) and the position channels of the pelvis's
// descendants the positions forward kinematics gives with the skeleton's
// offsets. Other channels are untouched. With `hinge_reference` (features of
// as many frames, e.g. the content clip's), hinges and their axes are found
// in its rotations instead of the starting ones (generated rotations, which
// turn about a knee's axis only nearly).
void FitRotationsToPositions(const Skeleton& skeleton, const HumanoidRoles& roles,
                             FeatureClip* features,
                             const FeatureClip* hinge_reference = nullptr);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_POSITION_FIT_H_
