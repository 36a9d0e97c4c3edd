// One step of a live package's networks for a batch of streams, in plain
// loops around one matrix product per convolution (internal to model/:
// LibTorch). Per frame the causal networks are small (about 0.4 M
// multiply-adds for the shipped package), so a step through LibTorch's
// modules would cost more in per-operation overhead than in arithmetic;
// here each convolution gathers every stream's window (carried state plus
// the new frame) into one matrix and multiplies it once by the weights.
// Same values as the modules' forward pass over whole clips
// (model/contrastive/live_net.h), up to float rounding.
//
// Thread-safety: Step may be called concurrently (it keeps no state of its
// own between calls).
#ifndef STYLUS_MODEL_CONTRASTIVE_LIVE_ENGINE_H_
#define STYLUS_MODEL_CONTRASTIVE_LIVE_ENGINE_H_

#include <torch/torch.h>

#include <vector>

#include "model/contrastive/contrastive_net.h"
#include "model/contrastive/live_carry.h"

namespace stylus::model {

class LiveEngine {
 public:
  // Copies the weights of `net`'s live content encoder and generator.
  explicit LiveEngine(ContrastiveNetImpl& net);

  // A stream's state before its first frame.
  LiveCarry NewCarry() const;
  // Whether `carry` has this engine's buffers.
  bool Fits(const LiveCarry& carry) const;
  // Runs one frame of each step's stream (ContrastiveModel::StepLive).
  void Step(const std::vector<LiveStep>& steps) const;
  int64_t macs() const;

 private:
  struct Conv {
    int in = 0, out = 0, kernel = 1, dilation = 1;
    int history() const { return (kernel - 1) * dilation; }
    torch::Tensor weight_t;  // (in * kernel, out): column o holds filter o.
    std::vector<float> bias;
  };
  // y (B, out) = conv `slot` of x (B, in), each stream's window completed
  // from its carried buffer, which moves on one frame.
  void RunConv(size_t slot, const std::vector<LiveStep>& steps, const float* x, float* y) const;

  std::vector<Conv> convs_;  // In LiveCarry::buffers order.
  size_t content_convs_ = 0;
  int dim_ = 0, channels_ = 0, content_blocks_ = 0, generator_blocks_ = 0;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CONTRASTIVE_LIVE_ENGINE_H_
