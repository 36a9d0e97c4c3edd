#include "model/contrastive/contrastive_net.h"

#include "model/window_tensor.h"
#include "motion/features.h"

namespace stylus::model {
namespace {

namespace nn = torch::nn;
namespace F = torch::nn::functional;

nn::Conv1d Conv(int in, int out, int kernel, int stride = 1) {
  const int pad = stride == 1 ? kernel / 2 : (kernel - stride) / 2;
  return nn::Conv1d(nn::Conv1dOptions(in, out, kernel).stride(stride).padding(pad));
}

torch::Tensor LeakyRelu(const torch::Tensor& x) {
  return F::leaky_relu(x, F::LeakyReLUFuncOptions().negative_slope(0.2));
}

// Per-sample, per-channel normalization over time, then scale and bias.
torch::Tensor AdaIn(const torch::Tensor& x, const torch::Tensor& scale, const torch::Tensor& bias) {
  const torch::Tensor normalized = (x - x.mean(2, true)) / (x.var(2, false, true) + 1e-5).sqrt();
  return normalized * (1 + scale.unsqueeze(2)) + bias.unsqueeze(2);
}

}  // namespace

ResBlockImpl::ResBlockImpl(int channels, int kernel, bool instance_norm) {
  conv1 = register_module("conv1", Conv(channels, channels, kernel));
  conv2 = register_module("conv2", Conv(channels, channels, kernel));
  if (instance_norm) {
    norm1 = register_module("norm1", nn::InstanceNorm1d(nn::InstanceNorm1dOptions(channels)));
    norm2 = register_module("norm2", nn::InstanceNorm1d(nn::InstanceNorm1dOptions(channels)));
  }
}

torch::Tensor ResBlockImpl::forward(const torch::Tensor& x) {
  torch::Tensor y = conv1->forward(x);
  if (norm1) y = norm1->forward(y);
  y = conv2->forward(LeakyRelu(y));
  if (norm2) y = norm2->forward(y);
  return x + y;
}

EncoderImpl::EncoderImpl(const ContrastiveConfig& c, bool instance_norm) {
  conv1 = register_module("conv1", Conv(c.dim, c.channels, 7));
  conv2 = register_module("conv2", Conv(c.channels, c.channels, 4, 2));
  conv3 = register_module("conv3", Conv(c.channels, c.channels, 7));
  blocks = register_module("blocks", nn::ModuleList());
  for (int i = 0; i < 3; ++i) blocks->push_back(ResBlock(c.channels, c.res_kernel, instance_norm));
}

torch::Tensor EncoderImpl::forward(torch::Tensor x) {
  x = LeakyRelu(conv1->forward(x));
  x = LeakyRelu(conv2->forward(x));
  x = LeakyRelu(conv3->forward(x));
  for (const auto& b : *blocks) x = b->as<ResBlock>()->forward(x);
  return x;
}

BottleneckImpl::BottleneckImpl(int channels, int k, int pool_steps) : pool(pool_steps) {
  down = register_module("down", Conv(channels, k, 1));
  up = register_module("up", Conv(k, channels, 1));
}

torch::Tensor BottleneckImpl::forward(const torch::Tensor& code) {
  torch::Tensor z = down->forward(code);
  z = (z - z.mean(2, true)) / (z.var(2, false, true) + 1e-5).sqrt();
  if (pool > 1) {
    const int64_t steps = z.size(2);
    z = F::avg_pool1d(z, F::AvgPool1dFuncOptions(pool).stride(pool).ceil_mode(true));
    z = F::interpolate(z, F::InterpolateFuncOptions()
                              .size(std::vector<int64_t>{steps})
                              .mode(torch::kLinear)
                              .align_corners(false));
  }
  return up->forward(z);
}

AdaInBlockImpl::AdaInBlockImpl(int c, int kernel) : channels(c) {
  conv1 = register_module("conv1", Conv(c, c, kernel));
  conv2 = register_module("conv2", Conv(c, c, kernel));
}

torch::Tensor AdaInBlockImpl::forward(const torch::Tensor& x, const torch::Tensor& p) {
  const auto parts = p.split(channels, 1);
  torch::Tensor y = LeakyRelu(AdaIn(conv1->forward(x), parts[0], parts[1]));
  y = AdaIn(conv2->forward(y), parts[2], parts[3]);
  return x + y;
}

StyleFilterImpl::StyleFilterImpl(int c, int k) : channels(c), taps(k) {
  kernels = register_module("kernels", nn::Linear(c, c * k));
  torch::NoGradGuard no_grad;
  kernels->weight.zero_();
  kernels->bias.zero_();
}

torch::Tensor StyleFilterImpl::forward(const torch::Tensor& x, const torch::Tensor& style) {
  const int64_t b = x.size(0), t = x.size(2);
  // One group per (window, channel): each window filtered with its own code's kernels.
  const torch::Tensor w = kernels->forward(style).reshape({b * channels, 1, taps});
  const torch::Tensor padded =
      F::pad(x.reshape({1, b * channels, t}),
             F::PadFuncOptions({taps / 2, taps / 2}).mode(torch::kReplicate));
  const torch::Tensor y = F::conv1d(padded, w, F::Conv1dFuncOptions().groups(b * channels));
  return x + y.reshape({b, channels, t});
}

GeneratorImpl::GeneratorImpl(const ContrastiveConfig& c) : channels(c.channels) {
  mlp = register_module("mlp",
                        nn::Sequential(nn::Linear(c.channels, c.channels),
                                       nn::LeakyReLU(nn::LeakyReLUOptions().negative_slope(0.2)),
                                       nn::Linear(c.channels, 4 * 4 * c.channels)));
  blocks = register_module("blocks", nn::ModuleList());
  for (int i = 0; i < 4; ++i) blocks->push_back(AdaInBlock(c.channels, c.res_kernel));
  if (c.style_filter_taps > 0)
    filter = register_module("filter", StyleFilter(c.channels, c.style_filter_taps));
  up_conv = register_module("up_conv", Conv(c.channels, c.channels, 7));
  out_conv = register_module("out_conv", Conv(c.channels, c.dim, 7));
}

torch::Tensor GeneratorImpl::forward(const torch::Tensor& content, const torch::Tensor& style) {
  const auto params = mlp->forward(style).split(4 * channels, 1);
  torch::Tensor x = content;
  for (size_t i = 0; i < blocks->size(); ++i)
    x = blocks[i]->as<AdaInBlock>()->forward(x, params[i]);
  if (filter) x = filter->forward(x, style);
  x = F::interpolate(
      x, F::InterpolateFuncOptions().scale_factor(std::vector<double>{2.0}).mode(torch::kNearest));
  x = LeakyRelu(up_conv->forward(x));
  return out_conv->forward(x);
}

DiscriminatorImpl::DiscriminatorImpl(const ContrastiveConfig& c) {
  const auto lrelu = nn::LeakyReLUOptions().negative_slope(0.2);
  mlp = register_module(
      "mlp", nn::Sequential(nn::Flatten(), nn::Linear(c.dim * c.window, 256), nn::LeakyReLU(lrelu),
                            nn::Linear(256, 128), nn::LeakyReLU(lrelu), nn::Linear(128, 1)));
}

torch::Tensor DiscriminatorImpl::forward(const torch::Tensor& x) {
  return mlp->forward(x).squeeze(1);
}

torch::Tensor FrameChanges(const torch::Tensor& x) {
  const int64_t t = x.size(2);
  const torch::Tensor d = x.slice(2, 1, t) - x.slice(2, 0, t - 1);
  return torch::cat({d.slice(2, 0, 1), d}, 2) * kFrameChangeScale;
}

ContrastiveNetImpl::ContrastiveNetImpl(const ContrastiveConfig& c) {
  frame_residual = c.frame_residual;
  style_from_motion = c.style_from_motion;
  if (c.live) {
    live_content = register_module("live_content", LiveContentEncoder(c));
    style_encoder = register_module("style_encoder", Encoder(c, /*instance_norm=*/false));
    live_generator = register_module("live_generator", LiveGenerator(c));
  } else {
    content_encoder = register_module("content_encoder", Encoder(c, /*instance_norm=*/true));
    if (c.bottleneck_channels > 0) {
      bottleneck = register_module(
          "bottleneck", Bottleneck(c.channels, c.bottleneck_channels, c.bottleneck_pool));
    }
    style_encoder = register_module("style_encoder", Encoder(c, /*instance_norm=*/false));
    generator = register_module("generator", Generator(c));
  }
  nce_w = register_parameter("nce_w", torch::eye(c.channels));
}

torch::Tensor ReconstructionLoss(const torch::Tensor& output, const torch::Tensor& target) {
  return (output - target).abs().mean();
}

torch::Tensor MaskedL1Loss(const torch::Tensor& output, const torch::Tensor& target,
                           const torch::Tensor& mask) {
  return ((output - target).abs() * mask).sum() / (mask.sum() * output.size(0) * output.size(2));
}

torch::Tensor NceLoss(const torch::Tensor& generated, const torch::Tensor& target,
                      const torch::Tensor& w, double temperature) {
  const torch::Tensor q = F::normalize(generated, F::NormalizeFuncOptions().dim(1));  // (B, C, L)
  const torch::Tensor k = F::normalize(target, F::NormalizeFuncOptions().dim(1));
  // logits[b, i, j] = q[b,:,i]^T W k[b,:,j]
  const torch::Tensor logits = torch::einsum("bci,cd,bdj->bij", {q, w, k}) / temperature;
  const int64_t b = logits.size(0), l = logits.size(1);
  const torch::Tensor labels = torch::arange(l).repeat({b});
  return F::cross_entropy(logits.reshape({b * l, l}), labels);
}

torch::Tensor TripletLoss(const torch::Tensor& anchor, const torch::Tensor& positive,
                          const torch::Tensor& negative, double margin) {
  const auto unit = F::NormalizeFuncOptions().dim(1);
  const torch::Tensor a = F::normalize(anchor, unit), p = F::normalize(positive, unit),
                      n = F::normalize(negative, unit);
  return torch::relu((a - p).norm(2, 1) - (a - n).norm(2, 1) + margin).mean();
}

torch::Tensor GeneratorGanLoss(const torch::Tensor& fake_logits) {
  return F::softplus(-fake_logits).mean();
}

torch::Tensor DiscriminatorGanLoss(const torch::Tensor& real_logits,
                                   const torch::Tensor& fake_logits) {
  return F::softplus(-real_logits).mean() + F::softplus(fake_logits).mean();
}

torch::Tensor FinishWindows(const ContrastiveConfig& config, const torch::Tensor& x,
                            torch::Tensor y, double content_detail, bool residual) {
  // Channels [0, path) pose the body; [path, dim) are the root trajectory
  // and foot contacts (motion/features.h).
  const int64_t path = config.dim - motion::FeatureLayout::kPathChannels;
  if (config.smooth_sigma > 0) {
    y.slice(1, 0, path).copy_(SmoothOverTime(y.slice(1, 0, path), config.smooth_sigma));
  }
  if (content_detail > 0) {
    const torch::Tensor pose = x.slice(1, 0, path);
    y.slice(1, 0, path).add_(content_detail * (pose - SmoothOverTime(pose, config.DetailSigma())));
  }
  if (residual) y = y + x;
  // keep_path: the style changes the body, not the content's path.
  if (config.keep_path) y.slice(1, path).copy_(x.slice(1, path));
  return y;
}

}  // namespace stylus::model
