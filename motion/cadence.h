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
  // Where the period comes from: the feet's steps (one foot's touchdown to
  // the other's), or, for a clip that does not step, how the whole body
  // moves (the autocorrelation of its speed relative to the root).
  enum class Source { kSteps, kMotion };
  Source source = Source::kMotion;
  double period_s = 0;  // Seconds per repeat: per step, or per repeat of the motion.
  // Steps: the share of step intervals within 15% of the period; motion: the
  // autocorrelation at the period (0-1).
  double strength = 0;
};

// Periods searched (seconds), and how strongly the body-speed signal must
// repeat to count as a cadence.
inline constexpr double kMinPeriodS = 0.25, kMaxPeriodS = 2.5, kMinCadenceStrength = 0.25;

// The clip's cadence. Steps first: each foot is planted while its ankle or
// toe is in contact (motion/contacts.h), a touchdown is where a foot becomes
// planted, and the period is the median time from one foot's touchdown to
// the other's (at least two such intervals, within [kMinPeriodS,
// kMaxPeriodS]). Otherwise the motion: the signal is the summed speed of
// every joint relative to the pelvis's floor point, and the period the lag of
// the highest peak of its autocorrelation (the biased estimate, so that a
// multiple of the period, seen over fewer frames, weighs less) within
// [kMinPeriodS, kMaxPeriodS] and half the clip, which must reach
// kMinCadenceStrength. NOT_FOUND when the clip neither steps nor repeats (a
// single punch, a bow) or is too short to show two periods.
absl::StatusOr<Cadence> FindCadence(const Motion& clip, const HumanoidRoles& roles);
// The same from the clip's joint positions per frame, Y up
// (GlobalPositionsYUp), for a caller that has them already.
absl::StatusOr<Cadence> FindCadence(const std::vector<std::vector<Vec3>>& positions,
                                    double frame_time, const HumanoidRoles& roles);

// How many times longer `to` takes per repeat than `from`. INVALID_ARGUMENT
// when one steps and the other does not (a walk's steps and a wave's swings
// are not the same kind of repeat).
absl::StatusOr<double> TempoRatio(const Cadence& from, const Cadence& to);

// `clip` played `ratio` times slower (ratio > 0): frame k of the result is
// `clip` at time k * frame_time / ratio, translations interpolated linearly
// and rotations by slerp; round((num_frames - 1) * ratio) + 1 frames at the
// clip's own rate, so the first and last frames are the clip's.
Motion TimeWarp(const Motion& clip, double ratio);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_CADENCE_H_
