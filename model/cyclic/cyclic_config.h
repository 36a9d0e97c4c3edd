// Hyper-parameters of the `cyclic` family (paper 004, docs/notes/cyclic.md), stored
// in a model package as `config.txt` (key = value lines).
#ifndef STYLUS_MODEL_CYCLIC_CYCLIC_CONFIG_H_
#define STYLUS_MODEL_CYCLIC_CYCLIC_CONFIG_H_

#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "model/config_text.h"
#include "motion/contacts.h"

namespace stylus::model {

// The content guard's keys (GuardKeys, model/config_text.h): a weaker style
// at strength k restyles the hidden features k of the way (the content's
// own features plus k times the change the style transform makes).
struct CyclicConfig : GuardKeys, MovementKeys {
  // Architecture: fixed when the network is trained.
  int window = 60;     // Training window (2 s at 30 fps).
  int hop = 30;        // Window stride (50% overlap).
  int dim = 0;         // Full feature width (motion/features.h), set from the data.
  int hidden = 256;    // Hidden units of the autoencoder.
  int kernel = 15;     // Temporal kernel of encoder and decoder (~0.5 s).
  double dropout = 0;  // Paper: 0.25 (docs/notes/cyclic.md: why 0 here).
  // With `residual`, G(C, S) = C + decode(h) - decode(encode(C)) where h is
  // the restyled hidden features: the decoder supplies the change the style
  // makes, and the autoencoder's own reconstruction error does not reach the
  // output (docs/notes/cyclic.md). Without, G(C, S) = decode(h) (the paper).
  bool residual = true;
  // The style input (docs/notes/cyclic.md, "A learned style network"): with
  // style_dim = 0 (v1) the style code is the per-channel mean and spread of
  // the encoder's features of the style clip and one modulated block
  // restyles the content's features; with style_dim > 0 a style encoder of
  // its own maps the style clip to style_dim values, and `blocks` residual
  // blocks (dilated convolutions, each modulated by the code) restyle them.
  int style_dim = 0;
  int blocks = 4;
  // Style network only (docs/notes/cyclic.md, "A normalized skip"): before the
  // blocks, the content's hidden features take the style clip's own
  // per-channel mean and spread over time (AdaIN of the autoencoder's
  // features, exact for a clip's own style), so the content clip's channel
  // statistics, which carry its style, do not reach the output along the
  // blocks' skip path. The style code then holds those statistics after the
  // style encoder's values.
  bool adain_skip = false;
  // The joints' rotations join the network's channels (after the path
  // channels; docs/notes/cyclic.md, "Rotations in the network"). Joint positions
  // fix each bone's direction but not its twist, nor the orientation of a
  // joint without a child joint (head, hands, toes); without this option the
  // output takes those from the content clip, and with them part of the
  // content's style. With it, the generated rotations supply them, and the
  // kinematic terms still read the positions.
  bool rotations = false;
  // Inference keys (InferenceKeys(), with the guard's of GuardKeys, and
  // use_kc; may be set at load time). With `keep_path`, the output's root
  // trajectory and foot contacts are the content's (the style restyles the
  // body along the content's path).
  bool keep_path = false;
  // Inference-time kinematic optimization of the hidden features: at most
  // kc_iters backtracking gradient steps (the first of RMS size kc_lr per
  // hidden unit), stopping when the loss stops falling.
  int kc_iters = 100;
  double kc_lr = 0.02;
  // Training keys: how the package was trained; inference ignores them.
  // Loss weights. The generator: reconstruction of C and G(C, C) = C,
  // Gram style loss and content loss in hidden space, adversarial, cycle
  // ||F(G(C,S), C) - C||^2, and the kinematic constraints on generated joint
  // positions: smoothness, bone length, trajectory and (an addition to the
  // paper) planted feet.
  double rec_weight = 1, style_weight = 1, content_weight = 1, gan_weight = 0.05;
  double cycle_weight = 1;
  double smooth_weight = 1, bone_weight = 1, traj_weight = 1, foot_weight = 1;
  // A content-keeping term (0: off): the L1 distance between G(C, S) and C
  // over the channels that say what is done and where: the legs' joint
  // positions, the root trajectory and the foot contacts (the contrastive
  // family's content_weight, in this family's channels).
  double keep_weight = 0;
  bool use_cycle = true;  // Off: no cycle loss.
  bool use_kc = true;     // Off: no kinematic constraint in training or inference (either).
  // Label-guided generator stage (docs/notes/cyclic.md, "Label-guided training"):
  // the style clip of each content clip has another style label, and a
  // critic trained on real labelled windows scores G(C, S) against S's
  // style and C's content, weighted by `class_weight`.
  bool guided = false;
  double class_weight = 1;
  // Guided only: the content head's share of that verdict, times this.
  double content_class_weight = 1;
  // Guided only: content windows are drawn so that a content class with n
  // windows comes up in proportion to n^(1 - content_balance) (as for the
  // other family: 0 every window alike, 1 every action alike).
  double content_balance = 0;
  // Guided only: the adversarial term (gan_weight) uses the label-conditional
  // discriminator of the contrastive family (model/guard_net.h),
  // which also rejects the unchanged content and the style clip under the
  // transfer's label pair.
  bool pair_gan = false;
  // Training: windows start anywhere in their clip, not only on the hop grid
  // (TrainingSet::random_starts), so the clips' last frames are trained on.
  bool random_starts = false;
  // Training: left-right mirrored copies of the training clips join them,
  // their content labels' sides swapped (train/training_set.h).
  bool mirror = false;
  // Weight averaging (train/weight_average.h): from iteration
  // `average_from` on (0: off), every `average_every` iterations, the
  // network's weights are folded into a running mean, which is what the
  // package holds.
  int average_from = 0, average_every = 50;
  // Optimization: the autoencoder alone for ae_iterations, then everything.
  int ae_iterations = 2000;
  int batch = 16;
  double lr = 5e-4;
  int iterations = 8000;
  uint64_t seed = 1;
  // Provenance (filled by training).
  std::string family = "cyclic";
  std::string data;
  std::string commit;
  int trained_iterations = 0;

  // Channels the network sees (a subset of the features): joint positions,
  // root trajectory, foot contacts, and with `rotations` the joint rotations
  // (CyclicChannels).
  int net_channels(int joints) const { return 3 * joints + 8 + (rotations ? 4 * joints : 0); }
  // Values in a style code.
  int code_size() const {
    return style_dim > 0 ? style_dim + (adain_skip ? 2 * hidden : 0) : 2 * hidden;
  }

  // The keys that may be set on top of a package's config.txt at load time
  // (model/family_registry.h).
  static const std::vector<std::string>& InferenceKeys();
  // How its features are extracted (motion/features.h): the defaults.
  motion::ContactParams Contacts() const { return {}; }

  std::string Serialize() const;
  // INVALID_ARGUMENT naming `source` and the line of a malformed or
  // out-of-range entry; unknown keys are errors too.
  static absl::StatusOr<CyclicConfig> Parse(const std::string& text, const std::string& source);
  // Reads and parses <dir>/config.txt (NOT_FOUND when missing), then the
  // lines of `overrides` as if they followed it.
  static absl::StatusOr<CyclicConfig> Read(const std::string& dir,
                                           const std::string& overrides = "");
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CYCLIC_CYCLIC_CONFIG_H_
