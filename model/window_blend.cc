#include "model/window_blend.h"

#include <algorithm>

namespace stylus::model {

WindowBlender::WindowBlender(int window, int overlap, int dim)
    : window_(window), overlap_(overlap), dim_(dim) {}

void WindowBlender::Add(int64_t start, const float* values) {
  const int64_t end = start + window_;
  while (first_ + static_cast<int64_t>(sums_.size()) < end) {
    sums_.emplace_back(dim_, 0.f);
    weights_.push_back(0.f);
  }
  for (int i = 0; i < window_; ++i) {
    const int64_t f = start + i;
    if (f < first_) continue;
    const float fade = std::min({1.f, (i + 1.f) / (overlap_ + 1.f), (window_ - i) / (overlap_ + 1.f)});
    std::vector<float>& row = sums_[f - first_];
    for (int k = 0; k < dim_; ++k) row[k] += fade * values[static_cast<size_t>(k) * window_ + i];
    weights_[f - first_] += fade;
  }
}

motion::FeatureClip WindowBlender::Take(int64_t end) {
  motion::FeatureClip out;
  out.dim = dim_;
  out.frames = static_cast<int>(std::max<int64_t>(0, end - first_));
  out.values.assign(static_cast<size_t>(out.frames) * dim_, 0.f);
  for (int f = 0; f < out.frames; ++f) {
    if (sums_.empty()) break;
    const float w = weights_.front();
    if (w > 0) {
      for (int k = 0; k < dim_; ++k) out.row(f)[k] = sums_.front()[k] / w;
    }
    sums_.pop_front();
    weights_.pop_front();
  }
  first_ = std::max(first_, end);
  return out;
}

}  // namespace stylus::model
