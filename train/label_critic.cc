#include "train/label_critic.h"

#include "absl/strings/str_cat.h"

namespace stylus::model {

LabelCritic::LabelCritic(int dim, int styles, int contents, double lr)
    : net_(dim, styles, contents),
      optimizer_(std::make_unique<torch::optim::Adam>(net_->parameters(),
                                                      torch::optim::AdamOptions(lr))) {}

double LabelCritic::Learn(const std::vector<LabelledWindows>& batches) {
  optimizer_->zero_grad();
  torch::Tensor loss = torch::zeros({});
  for (const LabelledWindows& b : batches) {
    loss = loss + LabelLoss(net_->forward(b.x.detach()), b.style, b.content);
  }
  loss = loss / static_cast<double>(batches.size());
  loss.backward();
  optimizer_->step();
  return loss.item<double>();
}

torch::Tensor LabelCritic::Verdict(const torch::Tensor& x, const torch::Tensor& style,
                                   const torch::Tensor& content, double content_weight) {
  return LabelLoss(net_->forward(x), style, content, content_weight);
}

void LabelCritic::AddFiles(const std::string& critic, const std::string& optimizer,
                           std::vector<TorchFile>* files) {
  files->push_back(Tensors(critic + ".pt", &net_));
  files->push_back(Tensors(optimizer + ".pt", optimizer_.get()));
}

}  // namespace stylus::model
