// Procedural motion: a parametric walk or run on the Bandai skeleton, with style
// knobs (speed, stride, posture, arm swing, ...). Feet are planted during stance
// (two-bone leg IK onto footstep targets), so the clips are usable as test data
// and as the sample clips the repository ships.
#ifndef STYLUS_MOTION_SYNTH_H_
#define STYLUS_MOTION_SYNTH_H_

#include <string>

#include "absl/status/statusor.h"
#include "motion/motion.h"

namespace stylus::motion {

// The Bandai dataset's 21-joint skeleton (joint names, hierarchy, offsets in cm,
// 6 channels per joint in ZXY rotation order), as its BVH files declare it.
Skeleton BandaiSkeleton();

struct SynthStyle {
  bool run = false;       // Gait: walk or run.
  double speed = 130;     // cm/s along the path.
  double stride = 125;    // cm per full gait cycle (two steps).
  double lean = 3;        // Forward trunk lean, degrees.
  double head_drop = 0;   // Extra head pitch down, degrees.
  double arm_swing = 20;  // Shoulder swing amplitude, degrees.
  double elbow = 15;      // Elbow bend, degrees.
  double arm_out = 6;     // Arms held away from the body, degrees.
  double bounce = 2;      // Pelvis vertical oscillation, cm.
  double foot_lift = 10;  // Swing foot clearance, cm.
  double crouch = 0.03;   // Knee bend at stance, as a fraction of leg length.
  double sway = 2;        // Pelvis side-to-side sway, cm.
  double turn = 0;        // Heading change, degrees per second (+ turns left).
  int frames = 150;
  double fps = 30;
};

// A style from "PRESET[,key=value...]" or "key=value,...". Presets: normal, old,
// tired, proud, happy, sneaky, run. Keys: gait (walk|run), speed, stride, lean,
// head_drop, arm_swing, elbow, arm_out, bounce, foot_lift, crouch, sway, turn,
// frames, fps. INVALID_ARGUMENT names an unknown key or bad value.
absl::StatusOr<SynthStyle> ParseSynthStyle(const std::string& spec);

// The motion, starting at the origin facing +Z. INVALID_ARGUMENT for
// out-of-range knobs (non-positive speed, stride, frames or fps).
absl::StatusOr<Motion> Synthesize(const SynthStyle& style);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_SYNTH_H_
