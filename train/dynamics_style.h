// The dynamics style term of training: paper 004's Gram style loss applied to
// how the body moves instead of to network features. A window's dynamics are,
// per frame, the velocities of the joints' positions relative to the root in
// its facing frame (the feature channels of every joint from the pelvis down;
// motion/features.h) and the root trajectory's four velocities, then their
// changes (accelerations). Each channel is scaled to unit deviation over the
// training clips, so a wrist and a hip weigh alike. The Gram matrix of a
// window's dynamics (channels x channels, averaged over frames) holds each
// channel's energy (amplitude: stride, arm swing) and how channels move
// together (coordination); that of the accelerations, how quickly they change
// (rhythm). Neither depends on when in the window a movement happens, so a
// transfer can be compared with a real clip of the target style that is not
// aligned with it.
#ifndef STYLUS_TRAIN_DYNAMICS_STYLE_H_
#define STYLUS_TRAIN_DYNAMICS_STYLE_H_

#include <torch/torch.h>

#include <cstdint>
#include <vector>

#include "train/training_set.h"

namespace stylus::model {

class DynamicsStyle {
 public:
  DynamicsStyle() = default;
  // Channel scales from every clip of `data` (normalized feature clips).
  explicit DynamicsStyle(const TrainingSet& data);

  bool on() const { return vel_scale_.defined(); }
  // (B, dim, T) normalized feature windows -> (B, C, T - 1) scaled
  // velocities and (B, C, T - 2) scaled accelerations.
  std::pair<torch::Tensor, torch::Tensor> Dynamics(const torch::Tensor& x) const;
  // The two stacked on the frames both have: (B, 2 C, T - 2), what the
  // motion critics of training read.
  torch::Tensor Stacked(const torch::Tensor& x) const;
  // C of Dynamics: three per moving joint, four of the root trajectory.
  int channels() const { return static_cast<int>(position_channels_.size(0)) + 4; }
  // The mean L1 distance between the Gram matrices of `out`'s dynamics and
  // `reference`'s, velocities and accelerations summed. Both (B, dim, T).
  torch::Tensor Loss(const torch::Tensor& out, const torch::Tensor& reference) const;

 private:
  torch::Tensor Unscaled(const torch::Tensor& x) const;

  torch::Tensor position_channels_;  // Long: the moving joints' position channels.
  int64_t trajectory_ = 0;           // First trajectory channel.
  torch::Tensor vel_scale_, acc_scale_;  // (1, C, 1).
};

// (B, C, T) -> (B, C, C): m m^T / T.
torch::Tensor GramMatrix(const torch::Tensor& m);

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_DYNAMICS_STYLE_H_
