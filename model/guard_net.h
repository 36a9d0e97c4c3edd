// The content guard's network (model/content_guard.h): a style and a content
// classifier on normalized feature windows, trained on real training windows
// only. Label-guided training uses the same network as its critic
// (train/label_critic.h), whose verdict on a transfer the generator is
// trained to match. Deliberately unlike the evaluation judges
// (eval/judges.cc): dilated convolutions and mean + spread pooling, so that a
// transfer the judges recognize is not one tuned to the judges' own design.
// Internal to model/, train/ and eval/ (includes LibTorch).
#ifndef STYLUS_MODEL_GUARD_NET_H_
#define STYLUS_MODEL_GUARD_NET_H_

#include <torch/torch.h>

#include <vector>

#include "motion/features.h"

namespace stylus::model {

// The trunk of the guard network, shared with training's label-conditional
// discriminator: three dilated convolutions (width channels, kernel 3,
// dilations 1, 2, 4), then each channel's mean and spread over time.
torch::nn::Conv1d DilatedConv(int in, int width, int dilation);
torch::Tensor PooledTrunk(const torch::Tensor& x, torch::nn::Conv1d& c1, torch::nn::Conv1d& c2,
                          torch::nn::Conv1d& c3);

struct LabelLogits {
  torch::Tensor style, content;  // (B, styles), (B, contents).
};

struct GuardNetImpl : torch::nn::Module {
  GuardNetImpl(int dim, int styles, int contents, int width = 96);
  // x: (B, dim, T) normalized feature windows.
  LabelLogits forward(const torch::Tensor& x);
  torch::nn::Conv1d conv1{nullptr}, conv2{nullptr}, conv3{nullptr};
  torch::nn::Linear style_head{nullptr}, content_head{nullptr};
};
TORCH_MODULE(GuardNet);

// Mean cross-entropy of both heads against the labels (kLong tensors (B,)),
// the content head's times `content_weight`.
torch::Tensor LabelLoss(const LabelLogits& logits, const torch::Tensor& style,
                        const torch::Tensor& content, double content_weight = 1.0);

// The softmax of `net`'s content logits averaged over the windows of `f`
// (window frames at hop `hop`; a clip shorter than a window is padded with
// its last frame), as kFloat64.
torch::Tensor ClipContentProbabilities(GuardNet& net, motion::FeatureClip f, int window, int hop);

}  // namespace stylus::model

#endif  // STYLUS_MODEL_GUARD_NET_H_
