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
  // Measure height above the joint's lowest point in frames 0..f instead of
  // in the whole clip, so frame f's contact needs no frame after f + 1
  // (live models, which cannot wait for the clip's end). A foot still in
  // the air in the first frames reads as low until it has touched down.
  bool running_floor = false;
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
