// Label-guided training's label-conditional discriminator and its labels as
// tensors. Internal to train/ (includes LibTorch).
#ifndef STYLUS_TRAIN_PAIR_DISCRIMINATOR_H_
#define STYLUS_TRAIN_PAIR_DISCRIMINATOR_H_

#include <torch/torch.h>

#include <memory>
#include <string>
#include <vector>

#include "model/guard_net.h"
#include "train/torch_files.h"

namespace stylus::model {

// The label-conditional discriminator of label-guided training with
// `pair_gan` (docs/notes/contrastive.md): a projection discriminator
//   D(x, s, c) = w . h(x) + e_s[s] . h(x) + e_c[c] . h(x)
// on the guard network's trunk (model/guard_net.h), real for real windows with their
// own labels, fake for transfers and for real windows given a label pair they
// do not have (the identity and copy-style answers).
struct PairDiscriminatorImpl : torch::nn::Module {
  PairDiscriminatorImpl(int dim, int styles, int contents, int width = 96);
  // x: (B, dim, T); style, content: kLong (B,). Returns logits (B,).
  torch::Tensor forward(const torch::Tensor& x, const torch::Tensor& style,
                        const torch::Tensor& content);
  // The same in two parts, so one window batch can be judged under several
  // label pairs: h(x) (B, 2 width), then the logits for a label pair.
  torch::Tensor Trunk(const torch::Tensor& x);
  torch::Tensor Verdict(const torch::Tensor& h, const torch::Tensor& style,
                        const torch::Tensor& content);
  torch::nn::Conv1d conv1{nullptr}, conv2{nullptr}, conv3{nullptr};
  torch::nn::Linear real_head{nullptr};
  torch::nn::Embedding style_embed{nullptr}, content_embed{nullptr};
};
TORCH_MODULE(PairDiscriminator);

// One step of label-conditional adversarial training: updates `d` (with
// `opt`) on real windows x and y under their own label pairs (real), and
// under the pair (y_style, x_content) the transfer `fake` of x into y's
// style (fake), the unchanged x (identity) and y itself when its content
// differs from x's (copy-style); returns the generator's non-saturating loss
// on `fake` under that pair, and the discriminator's loss in `d_loss`.
torch::Tensor PairAdversarialStep(PairDiscriminator& d, torch::optim::Optimizer& opt,
                                  const torch::Tensor& x, const torch::Tensor& x_style,
                                  const torch::Tensor& x_content, const torch::Tensor& y,
                                  const torch::Tensor& y_style, const torch::Tensor& y_content,
                                  const torch::Tensor& fake, double* d_loss);

// A label-conditional discriminator with its own Adam (betas 0.5, 0.999):
// what a trainer with `pair_gan` holds and checkpoints.
class PairGan {
 public:
  PairGan() = default;
  PairGan(int dim, int styles, int contents, double lr);
  // PairAdversarialStep with this discriminator and optimizer.
  torch::Tensor Step(const torch::Tensor& x, const torch::Tensor& x_style,
                     const torch::Tensor& x_content, const torch::Tensor& y,
                     const torch::Tensor& y_style, const torch::Tensor& y_content,
                     const torch::Tensor& fake, double* d_loss);
  // Checkpoint files `disc`.pt and `optimizer`.pt.
  void AddFiles(std::vector<TorchFile>* files, const std::string& disc = "pair_disc",
                const std::string& optimizer = "opt_p");

 private:
  PairDiscriminator disc_{nullptr};
  std::unique_ptr<torch::optim::Adam> optimizer_;
};

// The label (kLong, (B,)) of each of `clips`, read from `label_of`.
torch::Tensor LabelTensor(const std::vector<int>& clips, const std::vector<int>& label_of);

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_PAIR_DISCRIMINATOR_H_
