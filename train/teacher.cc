#include "train/teacher.h"

#include "absl/strings/str_cat.h"
#include "model/weights_io.h"
#include "model/window_tensor.h"
#include "motion/features.h"

namespace stylus::model {

absl::StatusOr<Teacher> Teacher::Load(const std::string& dir, int dim,
                                      const motion::NormStats& norm, double strength) {
  absl::StatusOr<ContrastiveConfig> config = ContrastiveConfig::Read(dir);
  if (!config.ok()) return config.status();
  const std::string what = absl::StrCat("--teacher ", dir, ": ");
  if (config->live) {
    return absl::FailedPreconditionError(
        what + "a live package; the teacher is an offline package that sees whole windows");
  }
  if (config->residual) {
    return absl::FailedPreconditionError(what + "packages with 'residual' are not supported");
  }
  if (config->dim != dim) {
    return absl::FailedPreconditionError(
        absl::StrCat(what, "its features are ", config->dim, " wide, the data's ", dim));
  }
  absl::StatusOr<motion::NormStats> own = motion::NormStats::Load(dir + "/norm.txt");
  if (!own.ok()) return own.status();
  if (own->names != norm.names) {
    return absl::FailedPreconditionError(what + "its feature channels are not the data's");
  }
  Teacher t;
  t.strength_ = strength;
  // x_teacher = (x * std + mean - mean_t) / std_t, channel by channel.
  t.scale_ = torch::empty({1, dim, 1});
  t.shift_ = torch::empty({1, dim, 1});
  for (int c = 0; c < dim; ++c) {
    t.scale_[0][c][0] = norm.std[c] / own->std[c];
    t.shift_[0][c][0] = (norm.mean[c] - own->mean[c]) / own->std[c];
  }
  t.config_ = *std::move(config);
  t.net_ = ContrastiveNet(t.config_);
  if (absl::Status s = LoadWeights(t.net_, dir + "/weights.pt"); !s.ok()) return s;
  t.net_->eval();
  for (torch::Tensor& p : t.net_->parameters()) p.requires_grad_(false);
  return t;
}

torch::Tensor Teacher::Transfer(const torch::Tensor& x, const torch::Tensor& style) const {
  torch::NoGradGuard no_grad;
  const torch::Tensor xt = x * scale_ + shift_;
  const torch::Tensor c = net_->content(xt);
  torch::Tensor code = net_->style(style * scale_ + shift_);
  if (strength_ < 1) {
    // The guard's weaker form (model/contrastive/contrastive_model.cc): the
    // change the style makes at this strength, added to the content.
    const torch::Tensor own = net_->style(xt);
    code = strength_ * code + (1 - strength_) * own;
    const torch::Tensor change = net_->decode(c, code) - net_->decode(c, own);
    const torch::Tensor y = FinishWindows(config_, xt, change, 0, /*residual=*/true);
    return ((y - shift_) / scale_).detach();
  }
  const torch::Tensor y =
      FinishWindows(config_, xt, net_->render(xt, c, code), config_.content_detail, false);
  return ((y - shift_) / scale_).detach();
}

torch::Tensor Teacher::PoseL1(const torch::Tensor& out, const torch::Tensor& target) {
  const int64_t path = out.size(1) - motion::FeatureLayout::kPathChannels;
  return (out.slice(1, 0, path) - target.slice(1, 0, path)).abs().mean();
}

}  // namespace stylus::model
