// Feature windows as LibTorch tensors (internal to model/).
#ifndef STYLUS_MODEL_WINDOW_TENSOR_H_
#define STYLUS_MODEL_WINDOW_TENSOR_H_

#include <torch/torch.h>

#include <vector>

#include "motion/features.h"

namespace stylus::model {

// Repeats the last frame until the clip has at least `length` frames.
void PadToLength(motion::FeatureClip* clip, int length);

// (starts.size(), dim, length): the windows of `clip` beginning at `starts`.
torch::Tensor WindowTensor(const motion::FeatureClip& clip, const std::vector<int>& starts,
                           int length);

// x (B, C, T) filtered over time by a Gaussian of `sigma` frames (kernel
// radius ceil(3 sigma), edges repeated): the same shape back.
torch::Tensor SmoothOverTime(const torch::Tensor& x, double sigma);

}  // namespace stylus::model

#endif  // STYLUS_MODEL_WINDOW_TENSOR_H_
