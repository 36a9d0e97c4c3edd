// A teacher for training a contrastive package (distillation): a trained
// offline contrastive package whose transfer of the same content window to
// the same style window the student is pulled towards, with an L1 term on
// the pose channels (ContrastiveConfig::teacher_weight). A live package
// learns from an offline one what a transfer that sees the whole window
// does, frame by frame with only its lookahead (docs/notes/live.md).
//
// The teacher's transfer is its inference form on one window: its style code
// from the style window, its generator's output smoothed (smooth_sigma), with
// the content's detail (content_detail), the path channels the content's
// (keep_path); its content guard, which reads whole clips, is not applied.
// At a strength k < 1 it is the weaker form that guard backs off to: the
// content window plus the smoothed change G(c, k s + (1 - k) s_own) -
// G(c, s_own) the style makes, s_own the content window's own code.
// Internal to train/ (includes LibTorch).
#ifndef STYLUS_TRAIN_TEACHER_H_
#define STYLUS_TRAIN_TEACHER_H_

#include <torch/torch.h>

#include <string>

#include "absl/status/statusor.h"
#include "model/contrastive/contrastive_config.h"
#include "model/contrastive/contrastive_net.h"
#include "motion/normalization.h"

namespace stylus::model {

class Teacher {
 public:
  Teacher() = default;
  // Loads the package `dir`: an offline contrastive package with the same
  // feature channels as the student's data (normalized by `norm`; the
  // teacher's own statistics may differ slightly: windows are converted to
  // them and back), else FAILED_PRECONDITION saying why; NOT_FOUND /
  // INVALID_ARGUMENT naming the file. `strength` in [0, 1].
  static absl::StatusOr<Teacher> Load(const std::string& dir, int dim,
                                      const motion::NormStats& norm, double strength = 1);

  bool on() const { return !net_.is_empty(); }
  // The teacher's transfer of content windows `x` to the style of `style`
  // windows, both (B, dim, T) normalized; no gradient.
  torch::Tensor Transfer(const torch::Tensor& x, const torch::Tensor& style) const;
  // The mean L1 distance between `out` and `target` over the pose channels
  // (the path channels are the content's at inference).
  static torch::Tensor PoseL1(const torch::Tensor& out, const torch::Tensor& target);

 private:
  ContrastiveConfig config_;
  double strength_ = 1;
  mutable ContrastiveNet net_{nullptr};
  torch::Tensor scale_, shift_;  // (1, dim, 1): the student's normalization to the teacher's.
};

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_TEACHER_H_
