// Inference with a trained `contrastive` model: encode a style, transfer it onto
// a content clip of any length, interpolate between styles.
//
// Thread-safety: after Load, all const methods may be called concurrently; each
// runs its forward passes under c10::InferenceMode on the calling thread.
// Errors: INVALID_ARGUMENT for a clip the model cannot take (another skeleton
// or frame rate, non-finite values, no frames, bad weights); INTERNAL when
// LibTorch fails (the message names the model).
#ifndef STYLUS_MODEL_CONTRASTIVE_MODEL_H_
#define STYLUS_MODEL_CONTRASTIVE_MODEL_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "model/package.h"
#include "motion/features.h"
#include "motion/motion.h"
#include "motion/postprocess.h"
#include "model/style_model.h"

namespace stylus::model {

class ContrastiveModel : public StyleModel {
 public:
  // Reads and validates the package in `dir` (see package.h) and its weights.
  // NOT_FOUND for a missing file; INVALID_ARGUMENT (naming the file) for a
  // corrupt or mismatched one.
  static absl::StatusOr<std::unique_ptr<ContrastiveModel>> Load(const std::string& dir);
  ~ContrastiveModel() override;

  const PackageContents& package() const;
  const std::string& dir() const override;
  const DataFiles& data() const override { return package(); }
  ModelSummary summary() const override;

  // The mean style code over the clip's windows (clips shorter than a window
  // are padded by repeating their last frame).
  absl::StatusOr<StyleCode> EncodeStyle(const motion::Motion& clip) const override;

  // Transfer with a blend of `styles`: each window uses sum_k w_k s_k, the
  // weights taken at the window's centre frame.
  absl::StatusOr<motion::Motion> Interpolate(
      const motion::Motion& content, const std::vector<StyleCode>& styles,
      const StyleWeights& weights,
      motion::PostProcessMode post = motion::PostProcessMode::kFull) const override;
  absl::StatusOr<motion::Motion> InterpolateNoted(const motion::Motion& content,
                                                  const std::vector<StyleCode>& styles,
                                                  const StyleWeights& weights,
                                                  motion::PostProcessMode post,
                                                  TransferNote* note) const override;

  // Lower-level steps of Transfer, for streaming (model/stream_transfer.h).
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

 private:
  struct Impl;
  explicit ContrastiveModel(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CONTRASTIVE_MODEL_H_
