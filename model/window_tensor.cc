#include "model/window_tensor.h"

namespace stylus::model {

void PadToLength(motion::FeatureClip* f, int length) {
  if (f->frames <= 0) return;
  const std::vector<float> last(f->row(f->frames - 1), f->row(f->frames - 1) + f->dim);
  while (f->frames < length) {
    f->values.insert(f->values.end(), last.begin(), last.end());
    ++f->frames;
  }
}

torch::Tensor WindowTensor(const motion::FeatureClip& f, const std::vector<int>& starts,
                           int length) {
  const int d = f.dim;
  torch::Tensor x = torch::empty({static_cast<int64_t>(starts.size()), d, length});
  float* out = x.data_ptr<float>();
  for (size_t w = 0; w < starts.size(); ++w) {
    for (int i = 0; i < length; ++i) {
      const float* row = f.row(starts[w] + i);
      for (int k = 0; k < d; ++k) out[(w * d + k) * length + i] = row[k];
    }
  }
  return x;
}

}  // namespace stylus::model
