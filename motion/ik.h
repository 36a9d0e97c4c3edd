// Two-bone inverse kinematics (hip-knee-ankle) in world space.
#ifndef STYLUS_MOTION_IK_H_
#define STYLUS_MOTION_IK_H_

#include <optional>

#include "motion/rotation.h"

namespace stylus::motion {

struct TwoBoneResult {
  Vec3 knee, ankle;      // New world positions.
  Quat hip_delta;        // World rotation to apply to the hip's frame ...
  Quat knee_delta;       // ... and to the knee's (both include the hip's).
  bool reached = false;  // The ankle is at the target (within 1e-6 of the leg's reach).
};

struct TwoBoneParams {
  // The knee's hinge in world space: turning the shin about it by a positive
  // angle bends the knee. Without it, the hinge is the one of the current
  // pose (the knee's offset from the hip-ankle line), and for a straight leg
  // the knee bends towards `pole_hint`.
  std::optional<Vec3> hinge;
  Vec3 pole_hint{0, 0, 1};
  // Soft reach (a length; 0: off): within `soft` of the leg's full reach,
  // further stretch is eased in exponentially, so a near-straight leg does
  // not snap straight and its knee does not race (the knee angle's
  // sensitivity to the hip-ankle distance grows without bound there). The
  // ankle then stops short of a far target along the hip-target line.
  double soft = 0;
};

// Places the ankle at `target` with the hip fixed and the upper and lower leg
// lengths of the current pose (hip->knee, knee->ankle): the knee turns about
// its hinge by as much as the new hip-ankle distance needs (nothing when the
// distance is unchanged), then the whole leg swings at the hip to point at
// the target. A target out of reach gives the leg as straight as its hinge
// allows (straight for the pose's own hinge), pointing at it. Never NaN for
// finite input.
TwoBoneResult SolveTwoBone(const Vec3& hip, const Vec3& knee, const Vec3& ankle, const Vec3& target,
                           const TwoBoneParams& params = {});

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_IK_H_
