// Per-channel normalization statistics (mean and standard deviation) of feature
// clips, computed over a dataset and stored with a model as a small text file.
#ifndef STYLUS_MOTION_NORMALIZATION_H_
#define STYLUS_MOTION_NORMALIZATION_H_

#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "motion/features.h"

namespace stylus::motion {

struct NormStats {
  std::vector<std::string> names;  // One per channel (may be empty strings).
  std::vector<float> mean;
  std::vector<float> std;  // Always > 0: constant channels get 1.

  int dim() const { return static_cast<int>(mean.size()); }

  // Statistics over every frame of `clips` (all of one width). Channels whose
  // deviation is below `min_std` get std 1, so they pass through unscaled.
  static absl::StatusOr<NormStats> Compute(const std::vector<const FeatureClip*>& clips,
                                           std::vector<std::string> names = {},
                                           float min_std = 1e-4f);

  // In place: (x - mean) / std and its inverse. The clip must be dim() wide.
  void Normalize(FeatureClip* clip) const;
  void Denormalize(FeatureClip* clip) const;
  // One frame of dim() values.
  void Normalize(float* frame) const;
  void Denormalize(float* frame) const;

  // Text format: a "stylus-norm 1 <dim>" line, then "name mean std" per channel.
  std::string Serialize() const;
  // INVALID_ARGUMENT naming `source` and the line for malformed text.
  static absl::StatusOr<NormStats> Parse(const std::string& text, const std::string& source);
  absl::Status Save(const std::string& path) const;
  static absl::StatusOr<NormStats> Load(const std::string& path);
};

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_NORMALIZATION_H_
