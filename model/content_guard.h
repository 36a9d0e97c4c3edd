// The content guard of a package (any family): a classifier of the action
// (content label) trained on the package's own normalized features of real
// training clips (train/guard_trainer.h), and used at inference to check
// that a transfer still reads as the action its content clip reads as. When
// it does not, StyleModel::Interpolate backs off the style (GuardKeys,
// model/config_text.h; docs/families.md). Its network is model/guard_net.h,
// deliberately unlike the evaluation judges. The header is torch-free.
//
// It is an ensemble of `guards` such classifiers, trained alike from
// different seeds, whose probabilities are averaged: one classifier's verdict
// on a transfer near its boundary depends on its draw.
//
// Files in the package: guard_1.pt ... guard_K.pt (weights) and guard.txt
// (the labels, how they were trained and their held-out accuracy).
#ifndef STYLUS_MODEL_CONTENT_GUARD_H_
#define STYLUS_MODEL_CONTENT_GUARD_H_

#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/features.h"

namespace stylus::model {

// The guard's files in the package `dir`: guard.txt (labels, provenance,
// held-out accuracy) and the weights of guard k (1-based).
std::string ContentGuardInfoPath(const std::string& dir);
std::string ContentGuardWeightsPath(const std::string& dir, int k);

class ContentGuard {
 public:
  // Reads guard.txt and the guards' weights from the package `dir` whose features are
  // `dim` wide, read in windows of `window` frames at hop `hop`. NOT_FOUND for
  // a missing file, INVALID_ARGUMENT (naming the file) for a malformed one.
  static absl::StatusOr<std::unique_ptr<ContentGuard>> Load(const std::string& dir, int dim,
                                                            int window, int hop);
  ~ContentGuard();

  const std::vector<std::string>& contents() const;
  // One probability per label of contents() for the clip: each guard's
  // softmax of its content logits averaged over the clip's windows (a clip
  // shorter than a window is padded with its last frame), averaged over the
  // guards. `normalized` as the package's statistics normalize it.
  // Thread-safe.
  std::vector<double> Probabilities(const motion::FeatureClip& normalized) const;
  // Index into contents() of the likeliest action.
  int Classify(const motion::FeatureClip& normalized) const;
  // Whether the likeliest action of the clip is `action`, with at least
  // `min_probability` (GuardKeys::guard_min_probability).
  bool Keeps(const motion::FeatureClip& normalized, int action, double min_probability) const;

 private:
  struct Impl;
  explicit ContentGuard(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace stylus::model

#endif  // STYLUS_MODEL_CONTENT_GUARD_H_
