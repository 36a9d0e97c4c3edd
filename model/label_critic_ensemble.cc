#include "model/label_critic_ensemble.h"

#include "absl/strings/str_cat.h"

namespace stylus::model {

LabelCriticEnsemble::LabelCriticEnsemble(int count, int dim, int styles, int contents,
                                         double lr) {
  for (int i = 0; i < count; ++i) {
    critics_.push_back(LabelCritic(dim, styles, contents));
    optimizers_.push_back(std::make_unique<torch::optim::Adam>(critics_.back()->parameters(),
                                                               torch::optim::AdamOptions(lr)));
  }
}

double LabelCriticEnsemble::Learn(const std::vector<LabelledWindows>& batches) {
  double total = 0;
  for (size_t i = 0; i < critics_.size(); ++i) {
    optimizers_[i]->zero_grad();
    torch::Tensor loss = torch::zeros({});
    for (const LabelledWindows& b : batches) {
      loss = loss + LabelLoss(critics_[i]->forward(b.x.detach()), b.style, b.content);
    }
    loss = loss / static_cast<double>(batches.size());
    loss.backward();
    optimizers_[i]->step();
    total += loss.item<double>();
  }
  return total / static_cast<double>(critics_.size());
}

torch::Tensor LabelCriticEnsemble::Verdict(const torch::Tensor& x, const torch::Tensor& style,
                                           const torch::Tensor& content, double content_weight) {
  torch::Tensor loss = torch::zeros({});
  for (LabelCritic& c : critics_) {
    loss = loss + LabelLoss(c->forward(x), style, content, content_weight);
  }
  return loss / static_cast<double>(critics_.size());
}

void LabelCriticEnsemble::AddFiles(const std::string& critic, const std::string& optimizer,
                                   std::vector<TorchFile>* files) {
  for (size_t i = 0; i < critics_.size(); ++i) {
    const std::string suffix = i == 0 ? "" : absl::StrCat(i + 1);
    files->push_back(Tensors(absl::StrCat(critic, suffix, ".pt"), &critics_[i]));
    files->push_back(Tensors(absl::StrCat(optimizer, suffix, ".pt"), optimizers_[i].get()));
  }
}

}  // namespace stylus::model
