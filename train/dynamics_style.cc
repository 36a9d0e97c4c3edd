#include "train/dynamics_style.h"

#include "motion/features.h"

namespace stylus::model {
namespace {

torch::Tensor TimeDiff(const torch::Tensor& x) {
  const int64_t t = x.size(2);
  return x.slice(2, 1, t) - x.slice(2, 0, t - 1);
}

// 1 / the deviation of each channel of (B, C, T) tensors, over all of them;
// 0 for channels that never move.
torch::Tensor InverseDeviation(const std::vector<torch::Tensor>& parts) {
  torch::Tensor all = torch::cat(parts, 2);  // (1, C, sum T)
  const torch::Tensor std = all.std(2, /*unbiased=*/false, /*keepdim=*/true);
  return torch::where(std > 1e-6, 1.0 / std.clamp_min(1e-6), torch::zeros_like(std));
}

}  // namespace

torch::Tensor GramMatrix(const torch::Tensor& m) {
  return torch::bmm(m, m.transpose(1, 2)) / static_cast<double>(m.size(2));
}

DynamicsStyle::DynamicsStyle(const TrainingSet& data) {
  const motion::Skeleton& sk = data.skeleton;
  const motion::FeatureLayout layout(sk.num_joints());
  const std::vector<bool> above = motion::AbovePelvis(sk, data.roles);
  std::vector<int64_t> channels;
  for (int j = 0; j < sk.num_joints(); ++j) {
    if (above[j]) continue;
    for (int c = 0; c < 3; ++c) channels.push_back(layout.position(j) + c);
  }
  position_channels_ = torch::tensor(channels, torch::kLong);
  trajectory_ = layout.trajectory();
  torch::NoGradGuard no_grad;
  std::vector<torch::Tensor> vel;
  for (const motion::FeatureClip& clip : data.clips) {
    if (clip.frames < 3) continue;
    const torch::Tensor x =
        torch::from_blob(const_cast<float*>(clip.values.data()), {clip.frames, clip.dim},
                         torch::kFloat32)
            .t()
            .unsqueeze(0);
    vel.push_back(Unscaled(x));
  }
  if (vel.empty()) return;
  vel_scale_ = InverseDeviation(vel);
  std::vector<torch::Tensor> scaled_acc;
  for (torch::Tensor& v : vel) scaled_acc.push_back(TimeDiff(v * vel_scale_));
  acc_scale_ = InverseDeviation(scaled_acc);
}

torch::Tensor DynamicsStyle::Unscaled(const torch::Tensor& x) const {
  const int64_t t = x.size(2);
  const torch::Tensor joints = TimeDiff(x.index_select(1, position_channels_));
  const torch::Tensor root = x.slice(1, trajectory_, trajectory_ + 4).slice(2, 1, t);
  return torch::cat({joints, root}, 1);
}

std::pair<torch::Tensor, torch::Tensor> DynamicsStyle::Dynamics(const torch::Tensor& x) const {
  const torch::Tensor v = Unscaled(x) * vel_scale_;
  return {v, TimeDiff(v) * acc_scale_};
}

torch::Tensor DynamicsStyle::Stacked(const torch::Tensor& x) const {
  const auto [v, a] = Dynamics(x);
  return torch::cat({v.slice(2, 1, v.size(2)), a}, 1);
}

torch::Tensor DynamicsStyle::Loss(const torch::Tensor& out, const torch::Tensor& reference) const {
  const auto [v_out, a_out] = Dynamics(out);
  const auto [v_ref, a_ref] = Dynamics(reference);
  return (GramMatrix(v_out) - GramMatrix(v_ref)).abs().mean() +
         (GramMatrix(a_out) - GramMatrix(a_ref)).abs().mean();
}

}  // namespace stylus::model
