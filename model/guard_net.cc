#include "model/guard_net.h"

#include "model/window_tensor.h"
#include "motion/windowing.h"

namespace stylus::model {

namespace nn = torch::nn;

nn::Conv1d DilatedConv(int in, int width, int dilation) {
  return nn::Conv1d(nn::Conv1dOptions(in, width, 3).dilation(dilation).padding(dilation));
}

torch::Tensor PooledTrunk(const torch::Tensor& x, nn::Conv1d& c1, nn::Conv1d& c2, nn::Conv1d& c3) {
  torch::Tensor h = torch::leaky_relu(c1->forward(x), 0.2);
  h = torch::leaky_relu(c2->forward(h), 0.2);
  h = torch::leaky_relu(c3->forward(h), 0.2);
  return torch::cat({h.mean(2), (h.var(2, false) + 1e-5).sqrt()}, 1);
}

GuardNetImpl::GuardNetImpl(int dim, int styles, int contents, int width) {
  conv1 = register_module("conv1", DilatedConv(dim, width, 1));
  conv2 = register_module("conv2", DilatedConv(width, width, 2));
  conv3 = register_module("conv3", DilatedConv(width, width, 4));
  style_head = register_module("style_head", nn::Linear(2 * width, styles));
  content_head = register_module("content_head", nn::Linear(2 * width, contents));
}

LabelLogits GuardNetImpl::forward(const torch::Tensor& x) {
  const torch::Tensor pooled = PooledTrunk(x, conv1, conv2, conv3);
  return {style_head->forward(pooled), content_head->forward(pooled)};
}

torch::Tensor ClipContentProbabilities(GuardNet& net, motion::FeatureClip f, int window, int hop) {
  PadToLength(&f, window);
  const std::vector<int> starts = *motion::WindowStarts(f.frames, {window, hop}, true);
  return torch::softmax(net->forward(WindowTensor(f, starts, window)).content.mean(0), 0)
      .to(torch::kFloat64);
}

torch::Tensor LabelLoss(const LabelLogits& logits, const torch::Tensor& style,
                        const torch::Tensor& content, double content_weight) {
  return torch::nn::functional::cross_entropy(logits.style, style) +
         content_weight * torch::nn::functional::cross_entropy(logits.content, content);
}

}  // namespace stylus::model
