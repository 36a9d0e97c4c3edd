// Changing a clip's frame rate: stages capture at 24-240 Hz while models run
// at their training rate (30 Hz for the Bandai data). Translations are
// interpolated linearly, rotations by slerp; Euler angles stay continuous.
#ifndef STYLUS_MOTION_RESAMPLE_H_
#define STYLUS_MOTION_RESAMPLE_H_

#include "absl/status/status.h"
#include "motion/motion.h"

namespace stylus::motion {

// The frame rates a clip or a stream may come at (Hz, inclusive).
inline constexpr double kMinServedFps = 24, kMaxServedFps = 240;

// Whether two frame times are the same rate (within 1%).
bool SameRate(double frame_time, double other);

// INVALID_ARGUMENT naming `what` unless 1 / frame_time is in
// [kMinServedFps, kMaxServedFps].
absl::Status CheckServedRate(double frame_time, const std::string& what);

// a + u (b - a): translations linearly, rotations by slerp; u outside [0, 1]
// extrapolates.
LocalPose BlendPoses(const LocalPose& a, const LocalPose& b, double u);

// The pose at fractional frame `frame` of `m` (clamped to its frames).
LocalPose PoseAtTime(const Motion& m, double frame);

// `m` at `frame_time`: frame k is `m` at time k * frame_time (the last frame
// held past the clip's end). `frames` > 0 sets the count; by default, the
// frames that fit in the clip's duration (at least one).
Motion Resample(const Motion& m, double frame_time, int frames = 0);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_RESAMPLE_H_
