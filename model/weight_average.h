// Weight averaging for training (internal to model/: LibTorch): the package
// of a run can hold the mean of the generator's weights sampled every few
// iterations late in training (stochastic weight averaging, Izmailov et al.
// 2018) instead of the last iteration's. GAN-style fine-tunes wander from
// checkpoint to checkpoint; their mean is steadier (docs/contrastive.md).
#ifndef STYLUS_MODEL_WEIGHT_AVERAGE_H_
#define STYLUS_MODEL_WEIGHT_AVERAGE_H_

#include <torch/torch.h>

#include <vector>

namespace stylus::model {

// How many samples a run averaging every `every` iterations from iteration
// `from` on (0: off) holds after `done` iterations.
inline int AveragedSamples(int done, int from, int every) {
  if (from <= 0 || every <= 0 || done < from) return 0;
  return (done - from) / every + 1;
}

// Whether iteration `done` (1-based) is one such a run samples.
inline bool IsAveragedIteration(int done, int from, int every) {
  return from > 0 && every > 0 && done >= from && (done - from) % every == 0;
}

// Folds the parameters and floating-point buffers of `net` into `average`
// (a network of the same shape) as its `count`-th sample: the first copies
// them, the n-th moves the mean 1/n of the way.
inline void FoldIntoAverage(const torch::nn::Module& net, torch::nn::Module* average, int count) {
  torch::NoGradGuard no_grad;
  const auto fold = [count](const std::vector<torch::Tensor>& src, std::vector<torch::Tensor> dst) {
    for (size_t i = 0; i < src.size() && i < dst.size(); ++i) {
      if (count <= 1 || !dst[i].is_floating_point()) {
        dst[i].copy_(src[i]);
      } else {
        dst[i].mul_((count - 1.0) / count).add_(src[i], 1.0 / count);
      }
    }
  };
  fold(net.parameters(), average->parameters());
  fold(net.buffers(), average->buffers());
}

}  // namespace stylus::model

#endif  // STYLUS_MODEL_WEIGHT_AVERAGE_H_
