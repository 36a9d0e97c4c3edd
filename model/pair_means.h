// The mean features of each (content, style) label pair of a training set:
// how a take of an action in a style poses on average. Label-guided training
// uses their differences as the posture change a style makes to an action
// (`pair_offset_weight`, docs/contrastive.md, session 13).
#ifndef STYLUS_MODEL_PAIR_MEANS_H_
#define STYLUS_MODEL_PAIR_MEANS_H_

#include <vector>

#include "model/clip_classes.h"
#include "model/training_set.h"

namespace stylus::model {

class PairMeans {
 public:
  PairMeans() = default;
  // Means over every frame of every clip of each pair (normalized features).
  PairMeans(const TrainingSet& data, const ClipClasses& classes);

  int dim() const { return dim_; }
  // Frames of the pair (content, style); 0 when no clip has both labels.
  int frames(int content, int style) const { return frames_[Index(content, style)]; }
  // Writes mean(content, to) - mean(content, from) into `out` (dim values)
  // and returns true when both pairs have frames; false (out untouched)
  // otherwise.
  bool Offset(int content, int from, int to, float* out) const;

 private:
  size_t Index(int content, int style) const {
    return static_cast<size_t>(content) * styles_ + style;
  }
  int styles_ = 0, dim_ = 0;
  std::vector<double> sums_;  // Per pair: dim sums, then divided by frames.
  std::vector<int> frames_;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_PAIR_MEANS_H_
