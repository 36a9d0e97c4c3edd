// Inference with a trained `contrastive` model (paper 000; docs/families.md):
// encode a style, transfer it onto a content clip of any length window by
// window, interpolate between styles, stream.
//
// Thread-safety: after Load, all const methods may be called concurrently; each
// runs its forward passes under c10::InferenceMode on the calling thread.
// Errors: INVALID_ARGUMENT for a clip the model cannot take (another skeleton
// or frame rate, non-finite values, no frames, bad weights); INTERNAL when
// LibTorch fails (the message names the model).
#ifndef STYLUS_MODEL_CONTRASTIVE_CONTRASTIVE_MODEL_H_
#define STYLUS_MODEL_CONTRASTIVE_CONTRASTIVE_MODEL_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "model/contrastive/contrastive_config.h"
#include "model/contrastive/live_carry.h"
#include "model/family_registry.h"
#include "model/style_model.h"
#include "motion/features.h"
#include "motion/motion.h"

namespace stylus::model {

class ContrastiveModel : public StyleModel {
 public:
  // Reads and validates the package in `dir` (model/package.h) and its weights.
  // NOT_FOUND for a missing file; INVALID_ARGUMENT (naming the file) for a
  // corrupt or mismatched one.
  // `overrides`: config.txt lines read after the package's own (inference
  // keys only; family_registry.h).
  static absl::StatusOr<std::unique_ptr<ContrastiveModel>> Load(const std::string& dir,
                                                                const std::string& overrides = "");
  ~ContrastiveModel() override;

  const ContrastiveConfig& config() const;
  const std::string& dir() const override;
  const DataFiles& data() const override;
  ModelSummary summary() const override;

  int code_size() const override;

  // Live packages (config().live; docs/families.md "Live packages"): a
  // stream runs one frame per step through the causal networks, with the
  // state each stream carries in a LiveCarry.
  // The generator's per-frame scale and bias for `style`, computed once per
  // style. INVALID_ARGUMENT for a code of another size.
  absl::StatusOr<std::vector<float>> LiveStyleParams(const StyleCode& style) const;
  // A stream's state before its first frame. Empty for an offline package.
  LiveCarry NewLiveCarry() const;
  // Steps each stream one feature frame, all in one forward pass: steps[i]'s
  // output is the generated frame of the feature frame config().lookahead - 1
  // steps before its input (the first lookahead - 1 outputs of a stream
  // stand for no frame). FAILED_PRECONDITION for an offline package.
  absl::Status StepLive(const std::vector<LiveStep>& steps) const;
  // Live packages: the steps of LiveStreamers opened on this model.
  absl::Status StepStreams(const std::vector<FrameStreamer*>& cores) const override;

  // Lower-level steps of Transfer, for streaming (model/contrastive/window_streamer.h).
  // The clip's normalized features, checked as Transfer checks a content clip
  // and not padded.
  // `sign_reference`: see motion::ExtractFeatures.
  absl::StatusOr<motion::FeatureClip> NormalizedFeatures(
      const motion::Motion& clip, const std::string& what,
      const std::vector<motion::Quat>* sign_reference = nullptr) const;
  // The generator's output (normalized features, (dim, window) per window,
  // channel major, one after another) for the windows of `features` starting
  // at `starts`, window i with style codes[i]. Every window must fit inside
  // `features`.
  absl::StatusOr<std::vector<float>> GenerateWindows(const motion::FeatureClip& features,
                                                     const std::vector<int>& starts,
                                                     const std::vector<StyleCode>& codes) const;

 protected:
  // The mean style code over the clip's windows (clips shorter than a window
  // are padded by repeating their last frame).
  absl::StatusOr<StyleCode> EncodeModelRateStyle(const motion::Motion& clip) const override;
  // Streams window by window (model/contrastive/window_streamer.h), or, for
  // a live package, frame by frame (model/contrastive/live_streamer.h).
  absl::StatusOr<std::unique_ptr<FrameStreamer>> OpenModelRateStream(
      const StreamSpec& spec) const override;
  // Each window uses sum_k w_k s_k, the weights taken at the window's centre
  // frame. Guard form k is the residual form at strength k: the content
  // plus k times the change the style makes.
  absl::StatusOr<std::unique_ptr<Forms>> PrepareTransfer(
      const motion::Motion& content, const std::vector<StyleCode>& styles,
      const StyleWeights& weights, PassBatcher* batcher) const override;
  const ContentGuard* content_guard() const override;
  const GuardKeys& guard_keys() const override;
  const MovementKeys& movement_keys() const override;

 private:
  class ClipForms;
  class LiveForms;
  struct Impl;
  explicit ContrastiveModel(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The registry's entry for this family (model/family_registry.h).
ModelFamily ContrastiveFamily();

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CONTRASTIVE_CONTRASTIVE_MODEL_H_
