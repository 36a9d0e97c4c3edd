// Foot contacts: which of the four foot joints (left/right ankle and toe) rest on
// the ground in each frame.
#ifndef STYLUS_MOTION_CONTACTS_H_
#define STYLUS_MOTION_CONTACTS_H_

#include <array>
#include <vector>

#include "motion/humanoid.h"
#include "motion/rotation.h"

namespace stylus::motion {

// Thresholds in units of the skeleton's leg length, so they hold for any scale.
struct ContactParams {
  // A joint is "low" within this height above its lowest height in the clip.
  double height = 0.06;
  // ... and "still" below this horizontal speed, in leg lengths per second.
  double speed = 0.6;
};

// The four foot joints in feature order: left ankle, left toe, right ankle,
// right toe.
std::array<int, 4> FootJoints(const HumanoidRoles& roles);

// contacts[f][k] is true when foot joint k (FootJoints order) is low and still in
// frame f. `positions` is frames x joints world positions (Y up); fps > 0.
std::vector<std::array<bool, 4>> DetectFootContacts(const std::vector<std::vector<Vec3>>& positions,
                                                    const HumanoidRoles& roles, double fps,
                                                    const ContactParams& params = {});

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_CONTACTS_H_
