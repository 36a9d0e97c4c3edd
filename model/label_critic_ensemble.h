// Several label critics (model/label_critic_net.h) trained side by side on
// the same real windows from different random starts, whose verdict on a
// transfer is their mean loss. A generator trained against one critic can
// find outputs that critic reads as the content and another classifier does
// not (the judges v1 and v2 disagree on 8-11% of the contrastive family's
// transfers, on 3% of real clips); outputs all members agree on should sit
// further inside the class. Measured on Bandai with three critics: no gain
// in content accuracy (docs/contrastive.md, session 11). Internal to model/
// (includes LibTorch).
#ifndef STYLUS_MODEL_LABEL_CRITIC_ENSEMBLE_H_
#define STYLUS_MODEL_LABEL_CRITIC_ENSEMBLE_H_

#include <torch/torch.h>

#include <memory>
#include <string>
#include <vector>

#include "model/label_critic_net.h"
#include "model/torch_files.h"

namespace stylus::model {

// Real windows (B, dim, T) and their labels (kLong, (B,)).
struct LabelledWindows {
  torch::Tensor x, style, content;
};

class LabelCriticEnsemble {
 public:
  LabelCriticEnsemble() = default;
  // `count` >= 1 critics on `dim` channels, each with its own Adam at `lr`.
  LabelCriticEnsemble(int count, int dim, int styles, int contents, double lr = 1e-3);

  int size() const { return static_cast<int>(critics_.size()); }
  LabelCritic& member(int i) { return critics_[i]; }

  // One optimizer step of every member on the mean label loss of `batches`
  // (real windows only: the critics never learn a transfer's labels).
  // Returns the members' mean loss.
  double Learn(const std::vector<LabelledWindows>& batches);
  // The members' mean LabelLoss of `x` against the labels (differentiable in x).
  torch::Tensor Verdict(const torch::Tensor& x, const torch::Tensor& style,
                        const torch::Tensor& content, double content_weight = 1.0);
  // Checkpoint files: `critic`.pt and `optimizer`.pt for the first member
  // (the names a single critic always had, so older checkpoints resume),
  // then `critic`2.pt, `optimizer`2.pt, ... for the others.
  void AddFiles(const std::string& critic, const std::string& optimizer,
                std::vector<TorchFile>* files);

 private:
  std::vector<LabelCritic> critics_;
  std::vector<std::unique_ptr<torch::optim::Adam>> optimizers_;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_LABEL_CRITIC_ENSEMBLE_H_
