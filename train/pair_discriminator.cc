#include "train/pair_discriminator.h"

namespace stylus::model {

namespace nn = torch::nn;

PairDiscriminatorImpl::PairDiscriminatorImpl(int dim, int styles, int contents, int width) {
  conv1 = register_module("conv1", DilatedConv(dim, width, 1));
  conv2 = register_module("conv2", DilatedConv(width, width, 2));
  conv3 = register_module("conv3", DilatedConv(width, width, 4));
  real_head = register_module("real_head", nn::Linear(2 * width, 1));
  style_embed = register_module("style_embed", nn::Embedding(styles, 2 * width));
  content_embed = register_module("content_embed", nn::Embedding(contents, 2 * width));
  // Small label embeddings: the verdict starts from realism alone.
  torch::NoGradGuard no_grad;
  style_embed->weight.normal_(0, 0.02);
  content_embed->weight.normal_(0, 0.02);
}

torch::Tensor PairDiscriminatorImpl::forward(const torch::Tensor& x, const torch::Tensor& style,
                                             const torch::Tensor& content) {
  return Verdict(Trunk(x), style, content);
}

torch::Tensor PairDiscriminatorImpl::Trunk(const torch::Tensor& x) {
  return PooledTrunk(x, conv1, conv2, conv3);
}

torch::Tensor PairDiscriminatorImpl::Verdict(const torch::Tensor& h, const torch::Tensor& style,
                                             const torch::Tensor& content) {
  const torch::Tensor projection =
      ((style_embed->forward(style) + content_embed->forward(content)) * h).sum(1);
  return real_head->forward(h).squeeze(1) + projection;
}

torch::Tensor PairAdversarialStep(PairDiscriminator& d, torch::optim::Optimizer& opt,
                                  const torch::Tensor& x, const torch::Tensor& x_style,
                                  const torch::Tensor& x_content, const torch::Tensor& y,
                                  const torch::Tensor& y_style, const torch::Tensor& y_content,
                                  const torch::Tensor& fake, double* d_loss) {
  namespace F = torch::nn::functional;
  opt.zero_grad();
  // Each real batch goes through the trunk once and is judged under two label pairs.
  const torch::Tensor h_x = d->Trunk(x), h_y = d->Trunk(y);
  const torch::Tensor real = (F::softplus(-d->Verdict(h_x, x_style, x_content)).mean() +
                              F::softplus(-d->Verdict(h_y, y_style, y_content)).mean()) /
                             2;
  const torch::Tensor as_fake = F::softplus(d->forward(fake.detach(), y_style, x_content));
  const torch::Tensor identity = F::softplus(d->Verdict(h_x, y_style, x_content));
  // A style window of the content's own content is a right answer, not a copy.
  const torch::Tensor differs = (y_content != x_content).to(torch::kFloat32);
  const torch::Tensor copy = F::softplus(d->Verdict(h_y, y_style, x_content)) * differs;
  const torch::Tensor loss = real + 0.5 * as_fake.mean() + 0.25 * identity.mean() +
                             0.25 * copy.sum() / differs.sum().clamp_min(1);
  loss.backward();
  opt.step();
  *d_loss = loss.item<double>();
  return F::softplus(-d->forward(fake, y_style, x_content)).mean();
}

PairGan::PairGan(int dim, int styles, int contents, double lr)
    : disc_(dim, styles, contents),
      optimizer_(std::make_unique<torch::optim::Adam>(
          disc_->parameters(), torch::optim::AdamOptions(lr).betas({0.5, 0.999}))) {}

torch::Tensor PairGan::Step(const torch::Tensor& x, const torch::Tensor& x_style,
                            const torch::Tensor& x_content, const torch::Tensor& y,
                            const torch::Tensor& y_style, const torch::Tensor& y_content,
                            const torch::Tensor& fake, double* d_loss) {
  return PairAdversarialStep(disc_, *optimizer_, x, x_style, x_content, y, y_style, y_content, fake,
                             d_loss);
}

void PairGan::AddFiles(std::vector<TorchFile>* files, const std::string& disc,
                       const std::string& optimizer) {
  files->push_back(Tensors(disc + ".pt", &disc_));
  files->push_back(Tensors(optimizer + ".pt", optimizer_.get()));
}

torch::Tensor LabelTensor(const std::vector<int>& clips, const std::vector<int>& label_of) {
  std::vector<int64_t> v;
  for (int c : clips) v.push_back(label_of[c]);
  return torch::tensor(v, torch::kLong);
}

}  // namespace stylus::model
