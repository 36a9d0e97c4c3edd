// How a clip moves, as an animator reads a gait: curves over time of where
// the left foot and hand are against the pelvis and how high the foot and
// the pelvis are, with their amplitudes, the cadence and the speed. Lengths
// are in leg lengths (HumanoidRoles::leg_length), so clips on rigs of other
// sizes compare. `stylus-tool gait` draws and tabulates them for a model's
// transfers beside their content and style clips.
#ifndef STYLUS_MOTION_GAIT_H_
#define STYLUS_MOTION_GAIT_H_

#include <optional>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/cadence.h"
#include "motion/humanoid.h"
#include "motion/motion.h"

namespace stylus::motion {

struct GaitCurves {
  double frame_time = 1.0 / 30.0;
  // One value per frame, in leg lengths. Forward is the body's facing (from
  // the hip and shoulder lines), on the floor.
  std::vector<double> foot_forward;   // Left ankle ahead of the pelvis: the stride.
  std::vector<double> foot_height;    // Left ankle above its lowest point in the clip: the lift.
  std::vector<double> hand_forward;   // Left hand ahead of the pelvis: the arm swing.
  std::vector<double> pelvis_height;  // Pelvis above its mean height: the bob.
};

struct GaitSummary {
  // Seconds per step (or per repeat of a motion that does not step); nullopt
  // when the clip does not repeat (motion/cadence.h).
  std::optional<Cadence> cadence;
  // Each curve's spread: its 95th minus its 5th percentile, in leg lengths.
  double stride = 0, foot_lift = 0, arm_swing = 0, bob = 0;
  double speed = 0;  // The pelvis's mean speed along the floor, leg lengths per second.
};

struct Gait {
  GaitCurves curves;
  GaitSummary summary;
};

// The curves of `clip`, their spreads, its cadence and its speed. The hand
// is the joint two below the left shoulder (upper arm, forearm, hand), each
// step down to the child with the most joints below it (past twist bones).
// INVALID_ARGUMENT for an empty clip or when the left arm has no such joint.
absl::StatusOr<Gait> MeasureGait(const Motion& clip, const HumanoidRoles& roles);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_GAIT_H_
