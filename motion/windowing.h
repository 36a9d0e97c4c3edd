// Fixed-length windows over a clip, as the models train and infer on them.
#ifndef STYLUS_MOTION_WINDOWING_H_
#define STYLUS_MOTION_WINDOWING_H_

#include <vector>

#include "absl/status/statusor.h"
#include "motion/features.h"

namespace stylus::motion {

struct WindowSpec {
  int length = 32;  // T frames.
  int hop = 24;     // Frames between window starts: T - T/4 for overlap T/4.

  // T with the default overlap of T/4.
  static WindowSpec WithLength(int length) { return {length, length - length / 4}; }
};

// Start frames of the windows over a clip of `frames` frames. With
// `cover_tail`, a last window ending at the clip's end is added when the regular
// ones miss frames there (inference covers every frame; training need not).
// Clips shorter than one window give no windows. INVALID_ARGUMENT for
// length <= 0 or hop <= 0.
absl::StatusOr<std::vector<int>> WindowStarts(int frames, const WindowSpec& spec,
                                              bool cover_tail = false);

// Rows [start, start + length) of `clip` as a new clip.
FeatureClip Slice(const FeatureClip& clip, int start, int length);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_WINDOWING_H_
