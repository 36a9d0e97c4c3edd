#include "model/contrastive/live_engine.h"

#include <algorithm>
#include <cmath>

namespace stylus::model {
namespace {

void LeakyRelu(float* x, size_t n) {
  for (size_t i = 0; i < n; ++i) x[i] = x[i] > 0 ? x[i] : 0.2f * x[i];
}

// Each row of x (rows x channels) to zero mean and unit variance.
void FrameNorm(float* x, int rows, int channels) {
  for (int r = 0; r < rows; ++r) {
    float* v = x + static_cast<size_t>(r) * channels;
    double mean = 0, var = 0;
    for (int c = 0; c < channels; ++c) mean += v[c];
    mean /= channels;
    for (int c = 0; c < channels; ++c) var += (v[c] - mean) * (v[c] - mean);
    var /= channels;
    const double inv = 1.0 / std::sqrt(var + 1e-5);
    for (int c = 0; c < channels; ++c) v[c] = static_cast<float>((v[c] - mean) * inv);
  }
}

// x * (1 + scale) + bias, row r's scale and bias from params row r.
void Affine(float* x, int rows, int channels, const std::vector<LiveStep>& steps, size_t offset) {
  for (int r = 0; r < rows; ++r) {
    float* v = x + static_cast<size_t>(r) * channels;
    const float* scale = steps[r].params + offset;
    const float* bias = scale + channels;
    for (int c = 0; c < channels; ++c) v[c] = v[c] * (1 + scale[c]) + bias[c];
  }
}

}  // namespace

LiveEngine::LiveEngine(ContrastiveNetImpl& net) {
  c10::InferenceMode guard;
  auto add = [this](const CausalConv& c) {
    Conv conv;
    conv.in = c->in;
    conv.out = c->out;
    conv.kernel = c->kernel;
    conv.dilation = c->dilation;
    conv.weight_t = c->conv->weight.detach().reshape({c->out, c->in * c->kernel}).t().contiguous();
    const torch::Tensor b = c->conv->bias.detach().contiguous();
    conv.bias.assign(b.data_ptr<float>(), b.data_ptr<float>() + b.numel());
    convs_.push_back(std::move(conv));
  };
  const LiveContentEncoderImpl& enc = *net.live_content;
  add(enc.conv1);
  add(enc.conv2);
  for (const auto& b : *enc.blocks) {
    add(b->as<LiveBlock>()->conv1);
    add(b->as<LiveBlock>()->conv2);
  }
  content_convs_ = convs_.size();
  content_blocks_ = static_cast<int>(enc.blocks->size());
  const LiveGeneratorImpl& gen = *net.live_generator;
  for (const auto& b : *gen.blocks) {
    add(b->as<LiveBlock>()->conv1);
    add(b->as<LiveBlock>()->conv2);
  }
  add(gen.up_conv);
  add(gen.out_conv);
  generator_blocks_ = static_cast<int>(gen.blocks->size());
  channels_ = gen.channels;
  dim_ = convs_.front().in;
}

LiveCarry LiveEngine::NewCarry() const {
  LiveCarry carry;
  for (const Conv& c : convs_)
    carry.buffers.emplace_back(static_cast<size_t>(c.in) * c.history(), 0.f);
  carry.content = content_convs_;
  return carry;
}

bool LiveEngine::Fits(const LiveCarry& carry) const {
  if (carry.buffers.size() != convs_.size()) return false;
  for (size_t i = 0; i < convs_.size(); ++i) {
    if (carry.buffers[i].size() != static_cast<size_t>(convs_[i].in) * convs_[i].history())
      return false;
  }
  return true;
}

int64_t LiveEngine::macs() const {
  int64_t n = 0;
  for (const Conv& c : convs_) n += static_cast<int64_t>(c.in) * c.out * c.kernel;
  return n;
}

void LiveEngine::RunConv(size_t slot, const std::vector<LiveStep>& steps, const float* x,
                         float* y) const {
  const Conv& c = convs_[slot];
  const int64_t rows = static_cast<int64_t>(steps.size()), k = c.kernel, width = c.in * k;
  std::vector<float> windows(static_cast<size_t>(rows) * width);
  for (int64_t r = 0; r < rows; ++r) {
    float* w = windows.data() + r * width;
    std::vector<float>& state = steps[r].carry->buffers[slot];
    const float* in = x + r * c.in;
    // The state holds each channel's last `history` inputs, oldest first;
    // tap t reads the one (k - 1 - t) * dilation frames back. Plain loops:
    // a state is a few frames, too short for a copy call.
    const int64_t d = c.dilation, hist = c.history();
    for (int i = 0; i < c.in; ++i) {
      float* wi = w + i * k;
      float* si = state.data() + i * hist;
      for (int64_t t = 0; t + 1 < k; ++t) wi[t] = si[t * d];
      wi[k - 1] = in[i];
      for (int64_t t = 0; t + 1 < hist; ++t) si[t] = si[t + 1];  // The state moves on one frame.
      if (hist > 0) si[hist - 1] = in[i];
    }
  }
  c10::InferenceMode guard;
  const torch::Tensor a = torch::from_blob(windows.data(), {rows, width});
  torch::Tensor out = torch::from_blob(y, {rows, c.out});
  torch::mm_out(out, a, c.weight_t);
  for (int64_t r = 0; r < rows; ++r) {
    float* v = y + r * c.out;
    for (int o = 0; o < c.out; ++o) v[o] += c.bias[o];
  }
}

void LiveEngine::Step(const std::vector<LiveStep>& steps) const {
  const int rows = static_cast<int>(steps.size()), ch = channels_;
  const size_t n = static_cast<size_t>(rows) * ch;
  std::vector<float> x(static_cast<size_t>(rows) * dim_), h(n), t(n), u(n);
  for (int r = 0; r < rows; ++r)
    std::copy(steps[r].features, steps[r].features + dim_, &x[r * dim_]);
  size_t slot = 0;
  // A residual block on h: conv, norm, [style], LeakyReLU, conv, norm,
  // [style], plus h. `offset`: the block's parameters, or -1 for none.
  auto block = [&](int64_t offset) {
    RunConv(slot++, steps, h.data(), t.data());
    FrameNorm(t.data(), rows, ch);
    if (offset >= 0) Affine(t.data(), rows, ch, steps, static_cast<size_t>(offset));
    LeakyRelu(t.data(), n);
    RunConv(slot++, steps, t.data(), u.data());
    FrameNorm(u.data(), rows, ch);
    if (offset >= 0) Affine(u.data(), rows, ch, steps, static_cast<size_t>(offset) + 2 * ch);
    for (size_t i = 0; i < n; ++i) h[i] += u[i];
  };
  // Content encoder.
  RunConv(slot++, steps, x.data(), t.data());
  LeakyRelu(t.data(), n);
  RunConv(slot++, steps, t.data(), h.data());
  LeakyRelu(h.data(), n);
  for (int b = 0; b < content_blocks_; ++b) block(-1);
  // Generator.
  for (int b = 0; b < generator_blocks_; ++b) block(static_cast<int64_t>(b) * 4 * ch);
  RunConv(slot++, steps, h.data(), t.data());
  LeakyRelu(t.data(), n);
  std::vector<float> out(static_cast<size_t>(rows) * dim_);
  RunConv(slot++, steps, t.data(), out.data());
  for (int r = 0; r < rows; ++r) {
    std::copy(&out[r * dim_], &out[r * dim_] + dim_, steps[r].out);
  }
}

}  // namespace stylus::model
