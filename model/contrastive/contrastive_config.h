// Hyper-parameters of the `contrastive` family (paper 000, docs/notes/contrastive.md),
// stored in a model package as `config.txt` (key = value lines).
#ifndef STYLUS_MODEL_CONTRASTIVE_CONTRASTIVE_CONFIG_H_
#define STYLUS_MODEL_CONTRASTIVE_CONTRASTIVE_CONFIG_H_

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "model/config_text.h"
#include "motion/contacts.h"

namespace stylus::model {

// The content guard's keys (GuardKeys, model/config_text.h): a weaker
// style is the residual form (the content plus the change the style makes)
// at that strength.
struct ContrastiveConfig : GuardKeys, MovementKeys {
  // Architecture: fixed when the network is trained.
  int window = 32;     // T frames per window.
  int hop = 24;        // Window stride (overlap T/4).
  int dim = 0;         // Feature channels d (set from the data).
  int channels = 144;  // Width of codes and hidden layers.
  int res_kernel = 3;  // Kernel of the residual blocks' convolutions.
  // A live package (docs/families.md "Live packages"): causal content encoder
  // and generator (model/contrastive/live_net.h) that stream one frame per
  // step, output frame t final once input frame t + lookahead has arrived
  // (1 or 2; the features take one of those frames: motion/features.h).
  // Its features' foot contacts measure height above the lowest point so
  // far (ContactParams::running_floor), so no feature waits for a clip's end.
  // The inference keys that need a whole window (smooth_sigma, residual,
  // content_detail, the content guard) are refused.
  bool live = false;
  int lookahead = 2;
  // Live only: the generator gives the change to each content frame (its
  // output is added to the frame's features), so what it does not change of
  // the content's motion is kept as it came.
  bool frame_residual = false;
  // Live only: residual block b of each network (from 0) has its
  // convolutions dilated by dilation_growth^b, so the networks see further
  // back for the same cost per frame (1: no dilation; 2: the generator's
  // three blocks look 2, 4 and 8 frames apart per tap).
  int dilation_growth = 1;
  // The style encoder reads how each feature changes from frame to frame
  // (FrameChanges, contrastive_net.h), not the features themselves: a style
  // code can say how the body moves (gait, rhythm, amplitude) but not how it
  // is posed. A style clip that does not move has one code whatever its pose.
  bool style_from_motion = false;
  // Offline only: the content code squeezed through `bottleneck_channels`
  // channels (0: off), instance-normalized there, and averaged over
  // `bottleneck_pool` of its steps (1: every step; the code runs at half the
  // frame rate), then widened again for the generator: a code that can say
  // what is done and when (the action and its phase), and less of the
  // clip's own way of doing it. Measured from scratch, it keeps the action
  // better but does not give the legs the style's gait
  // (docs/notes/motion_style.md "A content bottleneck").
  int bottleneck_channels = 0;
  int bottleneck_pool = 1;
  // Offline only: after its AdaIN blocks the generator filters each of its
  // channels over time with a kernel of `style_filter_taps` steps (odd; 0:
  // off) that the style code chooses (StyleFilter, contrastive_net.h). AdaIN
  // scales and shifts a channel; it cannot delay, smooth or sharpen it, so
  // with AdaIN alone the timing between joints is the content's. Measured:
  // the raw output's steps move towards the style's pace, the motion-only
  // judge does not (docs/notes/motion_style.md "A style-chosen temporal
  // filter").
  int style_filter_taps = 0;
  // Inference keys (InferenceKeys(), with the guard's of GuardKeys; may be
  // set at load time). With `keep_path`, a transfer's root trajectory and
  // foot contacts are the content clip's (the style restyles the body along
  // the content's path).
  bool keep_path = false;
  // Inference: a Gaussian of this many frames (sigma; 0: off) over time on
  // each generated window's pose channels (positions and rotations): the
  // generator's frame-to-frame shake removed before windows are cross-faded,
  // alike for whole clips and streams (docs/postprocess.md).
  double smooth_sigma = 0;
  // Inference: how far each window's style moves from the content window's
  // own style code towards the requested one, k in [0, 1]: the generator gets
  // k * requested + (1 - k) * Es(content window). 1 (the default): the
  // requested style alone; 0: the content restyled with itself. Per window,
  // so whole clips and streams stay alike (docs/notes/contrastive.md).
  // A live package has no content window to encode: there, each generated
  // frame's pose moves k of the way from the content frame's towards the
  // generator's.
  double style_strength = 1;
  // Inference: with `residual`, each window is the content window plus
  // G(Ec(x), style) - G(Ec(x), Es(x)), the change the style makes in the
  // generator's output (smoothed by smooth_sigma), so what the generator
  // fails to reproduce of the content is not lost (docs/notes/contrastive.md).
  // Training with it (`train --residual`) trains the transfers in this form.
  bool residual = false;
  // Inference: with `content_detail` k in (0, 1], each generated window's
  // pose channels also take k times the content window's own detail, what a
  // Gaussian of `detail_sigma` frames (0: smooth_sigma) removes from it: the
  // generator's output sets the slow part of the motion (posture, the
  // reach of a gesture), the content keeps its quick part (when a hand
  // moves, and that a held hand stays still). The frequency split of
  // spectral style transfer (docs/notes/contrastive.md). Not with
  // `residual`, whose output already carries the whole content window.
  double content_detail = 0;
  double detail_sigma = 0;
  // Training keys: how the package was trained; inference ignores them.
  // Loss weights: L = L_rec + a L_gan + b L_nce + c L_tri.
  double alpha = 1.0, beta = 0.3, gamma = 0.3;
  double margin = 1.0;       // Triplet margin.
  double temperature = 0.1;  // InfoNCE temperature on unit-length codes.
  bool use_nce = true, use_tri = true;
  // Style view (docs/notes/contrastive.md): with `cross_view`, the style code of a
  // window is taken from another window of the same clip, so it can only carry
  // what the whole clip shares; without, from the window itself (the paper).
  bool cross_view = true;
  // Weight of a content-keeping term on the transfer M_G (0: off): the L1
  // distance between M_G and its content input M_T over the channels that say
  // what is being done and where: root trajectory, foot contacts and the
  // legs' positions and rotations (docs/notes/contrastive.md).
  double content_weight = 0;
  // Weight of a style term on how the transfer moves (0: off): the L1
  // distance between Gram matrices (paper 004's style statistics) of the
  // transfer's dynamics and a real window's of the target style, doing the
  // content's action when the data has it. Dynamics: per frame, each joint's
  // velocity relative to the root in its facing frame and the root's own
  // velocities, and their changes (accelerations), each channel scaled to
  // unit deviation over the training data (docs/notes/motion_style.md).
  double dynamics_weight = 0;
  // Label-guided training only: critics that read only how the body moves
  // (the same dynamics, velocities and accelerations, no static pose).
  // `motion_gan_weight`: the generator's loss against a label-conditional
  // discriminator on the dynamics (real: real windows under their own
  // labels; fake: the transfer, and the content and style windows under the
  // transfer's labels). `motion_class_weight`: the cross-entropy of a
  // dynamics classifier, trained on real windows only, against the target
  // style and the content's action (docs/notes/motion_style.md). 0: off.
  double motion_gan_weight = 0;
  double motion_class_weight = 0;
  // The content half of the motion classifier's verdict, times this; unset:
  // `content_class_weight`, as for the pose critic. Lower, the classifier
  // asks for the style's motion more than for the content's action in it.
  std::optional<double> motion_content_weight;
  double MotionContentWeight() const {
    return motion_content_weight.value_or(content_class_weight);
  }
  // Label-guided training only: weight of an L1 term between each transfer
  // and a real window of the content's action performed in the target
  // style, the one whose content code is nearest the content window's
  // (train/paired_target.h); every channel but the root path's. 0: off.
  double paired_weight = 0;
  // Label-guided training only: terms on the generator's fidelity to how a
  // clip moves. `motion_rec_weight`: W x the L1 distance between the
  // frame-to-frame changes of the pose channels (as FrameChanges scales
  // them) of the reconstruction and the cycle and those of the content
  // window. `own_rec_weight`: W x the L1 distance, on the features and on
  // those changes, between the content window and its rendering with its
  // own style code (the reconstruction otherwise takes another clip's of
  // the same style, which cannot say how this clip moves). 0: off.
  double motion_rec_weight = 0;
  double own_rec_weight = 0;
  // Distillation (train/teacher.h): weight of an L1 term on the pose
  // channels between the transfer and the `teacher` package's transfer of
  // the same content window to the same style window (0: off). `teacher` is
  // the package's directory, as given to training. `teacher_strength` k < 1
  // distils the teacher's weaker form, the one its content guard backs off
  // to: the content plus k times the change the style makes.
  double teacher_weight = 0;
  std::string teacher;
  double teacher_strength = 1;
  // Label-guided training (docs/notes/contrastive.md, "Label-guided training"):
  // style labels choose the style clips (the reconstruction's style code from
  // a clip of the same style doing something else, the transfer's from a clip
  // of another style), and a critic trained on the labels of real windows
  // judges each transfer: `class_weight` x its cross-entropy against the
  // target style and the content input's content, plus `cycle_weight` x the
  // L1 error of restyling the transfer back with the content's own style.
  bool guided = false;
  double class_weight = 1.0, cycle_weight = 1.0;
  // Guided only: the content head's share of the critic's verdict on a
  // transfer, times this (1: style and content weigh alike).
  double content_class_weight = 1.0;
  // Guided only: content windows are drawn so that a content class with n
  // training windows comes up in proportion to n^(1 - content_balance)
  // (0: uniformly over windows; 1: every class alike). Bandai's dataset-1
  // actions have 2-15 clips each against dataset-2's 70.
  double content_balance = 0.0;
  // Training: content windows start anywhere in their clip, not only on the
  // hop grid, so every clip's last frames are trained on too
  // (TrainingSet::random_starts).
  bool random_starts = false;
  // Training: left-right mirrored copies of the training clips join them,
  // their content labels' sides swapped (train/training_set.h).
  bool mirror = false;
  // Weight averaging (train/weight_average.h): from iteration
  // `average_from` on (0: off), every `average_every` iterations, the
  // generator's weights are folded into a running mean, which is what the
  // package holds.
  int average_from = 0, average_every = 50;
  // Guided only: with `pair_gan`, the adversarial term (weight alpha) is a
  // discriminator conditioned on the (style, content) label pair, which also
  // rejects the content window (identity) and the style window (copy-style)
  // under the transfer's labels (docs/notes/contrastive.md).
  bool pair_gan = false;
  // Optimization.
  int batch = 16;
  double lr = 1e-4;
  int iterations = 20000;
  uint64_t seed = 1;
  // Provenance (filled by training).
  std::string family = "contrastive";
  std::string data;    // Data directories trained on.
  std::string commit;  // Source commit of the trainer.
  int trained_iterations = 0;

  // The Gaussian that splits off the content's detail: detail_sigma, or
  // smooth_sigma when it is 0.
  double DetailSigma() const { return detail_sigma > 0 ? detail_sigma : smooth_sigma; }

  // How a package's features are extracted (motion/features.h).
  motion::ContactParams Contacts() const {
    motion::ContactParams p;
    p.running_floor = live;
    return p;
  }

  // The keys that may be set on top of a package's config.txt at load time
  // (model/family_registry.h).
  static const std::vector<std::string>& InferenceKeys();

  std::string Serialize() const;
  // INVALID_ARGUMENT naming `source` and the line of a malformed or
  // out-of-range entry; unknown keys are errors too.
  static absl::StatusOr<ContrastiveConfig> Parse(const std::string& text,
                                                 const std::string& source);
  // Reads and parses <dir>/config.txt (NOT_FOUND when missing), then the
  // lines of `overrides` as if they followed it.
  static absl::StatusOr<ContrastiveConfig> Read(const std::string& dir,
                                                const std::string& overrides = "");
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CONTRASTIVE_CONTRASTIVE_CONFIG_H_
