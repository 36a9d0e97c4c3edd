// The networks and losses of the `cyclic` family (paper 004; internal to
// model/: includes LibTorch). Tensors are (batch, channels, time); the
// network's channels are a subset of the normalized features: joint positions
// (3J), root trajectory (4), foot contacts (4) (CyclicConfig::net_channels).
#ifndef STYLUS_MODEL_CYCLIC_CYCLIC_NET_H_
#define STYLUS_MODEL_CYCLIC_CYCLIC_NET_H_

#include <torch/torch.h>

#include <vector>

#include "model/cyclic/cyclic_config.h"
#include "motion/humanoid.h"
#include "motion/normalization.h"
#include "motion/skeleton.h"

namespace stylus::model {

// The Holden-style convolutional autoencoder (encoder: dropout, conv, ReLU,
// max-pool; decoder: unpool, dropout, conv) and the feed-forward style
// transform that makes it a generator G(C, S) (docs/notes/cyclic.md): the content's
// hidden features, instance-normalized, are modulated by a scale and bias
// computed from the style's hidden statistics (per-channel mean and standard
// deviation over time), passed through two convolutions and added back.
struct CyclicNetImpl : torch::nn::Module {
  CyclicNetImpl(const CyclicConfig& c, int channels);
  torch::Tensor encode(const torch::Tensor& x);  // (B, C, T) -> (B, H, T/2); T even.
  torch::Tensor decode(const torch::Tensor& h);  // (B, H, T/2) -> (B, C, T).
  // (B, H, t) -> (B, 2H, 1): the style code (mean and std over time).
  static torch::Tensor stats(const torch::Tensor& h);
  // With adain_skip: `content` (B, H, t) given, channel by channel, the mean
  // and spread that `skip_stats` ((B, 2H, 1 or t), the tail of a style code)
  // hold. The identity when they are the content's own (SkipStats).
  static torch::Tensor AdaInSkip(const torch::Tensor& content, const torch::Tensor& skip_stats);
  // (B, H, t) -> (B, 2H, 1): per-channel mean and spread, as AdaInSkip uses.
  static torch::Tensor SkipStats(const torch::Tensor& h);
  // The style code of a clip (B, C, T) -> (B, code_size, 1): stats(encode(x))
  // or, with a style network (CyclicConfig::style_dim), its style encoder's
  // (followed, with adain_skip, by SkipStats(encode(x))).
  torch::Tensor code(const torch::Tensor& x);
  // Content hidden features restyled by `style` ((B, code_size, 1), or
  // (B, code_size, t) for a code per hidden step).
  torch::Tensor transform(const torch::Tensor& content, const torch::Tensor& style);
  // The output for restyled hidden features `h` of clip `x` whose own hidden
  // features are `hx`: decode(h), or with `residual` x + decode(h) -
  // decode(hx) (CyclicConfig::residual).
  torch::Tensor output(const torch::Tensor& x, const torch::Tensor& hx, const torch::Tensor& h);
  // G(C, S) = output(C, encode(C), transform(encode(C), code(S))).
  torch::Tensor generate(const torch::Tensor& content, const torch::Tensor& style_clip);

  torch::nn::Dropout enc_drop{nullptr}, dec_drop{nullptr};
  torch::nn::Conv1d enc_conv{nullptr}, dec_conv{nullptr};
  torch::nn::Conv1d style_a{nullptr}, style_b{nullptr};  // 1x1: 2H -> H -> 2H.
  torch::nn::Conv1d mix_a{nullptr}, mix_b{nullptr};      // k3: H -> H -> H.
  // The style network (style_dim > 0 only; then style_a..mix_b are unused
  // and absent): the style encoder (conv k, pool, conv 5, mean over time,
  // 1x1 to style_dim) and per block a 1x1 modulation (style_dim -> 2H) and
  // two k3 convolutions, the first dilated 2^block.
  torch::nn::Conv1d sty_a{nullptr}, sty_b{nullptr}, sty_out{nullptr};
  torch::nn::ModuleList block_mod{nullptr}, block_a{nullptr}, block_b{nullptr};
  int hidden, style_dim;
  bool residual, adain_skip;
};
TORCH_MODULE(CyclicNet);

// The encoder's structure, then a 1x1 conv to one logit per hidden step,
// averaged over time: (B, C, T) -> (B).
struct CyclicCriticImpl : torch::nn::Module {
  CyclicCriticImpl(const CyclicConfig& c, int channels);
  torch::Tensor forward(const torch::Tensor& x);
  torch::nn::Dropout drop{nullptr};
  torch::nn::Conv1d conv{nullptr}, out{nullptr};
};
TORCH_MODULE(CyclicCritic);

// Gram matrices of hidden features: (B, H, t) -> (B, H, H), divided by t.
torch::Tensor Gram(const torch::Tensor& h);

// The kinematic constraints (paper 004 eq. 10-12, plus planted feet), on
// normalized network channels. Positions are measured in leg lengths and
// time in seconds, so the terms do not depend on the skeleton's units.
class KinematicLoss {
 public:
  struct Terms {
    torch::Tensor smooth, bone, traj, foot;
  };
  // `norm`: statistics of the full features; only the network's channels are
  // used.
  KinematicLoss(const motion::Skeleton& skeleton, const motion::HumanoidRoles& roles,
                const motion::NormStats& norm, double frame_time);
  // Each term a scalar for `out` (generated) against `content`, both
  // (B, C, T) normalized network channels.
  Terms Compute(const torch::Tensor& out, const torch::Tensor& content) const;
  // The weighted sum of the terms `config` switches on.
  torch::Tensor Weighted(const Terms& t, const CyclicConfig& config) const;
  // Bone length error alone: mean relative error over bones and frames.
  torch::Tensor BoneError(const torch::Tensor& out) const;

 private:
  // The channels the terms read: positions and path (rotations, when the
  // network has them, come after and are not constrained).
  torch::Tensor Own(const torch::Tensor& x) const;
  torch::Tensor Positions(const torch::Tensor& x) const;  // (B, J, 3, T), leg lengths.
  // Relative bone length errors (B, bones, T) of positions `p`.
  torch::Tensor BoneErrors(const torch::Tensor& p) const;
  torch::Tensor mean_, std_;                              // (1, C, 1) of the network channels.
  torch::Tensor bone_child_, bone_parent_, bone_length_;  // Bones below the pelvis.
  torch::Tensor feet_;  // Left ankle, left toe, right ankle, right toe.
  int joints_;
  double leg_, fps_;
};

// The inference-time kinematic optimization (paper 004 eq. 13): Adam steps
// on the hidden features `h` (changed in place) minimizing the weighted
// kinematic loss of decode(h) against `content`, until it stops falling
// (less than 0.1% better over 10 steps) or after config.kc_iters steps. The
// output judged is decode(h) + `offset` (see CyclicNetImpl::output: zero, or
// x - decode(hx)). The network's parameters must not require gradients.
struct KinematicFit {
  double loss_before = 0, loss_after = 0;
  int steps = 0;
};
KinematicFit OptimizeHidden(CyclicNet& net, const KinematicLoss& loss, const CyclicConfig& config,
                            const torch::Tensor& content, const torch::Tensor& offset,
                            torch::Tensor* h);

// Indices of the network's channels in the full feature layout: joint
// positions (3J), the path (root trajectory 4, foot contacts 4), then with
// `rotations` the joint rotations (4J).
std::vector<int64_t> CyclicChannels(int joints, bool rotations);

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CYCLIC_CYCLIC_NET_H_
