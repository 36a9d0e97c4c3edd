// The networks and losses of the `contrastive` family (internal to model/:
// includes LibTorch). Tensors are (batch, channels, time).
#ifndef STYLUS_MODEL_CONTRASTIVE_CONTRASTIVE_NET_H_
#define STYLUS_MODEL_CONTRASTIVE_CONTRASTIVE_NET_H_

#include <torch/torch.h>

#include "model/contrastive/contrastive_config.h"
#include "model/contrastive/live_net.h"

namespace stylus::model {

// conv -> norm -> LeakyReLU -> conv -> norm, plus the input. With `instance_norm`
// the norms are InstanceNorm (content encoder: strips per-clip statistics);
// without, plain (style encoder: keeps them).
struct ResBlockImpl : torch::nn::Module {
  ResBlockImpl(int channels, int kernel, bool instance_norm);
  torch::Tensor forward(const torch::Tensor& x);
  torch::nn::Conv1d conv1{nullptr}, conv2{nullptr};
  torch::nn::InstanceNorm1d norm1{nullptr}, norm2{nullptr};
};
TORCH_MODULE(ResBlock);

// 3 Conv1d layers (the second with stride 2: T -> T/2), then 3 residual
// blocks.
struct EncoderImpl : torch::nn::Module {
  EncoderImpl(const ContrastiveConfig& c, bool instance_norm);
  torch::Tensor forward(torch::Tensor x);
  torch::nn::Conv1d conv1{nullptr}, conv2{nullptr}, conv3{nullptr};
  torch::nn::ModuleList blocks;
};
TORCH_MODULE(Encoder);

// The content code's bottleneck (config `bottleneck_channels`): a 1x1
// convolution down to k channels, instance normalization over time, the mean
// over every `pool` steps (held, then linearly interpolated back to every
// step), and a 1x1 convolution back up to the code's width.
struct BottleneckImpl : torch::nn::Module {
  BottleneckImpl(int channels, int k, int pool);
  torch::Tensor forward(const torch::Tensor& code);
  torch::nn::Conv1d down{nullptr}, up{nullptr};
  int pool;
};
TORCH_MODULE(Bottleneck);

// What the style encoder reads with `style_from_motion`: each channel's
// change from the frame before, times kFrameChangeScale (normalized features
// move about a tenth of their spread per frame at 30 fps); the first frame
// takes the second's change. (B, C, T) -> (B, C, T), T >= 2.
inline constexpr double kFrameChangeScale = 10;
torch::Tensor FrameChanges(const torch::Tensor& x);

// Residual block whose two normalizations are AdaIN with given scale and bias.
struct AdaInBlockImpl : torch::nn::Module {
  AdaInBlockImpl(int channels, int kernel);
  // params: (B, 4C): scale1, bias1, scale2, bias2.
  torch::Tensor forward(const torch::Tensor& x, const torch::Tensor& params);
  torch::nn::Conv1d conv1{nullptr}, conv2{nullptr};
  int channels;
};
TORCH_MODULE(AdaInBlock);

// A per-channel temporal filter chosen by the style code (config
// `style_filter_taps`): x plus x convolved, channel by channel, with `taps`
// weights that a linear map of the style code gives (edges held). The map
// starts at zero, so a fresh filter passes x unchanged and a package
// fine-tuned with it starts from its own output.
struct StyleFilterImpl : torch::nn::Module {
  StyleFilterImpl(int channels, int taps);
  // x: (B, C, T); style: (B, C_style).
  torch::Tensor forward(const torch::Tensor& x, const torch::Tensor& style);
  torch::nn::Linear kernels{nullptr};
  int channels, taps;
};
TORCH_MODULE(StyleFilter);

// 4 AdaIN residual blocks on the content code, AdaIN parameters from an MLP on
// the style code, (with style_filter_taps) the style filter, then upsampling
// back to T frames and an output conv to d.
struct GeneratorImpl : torch::nn::Module {
  explicit GeneratorImpl(const ContrastiveConfig& c);
  torch::Tensor forward(const torch::Tensor& content, const torch::Tensor& style);
  torch::nn::Sequential mlp{nullptr};
  StyleFilter filter{nullptr};
  torch::nn::ModuleList blocks;
  torch::nn::Conv1d up_conv{nullptr}, out_conv{nullptr};
  int channels;
};
TORCH_MODULE(Generator);

// MLP on a flattened window: real (high) vs generated (low) logits.
struct DiscriminatorImpl : torch::nn::Module {
  explicit DiscriminatorImpl(const ContrastiveConfig& c);
  torch::Tensor forward(const torch::Tensor& x);
  torch::nn::Sequential mlp{nullptr};
};
TORCH_MODULE(Discriminator);

// Everything inference needs (Ec, Es, G) plus the InfoNCE bilinear W. The
// discriminator lives apart: it is only for training and is not shipped. A
// live package (config `live`) has the causal content encoder and generator
// of model/contrastive/live_net.h; its style encoder is the offline one
// (a style clip is whole before it is encoded).
struct ContrastiveNetImpl : torch::nn::Module {
  explicit ContrastiveNetImpl(const ContrastiveConfig& c);
  torch::Tensor content(const torch::Tensor& x) {
    if (live_content) return live_content->forward(x);
    const torch::Tensor code = content_encoder->forward(x);
    return bottleneck ? bottleneck->forward(code) : code;
  }
  // (B, C): temporal mean of the style encoder's output, on the windows'
  // FrameChanges with `style_from_motion`.
  torch::Tensor style(const torch::Tensor& x) {
    return style_encoder->forward(style_from_motion ? FrameChanges(x) : x).mean(2);
  }
  // `s`: (B, C); a live package also takes (B, C, T), a code per frame.
  torch::Tensor decode(const torch::Tensor& c, const torch::Tensor& s) {
    return live_generator ? live_generator->forward(c, s) : generator->forward(c, s);
  }
  // The generator's output for content windows `x` with codes `c` =
  // content(x): decode, plus x with `frame_residual`.
  torch::Tensor render(const torch::Tensor& x, const torch::Tensor& c, const torch::Tensor& s) {
    const torch::Tensor y = decode(c, s);
    return frame_residual ? y + x : y;
  }
  Encoder content_encoder{nullptr}, style_encoder{nullptr};
  Bottleneck bottleneck{nullptr};  // With bottleneck_channels.
  Generator generator{nullptr};
  bool frame_residual = false;
  bool style_from_motion = false;
  LiveContentEncoder live_content{nullptr};  // Live packages only, with...
  LiveGenerator live_generator{nullptr};     // ...this generator.
  torch::Tensor nce_w;
};
TORCH_MODULE(ContrastiveNet);

// Losses (docs/notes/contrastive.md).
torch::Tensor ReconstructionLoss(const torch::Tensor& output, const torch::Tensor& target);
// The L1 distance over the channels `mask` (1, dim, 1) marks with 1 only:
// the mean over the batch, those channels and time.
torch::Tensor MaskedL1Loss(const torch::Tensor& output, const torch::Tensor& target,
                           const torch::Tensor& mask);
// InfoNCE over every time step i of the content codes: query column i of
// `generated`, positive column i of `target`, negatives its other columns;
// similarity q^T W k / temperature on unit-length columns.
torch::Tensor NceLoss(const torch::Tensor& generated, const torch::Tensor& target,
                      const torch::Tensor& w, double temperature);
// Triplet hinge on unit-length style codes.
torch::Tensor TripletLoss(const torch::Tensor& anchor, const torch::Tensor& positive,
                          const torch::Tensor& negative, double margin);
// Non-saturating GAN: the generator's loss, and the discriminator's.
torch::Tensor GeneratorGanLoss(const torch::Tensor& fake_logits);
torch::Tensor DiscriminatorGanLoss(const torch::Tensor& real_logits,
                                   const torch::Tensor& fake_logits);

// The inference form's finish of generated windows `y` for content windows
// `x` (both (B, dim, T), normalized), the same for transfers and for a
// teacher in training (train/teacher.h): the pose channels smoothed by
// smooth_sigma, plus `content_detail` times the content's own detail, plus
// x when `residual` (y is then the change the style makes), and with
// keep_path the content's path channels.
torch::Tensor FinishWindows(const ContrastiveConfig& config, const torch::Tensor& x,
                            torch::Tensor y, double content_detail, bool residual);

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CONTRASTIVE_CONTRASTIVE_NET_H_
