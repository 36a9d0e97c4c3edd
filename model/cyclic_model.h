// Inference with a trained `cyclic` model (paper 004, docs/cyclic.md): the
// whole clip goes through the convolutional autoencoder at once (no windows),
// the style transform restyles its hidden features, the inference-time
// kinematic optimization (when the package was trained with kinematic
// constraints and kc_iters > 0) adjusts them, and the generated joint
// positions become rotations (motion/position_fit.h) on the content's
// skeleton, twist taken from the content.
#ifndef STYLUS_MODEL_CYCLIC_MODEL_H_
#define STYLUS_MODEL_CYCLIC_MODEL_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "model/cyclic_config.h"
#include "model/style_model.h"

namespace stylus::model {

struct CyclicOptions {
  int kc_iters = -1;  // Inference-time optimization steps; -1: the package's.
  // A probe, not a product mode: replace the learned style transform by a
  // parameter-free AdaIN that gives the content's hidden features exactly the
  // style code's per-channel mean and spread (the most the code says).
  bool adain = false;
};

class CyclicModel : public StyleModel {
 public:
  // Reads and validates the package in `dir` and its weights. NOT_FOUND for
  // a missing file; INVALID_ARGUMENT (naming the file) for a corrupt or
  // mismatched one.
  static absl::StatusOr<std::unique_ptr<CyclicModel>> Load(const std::string& dir,
                                                           CyclicOptions options = {});
  ~CyclicModel() override;

  const CyclicConfig& config() const;
  const std::string& dir() const override;
  const DataFiles& data() const override;
  ModelSummary summary() const override;

  // The mean and standard deviation over time of the clip's hidden features
  // (2 x hidden values).
  absl::StatusOr<StyleCode> EncodeStyle(const motion::Motion& clip) const override;
  // With per-frame weights, each hidden step (two frames) gets the blend of
  // its first frame.
  absl::StatusOr<motion::Motion> Interpolate(
      const motion::Motion& content, const std::vector<StyleCode>& styles,
      const StyleWeights& weights,
      motion::PostProcessMode post = motion::PostProcessMode::kFull) const override;
  // With a content guard (CyclicConfig::content_guard), says what it did.
  absl::StatusOr<motion::Motion> InterpolateNoted(const motion::Motion& content,
                                                  const std::vector<StyleCode>& styles,
                                                  const StyleWeights& weights,
                                                  motion::PostProcessMode post,
                                                  TransferNote* note) const override;

 private:
  struct Impl;
  explicit CyclicModel(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CYCLIC_MODEL_H_
