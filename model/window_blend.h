// Cross-fading of overlapping output windows into one feature sequence: each
// window's frames are weighted by linear ramps over the overlaps with its
// neighbours, and every frame is the weighted mean of the windows covering it.
// Used by whole-clip transfer and by streaming, so both blend alike.
#ifndef STYLUS_MODEL_WINDOW_BLEND_H_
#define STYLUS_MODEL_WINDOW_BLEND_H_

#include <cstdint>
#include <deque>
#include <vector>

#include "motion/features.h"

namespace stylus::model {

class WindowBlender {
 public:
  // Windows of `window` frames overlapping by `overlap` frames, `dim` channels.
  WindowBlender(int window, int overlap, int dim);

  // Adds the output window that starts at frame `start` (frames before the
  // first one not yet taken are ignored). `values` is (dim, window), channel
  // major, as the network writes it.
  void Add(int64_t start, const float* values);

  // Frames [taken(), end) as a clip (the weighted means), which are then
  // dropped. Frames no window has covered come out as zeros.
  motion::FeatureClip Take(int64_t end);
  int64_t taken() const { return first_; }

 private:
  int window_, overlap_, dim_;
  int64_t first_ = 0;  // Index of the first frame still held.
  std::deque<std::vector<float>> sums_;
  std::deque<float> weights_;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_WINDOW_BLEND_H_
