#include "model/cyclic/cyclic_net.h"

#include <algorithm>
#include <numeric>

#include "motion/features.h"

namespace stylus::model {

namespace nn = torch::nn;

std::vector<int64_t> CyclicChannels(int joints, bool rotations) {
  const motion::FeatureLayout layout(joints);
  std::vector<int64_t> channels(3 * joints);
  std::iota(channels.begin(), channels.end(), 0);
  for (int c = 0; c < motion::FeatureLayout::kPathChannels; ++c)
    channels.push_back(layout.trajectory() + c);
  if (rotations) {
    for (int c = 0; c < 4 * joints; ++c) channels.push_back(layout.rotation(0) + c);
  }
  return channels;
}

CyclicNetImpl::CyclicNetImpl(const CyclicConfig& c, int channels)
    : hidden(c.hidden), style_dim(c.style_dim), residual(c.residual), adain_skip(c.adain_skip) {
  const int pad = c.kernel / 2;
  enc_drop = register_module("enc_drop", nn::Dropout(c.dropout));
  enc_conv = register_module(
      "enc_conv", nn::Conv1d(nn::Conv1dOptions(channels, c.hidden, c.kernel).padding(pad)));
  dec_drop = register_module("dec_drop", nn::Dropout(c.dropout));
  dec_conv = register_module(
      "dec_conv", nn::Conv1d(nn::Conv1dOptions(c.hidden, channels, c.kernel).padding(pad)));
  torch::NoGradGuard no_grad;
  if (style_dim > 0) {
    sty_a = register_module(
        "sty_a", nn::Conv1d(nn::Conv1dOptions(channels, c.hidden, c.kernel).padding(pad)));
    sty_b =
        register_module("sty_b", nn::Conv1d(nn::Conv1dOptions(c.hidden, c.hidden, 5).padding(2)));
    sty_out = register_module("sty_out", nn::Conv1d(nn::Conv1dOptions(c.hidden, style_dim, 1)));
    block_mod = register_module("block_mod", nn::ModuleList());
    block_a = register_module("block_a", nn::ModuleList());
    block_b = register_module("block_b", nn::ModuleList());
    for (int b = 0; b < c.blocks; ++b) {
      const int dilation = 1 << std::min(b, 4);
      block_mod->push_back(nn::Conv1d(nn::Conv1dOptions(style_dim, 2 * c.hidden, 1)));
      block_a->push_back(nn::Conv1d(
          nn::Conv1dOptions(c.hidden, c.hidden, 3).padding(dilation).dilation(dilation)));
      nn::Conv1d last(nn::Conv1dOptions(c.hidden, c.hidden, 3).padding(1));
      // Each block starts near the identity: G(C, S) = autoencoder(C).
      last->weight.mul_(0.1);
      last->bias.zero_();
      block_b->push_back(last);
    }
    return;
  }
  style_a = register_module("style_a", nn::Conv1d(nn::Conv1dOptions(2 * c.hidden, c.hidden, 1)));
  style_b = register_module("style_b", nn::Conv1d(nn::Conv1dOptions(c.hidden, 2 * c.hidden, 1)));
  mix_a = register_module("mix_a", nn::Conv1d(nn::Conv1dOptions(c.hidden, c.hidden, 3).padding(1)));
  mix_b = register_module("mix_b", nn::Conv1d(nn::Conv1dOptions(c.hidden, c.hidden, 3).padding(1)));
  // The transform starts as the identity: G(C, S) = autoencoder(C).
  mix_b->weight.mul_(0.1);
  mix_b->bias.zero_();
}

torch::Tensor CyclicNetImpl::encode(const torch::Tensor& x) {
  return torch::max_pool1d(torch::relu(enc_conv(enc_drop(x))), 2);
}

torch::Tensor CyclicNetImpl::decode(const torch::Tensor& h) {
  return dec_conv(dec_drop(torch::repeat_interleave(h, 2, /*dim=*/2)));
}

torch::Tensor CyclicNetImpl::stats(const torch::Tensor& h) {
  const torch::Tensor mean = h.mean(2, /*keepdim=*/true);
  const torch::Tensor var = (h - mean).pow(2).mean(2, /*keepdim=*/true);
  return torch::cat({mean, (var + 1e-5).sqrt()}, 1);
}

namespace {

// Each channel of `h` (B, H, t) normalized over time. A generous epsilon:
// ReLU features that barely move over a clip would otherwise be blown up
// (and with them the gradients).
torch::Tensor InstanceNormalize(const torch::Tensor& h) {
  const torch::Tensor mean = h.mean(2, true);
  const torch::Tensor sd = ((h - mean).pow(2).mean(2, true) + 1e-2).sqrt();
  return (h - mean) / sd;
}

// The variance floor of the normalized skip: small enough that a clip's own
// statistics give back its features (to 1e-5), large enough that a channel
// which barely moves over a clip is not blown up into noise.
constexpr double kSkipVarianceFloor = 1e-3;

}  // namespace

torch::Tensor CyclicNetImpl::SkipStats(const torch::Tensor& h) {
  const torch::Tensor mean = h.mean(2, /*keepdim=*/true);
  const torch::Tensor var = (h - mean).pow(2).mean(2, /*keepdim=*/true);
  return torch::cat({mean, (var + kSkipVarianceFloor).sqrt()}, 1);
}

torch::Tensor CyclicNetImpl::AdaInSkip(const torch::Tensor& content,
                                       const torch::Tensor& skip_stats) {
  const int64_t h = content.size(1);
  const torch::Tensor own = SkipStats(content);
  const torch::Tensor normalized = (content - own.slice(1, 0, h)) / own.slice(1, h, 2 * h);
  return normalized * skip_stats.slice(1, h, 2 * h) + skip_stats.slice(1, 0, h);
}

torch::Tensor CyclicNetImpl::code(const torch::Tensor& x) {
  if (style_dim == 0) return stats(encode(x));
  const torch::Tensor h = torch::max_pool1d(torch::leaky_relu(sty_a(x), 0.2), 2);
  const torch::Tensor code = sty_out(torch::leaky_relu(sty_b(h), 0.2).mean(2, /*keepdim=*/true));
  return adain_skip ? torch::cat({code, SkipStats(encode(x))}, 1) : code;
}

torch::Tensor CyclicNetImpl::transform(const torch::Tensor& content, const torch::Tensor& style) {
  if (style_dim > 0) {
    torch::Tensor h = content;
    torch::Tensor code = style;
    if (adain_skip) {
      h = AdaInSkip(content, style.slice(1, style_dim, style.size(1)));
      code = style.slice(1, 0, style_dim);
    }
    for (size_t b = 0; b < block_mod->size(); ++b) {
      const torch::Tensor p = block_mod[b]->as<nn::Conv1d>()->forward(code);
      const torch::Tensor scale = p.slice(1, 0, hidden), bias = p.slice(1, hidden, 2 * hidden);
      const torch::Tensor m = torch::leaky_relu((1 + scale) * InstanceNormalize(h) + bias, 0.2);
      h = h + block_b[b]->as<nn::Conv1d>()->forward(
                  torch::leaky_relu(block_a[b]->as<nn::Conv1d>()->forward(m), 0.2));
    }
    return h;
  }
  const torch::Tensor p = style_b(torch::leaky_relu(style_a(style), 0.2));
  const torch::Tensor scale = p.slice(1, 0, hidden), bias = p.slice(1, hidden, 2 * hidden);
  const torch::Tensor n = InstanceNormalize(content);
  return content + mix_b(torch::leaky_relu(mix_a((1 + scale) * n + bias), 0.2));
}

torch::Tensor CyclicNetImpl::output(const torch::Tensor& x, const torch::Tensor& hx,
                                    const torch::Tensor& h) {
  return residual ? x + decode(h) - decode(hx) : decode(h);
}

torch::Tensor CyclicNetImpl::generate(const torch::Tensor& content,
                                      const torch::Tensor& style_clip) {
  const torch::Tensor hc = encode(content);
  return output(content, hc, transform(hc, code(style_clip)));
}

CyclicCriticImpl::CyclicCriticImpl(const CyclicConfig& c, int channels) {
  drop = register_module("drop", nn::Dropout(c.dropout));
  conv = register_module(
      "conv", nn::Conv1d(nn::Conv1dOptions(channels, c.hidden, c.kernel).padding(c.kernel / 2)));
  out = register_module("out", nn::Conv1d(nn::Conv1dOptions(c.hidden, 1, 1)));
}

torch::Tensor CyclicCriticImpl::forward(const torch::Tensor& x) {
  const torch::Tensor h = torch::max_pool1d(torch::leaky_relu(conv(drop(x)), 0.2), 2);
  return out(h).mean({1, 2});
}

torch::Tensor Gram(const torch::Tensor& h) {
  return torch::bmm(h, h.transpose(1, 2)) / static_cast<double>(h.size(2));
}

KinematicLoss::KinematicLoss(const motion::Skeleton& skeleton, const motion::HumanoidRoles& roles,
                             const motion::NormStats& norm, double frame_time)
    : joints_(skeleton.num_joints()), leg_(roles.leg_length), fps_(1.0 / frame_time) {
  const std::vector<int64_t> channels = CyclicChannels(joints_, /*rotations=*/false);
  std::vector<float> mean, sd;
  for (int64_t c : channels) mean.push_back(norm.mean[c]), sd.push_back(norm.std[c]);
  const int64_t n = static_cast<int64_t>(channels.size());
  mean_ = torch::tensor(mean).view({1, n, 1});
  std_ = torch::tensor(sd).view({1, n, 1});
  std::vector<bool> below(joints_, false);
  below[roles.pelvis] = true;
  std::vector<int64_t> child, parent;
  std::vector<float> length;
  for (int j = roles.pelvis + 1; j < joints_; ++j) {
    const int p = skeleton.joint(j).parent;
    below[j] = p >= 0 && below[p];
    const double l = motion::Norm(skeleton.joint(j).offset);
    if (!below[j] || l < 1e-6 * leg_) continue;
    child.push_back(j), parent.push_back(p), length.push_back(static_cast<float>(l / leg_));
  }
  bone_child_ = torch::tensor(child);
  bone_parent_ = torch::tensor(parent);
  bone_length_ = torch::tensor(length).view({1, -1, 1});
  feet_ = torch::tensor(
      std::vector<int64_t>{roles.left_ankle, roles.left_toe, roles.right_ankle, roles.right_toe});
}

torch::Tensor KinematicLoss::Own(const torch::Tensor& x) const {
  return x.slice(1, 0, mean_.size(1));
}

torch::Tensor KinematicLoss::Positions(const torch::Tensor& x) const {
  const torch::Tensor real = Own(x) * std_ + mean_;
  return real.slice(1, 0, 3 * joints_).reshape({x.size(0), joints_, 3, x.size(2)}) / leg_;
}

torch::Tensor KinematicLoss::BoneErrors(const torch::Tensor& p) const {
  const torch::Tensor d = (p.index_select(1, bone_child_) - p.index_select(1, bone_parent_))
                              .pow(2)
                              .sum(2)
                              .add(1e-12)
                              .sqrt();
  return (d - bone_length_) / bone_length_;
}

torch::Tensor KinematicLoss::BoneError(const torch::Tensor& out) const {
  return BoneErrors(Positions(out)).abs().mean();
}

KinematicLoss::Terms KinematicLoss::Compute(const torch::Tensor& out,
                                            const torch::Tensor& content) const {
  Terms t;
  const torch::Tensor po = Positions(out), pc = Positions(content);
  t.bone = BoneErrors(po).pow(2).mean();  // Bone length (eq. 11), relative.
  // Smoothness (eq. 10): squared joint accelerations (leg lengths/s^2, in
  // units of 10) beyond the content's own; one-sided, so the output may be
  // smoother than the content but not jerkier.
  auto accel2 = [&](const torch::Tensor& p) {
    const int64_t n = p.size(3);
    const torch::Tensor a =
        (p.slice(3, 2, n) - 2 * p.slice(3, 1, n - 1) + p.slice(3, 0, n - 2)) * (fps_ * fps_ / 10);
    return a.pow(2).sum(2);
  };
  t.smooth = torch::relu(accel2(po) - accel2(pc)).mean();
  // Trajectory (eq. 12): root planar velocity, yaw rate and vertical velocity
  // against the content's, in normalized units.
  const int64_t tr = 3 * joints_;
  t.traj = (out.slice(1, tr, tr + 4) - content.slice(1, tr, tr + 4)).pow(2).mean();
  // Planted feet: where the content's foot is in contact (in this frame and
  // the next), the output foot's horizontal velocity in the character's frame
  // equals the content's (leg lengths/s), so with the content's trajectory
  // it stays on the ground where the content's does.
  const torch::Tensor contact = ((Own(content) * std_ + mean_).slice(1, tr + 4, tr + 8) > 0.5)
                                    .to(torch::kFloat32);  // (B,4,T)
  const int64_t n = out.size(2);
  const torch::Tensor both = contact.slice(2, 0, n - 1) * contact.slice(2, 1, n);
  auto foot_velocity = [&](const torch::Tensor& p) {
    const torch::Tensor f = p.index_select(1, feet_);  // (B, 4, 3, T)
    const torch::Tensor v = (f.slice(3, 1, n) - f.slice(3, 0, n - 1)) * fps_;
    return torch::stack({v.select(2, 0), v.select(2, 2)}, 2);  // (B, 4, 2, T-1)
  };
  const torch::Tensor dv = (foot_velocity(po) - foot_velocity(pc)).pow(2).sum(2);
  t.foot = (dv * both).sum() / both.sum().clamp_min(1.0);
  return t;
}

torch::Tensor KinematicLoss::Weighted(const Terms& t, const CyclicConfig& c) const {
  return c.smooth_weight * t.smooth + c.bone_weight * t.bone + c.traj_weight * t.traj +
         c.foot_weight * t.foot;
}

KinematicFit OptimizeHidden(CyclicNet& net, const KinematicLoss& loss, const CyclicConfig& config,
                            const torch::Tensor& content, const torch::Tensor& offset,
                            torch::Tensor* h) {
  // Gradient descent with a backtracking step: each step moves h along the
  // gradient, scaled so its root-mean-square is `step` per unit, and is kept
  // only if the loss falls (then the step grows by 20%; otherwise it halves).
  // Unlike Adam, whose per-unit normalization moves units with negligible
  // gradients as far as the others, this follows the gradient's direction,
  // and the loss never rises.
  torch::AutoGradMode grad(true);
  auto evaluate = [&](const torch::Tensor& x) {
    return loss.Weighted(loss.Compute(net->decode(x) + offset, content), config);
  };
  torch::Tensor x = h->detach().clone().requires_grad_(true);
  torch::Tensor value = evaluate(x);
  KinematicFit fit;
  fit.loss_before = value.item<double>();
  double current = fit.loss_before, window_start = current, step = config.kc_lr;
  for (fit.steps = 0; fit.steps < config.kc_iters && step > 1e-6; ++fit.steps) {
    const torch::Tensor g = torch::autograd::grad({value}, {x})[0];
    const double rms = g.pow(2).mean().sqrt().item<double>();
    if (!(rms > 1e-12)) break;
    torch::Tensor candidate = (x.detach() - (step / rms) * g).requires_grad_(true);
    torch::Tensor candidate_value = evaluate(candidate);
    const double c = candidate_value.item<double>();
    if (c < current) {
      x = candidate, value = candidate_value, current = c;
      step *= 1.2;
    } else {
      step *= 0.5;
      value = evaluate(x);  // A fresh graph for the next gradient.
    }
    if ((fit.steps + 1) % 10 == 0) {
      if (current > window_start * (1 - 1e-3)) break;
      window_start = current;
    }
  }
  fit.loss_after = current;
  *h = x.detach();
  return fit;
}

}  // namespace stylus::model
