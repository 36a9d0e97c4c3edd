// Inference with a trained `cyclic` model (paper 004, docs/notes/cyclic.md): the
// whole clip goes through the convolutional autoencoder at once (no windows),
// the style transform restyles its hidden features, the inference-time
// kinematic optimization (when the package was trained with kinematic
// constraints and kc_iters > 0) adjusts them, and the generated joint
// positions become rotations (motion/position_fit.h) on the content's
// skeleton, twist taken from the content.
#ifndef STYLUS_MODEL_CYCLIC_CYCLIC_MODEL_H_
#define STYLUS_MODEL_CYCLIC_CYCLIC_MODEL_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "model/cyclic/cyclic_config.h"
#include "model/family_registry.h"
#include "model/style_model.h"

namespace stylus::model {

class CyclicModel : public StyleModel {
 public:
  // Reads and validates the package in `dir` and its weights. NOT_FOUND for
  // a missing file; INVALID_ARGUMENT (naming the file) for a corrupt or
  // mismatched one.
  // `overrides`: config.txt lines read after the package's own (inference
  // keys only; family_registry.h).
  static absl::StatusOr<std::unique_ptr<CyclicModel>> Load(const std::string& dir,
                                                           const std::string& overrides = "");
  ~CyclicModel() override;

  const CyclicConfig& config() const;
  const std::string& dir() const override;
  const DataFiles& data() const override;
  ModelSummary summary() const override;

  int code_size() const override;

 protected:
  // The style network's code of the clip (with style_dim = 0: the mean and
  // standard deviation over time of its hidden features, 2 x hidden values).
  absl::StatusOr<StyleCode> EncodeModelRateStyle(const motion::Motion& clip) const override;
  // The whole clip at once; with per-frame weights, each hidden step (two
  // frames) gets the blend of its first frame. Guard form k restyles the
  // hidden features k of the way. The kinematic optimization runs on the
  // chosen form only.
  absl::StatusOr<std::unique_ptr<Forms>> PrepareTransfer(const motion::Motion& content,
                                                         const std::vector<StyleCode>& styles,
                                                         const StyleWeights& weights,
                                                         PassBatcher* batcher) const override;
  const ContentGuard* content_guard() const override;
  const GuardKeys& guard_keys() const override;
  const MovementKeys& movement_keys() const override;

 private:
  class ClipForms;
  struct Impl;
  explicit CyclicModel(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// The registry's entry for this family (model/family_registry.h).
ModelFamily CyclicFamily();

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CYCLIC_CYCLIC_MODEL_H_
