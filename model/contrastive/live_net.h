// The causal networks of a live `contrastive` package (config `live`,
// docs/families.md "Live packages"; internal to model/: includes LibTorch).
//
// Paper 000's content encoder and generator made causal: every convolution
// sees only its current and past inputs (zeros before a clip's first
// frame), the normalizations are per frame (over channels, not over time),
// and the content path runs at the full frame rate. The content encoder's
// input is the clip's features shifted by `lookahead - 1` frames (the
// features themselves look one frame ahead: motion/features.h), so output
// frame t depends on input frames up to t + lookahead and nothing later.
//
// Whole clips run as one pass (`forward`); a stream runs one frame per step
// with each convolution's last inputs carried (model/contrastive/
// live_engine.h), and gets the same values as the whole clip up to float
// rounding.
#ifndef STYLUS_MODEL_CONTRASTIVE_LIVE_NET_H_
#define STYLUS_MODEL_CONTRASTIVE_LIVE_NET_H_

#include <torch/torch.h>

#include <vector>

#include "model/contrastive/contrastive_config.h"

namespace stylus::model {

// A 1-D convolution whose output t sees inputs t - (kernel - 1) * dilation,
// ..., t - dilation, t.
struct CausalConvImpl : torch::nn::Module {
  CausalConvImpl(int in, int out, int kernel, int dilation = 1);
  // (B, in, T) -> (B, out, T); zeros stand for the inputs before the first.
  torch::Tensor forward(const torch::Tensor& x);
  // Past frames of input the convolution needs: (kernel - 1) * dilation.
  int history() const { return (kernel - 1) * dilation; }
  torch::nn::Conv1d conv{nullptr};
  int in, out, kernel, dilation;
};
TORCH_MODULE(CausalConv);

// conv -> per-frame norm -> LeakyReLU -> conv -> per-frame norm, plus the
// input; with `styled`, each norm is followed by the style's scale and bias
// (AdaIN made per frame).
struct LiveBlockImpl : torch::nn::Module {
  LiveBlockImpl(int channels, int kernel, int dilation = 1);
  // params: (B, 4C) or (B, 4C, T): scale1, bias1, scale2, bias2; undefined
  // for the content encoder's unstyled blocks.
  torch::Tensor forward(const torch::Tensor& x, const torch::Tensor& params);
  CausalConv conv1{nullptr}, conv2{nullptr};
  int channels;
};
TORCH_MODULE(LiveBlock);

// Features (B, dim, T) -> content codes (B, C, T), frame t's from features
// up to t + lookahead - 1.
struct LiveContentEncoderImpl : torch::nn::Module {
  explicit LiveContentEncoderImpl(const ContrastiveConfig& c);
  torch::Tensor forward(const torch::Tensor& x);
  // Feature frames the codes trail the input by (lookahead - 1).
  int shift() const { return shift_; }
  CausalConv conv1{nullptr}, conv2{nullptr};
  torch::nn::ModuleList blocks;
  int shift_;
};
TORCH_MODULE(LiveContentEncoder);

// Content codes (B, C, T) and a style code per clip (B, C) or per frame
// (B, C, T) -> features (B, dim, T).
struct LiveGeneratorImpl : torch::nn::Module {
  explicit LiveGeneratorImpl(const ContrastiveConfig& c);
  torch::Tensor forward(const torch::Tensor& content, const torch::Tensor& style);
  // The AdaIN parameters of style codes (B, C): (B, blocks * 4C).
  torch::Tensor Params(const torch::Tensor& style);
  torch::nn::Sequential mlp{nullptr};
  torch::nn::ModuleList blocks;
  CausalConv up_conv{nullptr}, out_conv{nullptr};
  int channels;
};
TORCH_MODULE(LiveGenerator);

// Blocks per network (the offline encoder has 3, its generator 4: the live
// path runs at the full frame rate, so it is kept lighter).
inline constexpr int kLiveContentBlocks = 2;
inline constexpr int kLiveGeneratorBlocks = 3;

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CONTRASTIVE_LIVE_NET_H_
