#include "model/label_critic_net.h"

namespace stylus::model {

namespace nn = torch::nn;

LabelCriticImpl::LabelCriticImpl(int dim, int styles, int contents, int width) {
  auto conv = [&](int in, int dilation) {
    return nn::Conv1d(nn::Conv1dOptions(in, width, 3).dilation(dilation).padding(dilation));
  };
  conv1 = register_module("conv1", conv(dim, 1));
  conv2 = register_module("conv2", conv(width, 2));
  conv3 = register_module("conv3", conv(width, 4));
  style_head = register_module("style_head", nn::Linear(2 * width, styles));
  content_head = register_module("content_head", nn::Linear(2 * width, contents));
}

LabelLogits LabelCriticImpl::forward(const torch::Tensor& x) {
  torch::Tensor h = torch::leaky_relu(conv1->forward(x), 0.2);
  h = torch::leaky_relu(conv2->forward(h), 0.2);
  h = torch::leaky_relu(conv3->forward(h), 0.2);
  const torch::Tensor pooled = torch::cat({h.mean(2), (h.var(2, false) + 1e-5).sqrt()}, 1);
  return {style_head->forward(pooled), content_head->forward(pooled)};
}

torch::Tensor LabelTensor(const std::vector<int>& clips, const std::vector<int>& label_of) {
  std::vector<int64_t> v;
  for (int c : clips) v.push_back(label_of[c]);
  return torch::tensor(v, torch::kLong);
}

torch::Tensor LabelLoss(const LabelLogits& logits, const torch::Tensor& style,
                        const torch::Tensor& content) {
  return torch::nn::functional::cross_entropy(logits.style, style) +
         torch::nn::functional::cross_entropy(logits.content, content);
}

}  // namespace stylus::model
