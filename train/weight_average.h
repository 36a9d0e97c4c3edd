// Weight averaging for training (internal to model/: LibTorch): the package
// of a run can hold the mean of the generator's weights sampled every few
// iterations late in training (stochastic weight averaging, Izmailov et al.
// 2018) instead of the last iteration's. GAN-style fine-tunes wander from
// checkpoint to checkpoint; their mean is steadier (docs/notes/contrastive.md).
#ifndef STYLUS_TRAIN_WEIGHT_AVERAGE_H_
#define STYLUS_TRAIN_WEIGHT_AVERAGE_H_

#include <torch/torch.h>

#include <vector>

#include "absl/status/status.h"
#include "absl/strings/str_cat.h"

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

// A trainer's running mean of its network `Net` (a module holder).
// Default-constructed it is off. Build it before the run seeds torch's
// generator: the mean's own initial weights then draw nothing from it, and
// a run trains the same weights with averaging as without.
template <typename Net>
class WeightAverage {
 public:
  WeightAverage() = default;
  // From iteration `from` (> 0) on, every `every`; `mean` is a network of
  // the trained one's shape.
  WeightAverage(int from, int every, Net mean) : from_(from), every_(every), mean_(mean) {}

  bool on() const { return from_ > 0; }
  // After iteration `done` (1-based) of `live`.
  void Update(int done, const Net& live) {
    if (IsAveragedIteration(done, from_, every_))
      FoldIntoAverage(*live, mean_.get(), AveragedSamples(done, from_, every_));
  }
  // What the package holds after `done` iterations: the mean once it holds
  // a sample, else `live`.
  Net* ForPackage(int done, Net* live) {
    return AveragedSamples(done, from_, every_) > 0 ? &mean_ : live;
  }
  Net* mean() { return &mean_; }  // For the checkpoint.

 private:
  int from_ = 0, every_ = 1;
  Net mean_{nullptr};
};

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_WEIGHT_AVERAGE_H_
