// The label critic of label-guided training (both families): the guard
// network's design (model/guard_net.h), a style and a content classifier
// trained on real labelled windows only, whose verdict on a transfer the
// generator is trained to match (the target's style, the content input's
// action). Internal to train/ (includes LibTorch).
#ifndef STYLUS_TRAIN_LABEL_CRITIC_H_
#define STYLUS_TRAIN_LABEL_CRITIC_H_

#include <torch/torch.h>

#include <memory>
#include <string>
#include <vector>

#include "model/guard_net.h"
#include "train/torch_files.h"

namespace stylus::model {

// Real windows (B, dim, T) and their labels (kLong, (B,)).
struct LabelledWindows {
  torch::Tensor x, style, content;
};

class LabelCritic {
 public:
  LabelCritic() = default;
  // A critic on `dim` channels with its own Adam at `lr`.
  LabelCritic(int dim, int styles, int contents, double lr = 1e-3);

  GuardNet& net() { return net_; }

  // One optimizer step on the mean label loss of `batches` (real windows
  // only: the critic never learns a transfer's labels). Returns that loss.
  double Learn(const std::vector<LabelledWindows>& batches);
  // LabelLoss of `x` against the labels (differentiable in x).
  torch::Tensor Verdict(const torch::Tensor& x, const torch::Tensor& style,
                        const torch::Tensor& content, double content_weight = 1.0);
  // Checkpoint files `critic`.pt and `optimizer`.pt.
  void AddFiles(const std::string& critic, const std::string& optimizer,
                std::vector<TorchFile>* files);

 private:
  GuardNet net_{nullptr};
  std::unique_ptr<torch::optim::Adam> optimizer_;
};

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_LABEL_CRITIC_H_
