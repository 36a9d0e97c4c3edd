// The cadence of a clip: the period at which its motion repeats (a walk's
// step, a wave's swing), found from the autocorrelation of how fast the body
// moves relative to its root. Used to give a transfer the style clip's
// timing (TransferOptions::timing) by a time warp.
#ifndef STYLUS_MOTION_CADENCE_H_
#define STYLUS_MOTION_CADENCE_H_

#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/humanoid.h"
#include "motion/motion.h"

namespace stylus::motion {

struct Cadence {
  double period_s = 0;  // Seconds per repeat: the strongest candidate.
  double strength = 0;  // The autocorrelation at that period (0-1).
  // Every period whose peak is at least half as strong, strongest first. A
  // walk repeats at its step and at its stride (two steps), and which one is
  // stronger depends on how even the gait is; two clips are compared by
  // their candidates nearest each other (NearestPeriod).
  std::vector<double> candidates_s;
};

// The candidate nearest `period_s` by ratio (the first when equal).
double NearestPeriod(const std::vector<double>& candidates_s, double period_s);

// Periods searched (seconds), and how strongly the body-speed signal must
// repeat to count as a cadence.
inline constexpr double kMinPeriodS = 0.3, kMaxPeriodS = 2.5, kMinCadenceStrength = 0.25;

// The clip's cadence: the signal is the summed speed of every joint
// relative to the pelvis's floor point, per frame; the period is the lag of
// the highest peak of its autocorrelation within [kMinPeriodS, kMaxPeriodS]
// (and half the clip), which must reach kMinCadenceStrength, refined to a
// fraction of a frame. The estimate is the biased one (each lag's sum over
// the whole clip's energy), so that a multiple of the period, seen over
// fewer frames, weighs less than the period itself: a walk's step, not its
// stride, nor half a step. NOT_FOUND when the clip does not repeat (a single
// punch, a bow) or is too short to show two periods.
absl::StatusOr<Cadence> FindCadence(const Motion& clip, const HumanoidRoles& roles);

// `clip` played `ratio` times slower (ratio > 0): frame k of the result is
// `clip` at time k * frame_time / ratio, translations interpolated linearly
// and rotations by slerp; round((num_frames - 1) * ratio) + 1 frames at the
// clip's own rate, so the first and last frames are the clip's.
Motion TimeWarp(const Motion& clip, double ratio);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_CADENCE_H_
