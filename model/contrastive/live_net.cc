#include "model/contrastive/live_net.h"

namespace stylus::model {
namespace {

namespace nn = torch::nn;
namespace F = torch::nn::functional;

torch::Tensor Lrelu(const torch::Tensor& x) {
  return F::leaky_relu(x, F::LeakyReLUFuncOptions().negative_slope(0.2));
}

// Each frame's channels to zero mean and unit variance (dim 1 of (B, C, T)).
torch::Tensor FrameNorm(const torch::Tensor& x) {
  return (x - x.mean(1, true)) / (x.var(1, false, true) + 1e-5).sqrt();
}

// scale/bias (B, C) or (B, C, T) applied to x (B, C, T).
torch::Tensor Affine(const torch::Tensor& x, const torch::Tensor& scale,
                     const torch::Tensor& bias) {
  if (scale.dim() == 2) return x * (1 + scale.unsqueeze(2)) + bias.unsqueeze(2);
  return x * (1 + scale) + bias;
}

}  // namespace

CausalConvImpl::CausalConvImpl(int in_channels, int out_channels, int k, int d)
    : in(in_channels), out(out_channels), kernel(k), dilation(d) {
  conv = register_module("conv", nn::Conv1d(nn::Conv1dOptions(in, out, kernel).dilation(dilation)));
}

torch::Tensor CausalConvImpl::forward(const torch::Tensor& x) {
  if (history() == 0) return conv->forward(x);
  return conv->forward(F::pad(x, F::PadFuncOptions({history(), 0})));
}

LiveBlockImpl::LiveBlockImpl(int c, int kernel, int dilation) : channels(c) {
  conv1 = register_module("conv1", CausalConv(c, c, kernel, dilation));
  conv2 = register_module("conv2", CausalConv(c, c, kernel, dilation));
}

torch::Tensor LiveBlockImpl::forward(const torch::Tensor& x, const torch::Tensor& p) {
  torch::Tensor y = FrameNorm(conv1->forward(x));
  std::vector<torch::Tensor> parts;
  if (p.defined()) {
    parts = p.split(channels, 1);
    y = Affine(y, parts[0], parts[1]);
  }
  y = FrameNorm(conv2->forward(Lrelu(y)));
  if (p.defined()) y = Affine(y, parts[2], parts[3]);
  return x + y;
}

LiveContentEncoderImpl::LiveContentEncoderImpl(const ContrastiveConfig& c)
    : shift_(c.lookahead - 1) {
  conv1 = register_module("conv1", CausalConv(c.dim, c.channels, c.res_kernel));
  conv2 = register_module("conv2", CausalConv(c.channels, c.channels, c.res_kernel));
  blocks = register_module("blocks", nn::ModuleList());
  for (int i = 0, d = 1; i < kLiveContentBlocks; ++i, d *= c.dilation_growth)
    blocks->push_back(LiveBlock(c.channels, c.res_kernel, d));
}

torch::Tensor LiveContentEncoderImpl::forward(const torch::Tensor& x) {
  const int64_t frames = x.size(2);
  // The last frames' look-ahead, as at the end of a stream: the last frame
  // repeated.
  torch::Tensor y =
      shift_ > 0 ? F::pad(x, F::PadFuncOptions({0, shift_}).mode(torch::kReplicate)) : x;
  y = Lrelu(conv1->forward(y));
  y = Lrelu(conv2->forward(y));
  for (const auto& b : *blocks) y = b->as<LiveBlock>()->forward(y, torch::Tensor());
  return y.narrow(2, shift_, frames);
}

LiveGeneratorImpl::LiveGeneratorImpl(const ContrastiveConfig& c) : channels(c.channels) {
  mlp = register_module(
      "mlp", nn::Sequential(nn::Linear(c.channels, c.channels),
                            nn::LeakyReLU(nn::LeakyReLUOptions().negative_slope(0.2)),
                            nn::Linear(c.channels, kLiveGeneratorBlocks * 4 * c.channels)));
  blocks = register_module("blocks", nn::ModuleList());
  for (int i = 0, d = 1; i < kLiveGeneratorBlocks; ++i, d *= c.dilation_growth)
    blocks->push_back(LiveBlock(c.channels, c.res_kernel, d));
  up_conv = register_module("up_conv", CausalConv(c.channels, c.channels, c.res_kernel));
  out_conv = register_module("out_conv", CausalConv(c.channels, c.dim, c.res_kernel));
}

torch::Tensor LiveGeneratorImpl::Params(const torch::Tensor& style) { return mlp->forward(style); }

torch::Tensor LiveGeneratorImpl::forward(const torch::Tensor& content, const torch::Tensor& style) {
  torch::Tensor params;
  if (style.dim() == 2) {
    params = Params(style);
  } else {  // (B, C, T): one code per frame.
    const int64_t b = style.size(0), t = style.size(2);
    params = Params(style.permute({0, 2, 1}).reshape({b * t, channels}))
                 .reshape({b, t, -1})
                 .permute({0, 2, 1});
  }
  const auto per_block = params.split(4 * channels, 1);
  torch::Tensor x = content;
  for (size_t i = 0; i < blocks->size(); ++i)
    x = blocks[i]->as<LiveBlock>()->forward(x, per_block[i]);
  x = Lrelu(up_conv->forward(x));
  return out_conv->forward(x);
}

}  // namespace stylus::model
