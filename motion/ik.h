// Two-bone inverse kinematics (hip-knee-ankle) in world space.
#ifndef STYLUS_MOTION_IK_H_
#define STYLUS_MOTION_IK_H_

#include "motion/rotation.h"

namespace stylus::motion {

struct TwoBoneResult {
  Vec3 knee, ankle;      // New world positions.
  Quat hip_delta;        // World rotation to apply to the hip's frame ...
  Quat knee_delta;       // ... and to the knee's (both include the hip's).
  bool reached = false;  // The ankle is at the target (within 1e-6 of the leg's reach).
};

// Places the ankle at `target` with the hip fixed and the upper and lower leg
// lengths of the current pose (hip->knee, knee->ankle), bending the knee in
// the plane that holds the current knee (its direction from the hip-ankle
// line is kept). A target out of reach gives the straight (or fully folded)
// leg pointing at it; a degenerate pose (knee on the hip-ankle line) bends
// towards `pole_hint`. Never NaN for finite input.
TwoBoneResult SolveTwoBone(const Vec3& hip, const Vec3& knee, const Vec3& ankle,
                           const Vec3& target, const Vec3& pole_hint = {0, 0, 1});

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_IK_H_
