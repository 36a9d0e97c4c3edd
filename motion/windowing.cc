#include "motion/windowing.h"

#include <algorithm>

#include "absl/strings/str_cat.h"

namespace stylus::motion {

absl::StatusOr<std::vector<int>> WindowStarts(int frames, const WindowSpec& spec, bool cover_tail) {
  if (spec.length <= 0 || spec.hop <= 0) {
    return absl::InvalidArgumentError(absl::StrCat("window length and hop must be positive, got ",
                                                   spec.length, " and ", spec.hop));
  }
  std::vector<int> starts;
  for (int s = 0; s + spec.length <= frames; s += spec.hop) starts.push_back(s);
  if (cover_tail && !starts.empty() && starts.back() + spec.length < frames) {
    starts.push_back(frames - spec.length);
  }
  return starts;
}

FeatureClip Slice(const FeatureClip& clip, int start, int length) {
  FeatureClip out;
  out.dim = clip.dim;
  out.frames = length;
  out.values.assign(clip.row(start), clip.row(start) + static_cast<size_t>(length) * clip.dim);
  return out;
}

}  // namespace stylus::motion
