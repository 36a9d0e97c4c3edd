#include "model/pair_means.h"

namespace stylus::model {

PairMeans::PairMeans(const TrainingSet& data, const ClipClasses& classes)
    : styles_(static_cast<int>(classes.styles.size())), dim_(data.dim()) {
  const size_t pairs = classes.contents.size() * classes.styles.size();
  sums_.assign(pairs * dim_, 0);
  frames_.assign(pairs, 0);
  for (size_t c = 0; c < data.clips.size(); ++c) {
    const size_t p = Index(classes.content_of[c], classes.style_of[c]);
    const motion::FeatureClip& clip = data.clips[c];
    for (int f = 0; f < clip.frames; ++f) {
      const float* row = clip.row(f);
      for (int k = 0; k < dim_; ++k) sums_[p * dim_ + k] += row[k];
    }
    frames_[p] += clip.frames;
  }
  for (size_t p = 0; p < pairs; ++p) {
    if (frames_[p] == 0) continue;
    for (int k = 0; k < dim_; ++k) sums_[p * dim_ + k] /= frames_[p];
  }
}

bool PairMeans::Offset(int content, int from, int to, float* out) const {
  const size_t a = Index(content, from), b = Index(content, to);
  if (frames_.empty() || frames_[a] == 0 || frames_[b] == 0) return false;
  for (int k = 0; k < dim_; ++k) {
    out[k] = static_cast<float>(sums_[b * dim_ + k] - sums_[a * dim_ + k]);
  }
  return true;
}

}  // namespace stylus::model
