#include "model/window_tensor.h"

#include <cmath>

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

torch::Tensor SmoothOverTime(const torch::Tensor& x, double sigma) {
  const int64_t radius = static_cast<int64_t>(std::ceil(3 * sigma));
  if (radius <= 0) return x;
  std::vector<float> taps;
  for (int64_t d = -radius; d <= radius; ++d)
    taps.push_back(static_cast<float>(std::exp(-0.5 * d * d / (sigma * sigma))));
  torch::Tensor kernel = torch::tensor(taps).view({1, 1, -1});
  kernel = kernel / kernel.sum();
  const int64_t b = x.size(0), c = x.size(1), t = x.size(2);
  namespace F = torch::nn::functional;
  const torch::Tensor padded =
      F::pad(x.reshape({b * c, 1, t}),
             F::PadFuncOptions({radius, radius}).mode(torch::kReplicate));
  return F::conv1d(padded, kernel).view({b, c, t});
}

}  // namespace stylus::model
