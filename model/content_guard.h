// The content guard of a package (either family): a classifier of the action
// (content label) trained on the package's own normalized features of real
// training clips, and used at inference to check that a transfer still reads
// as the action its content clip reads as. When it does not, the model backs
// off the style (ContrastiveConfig::content_guard, docs/contrastive.md,
// session 14). Its design is the label critic's (model/label_critic_net.h),
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

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/features.h"

namespace stylus::model {

struct ContentGuardTrainOptions {
  std::string model;              // The package the guard is trained for and written into.
  std::vector<std::string> data;  // Labelled dataset directories (their training split).
  int iterations = 3000;
  int batch = 32;
  double lr = 1e-3;
  uint64_t seed = 1;  // Guard k (1-based) uses seed + k - 1.
  int guards = 3;
  std::function<void(const std::string&)> log;  // Default: stderr.
};

struct ContentGuardAccuracy {
  // Clip-level accuracy on the held-out split: the ensemble's content
  // verdict, and each guard's own.
  double content = 0;
  std::vector<double> each;
  int clips = 0;
};

// Trains the guards on the training split of `data`, normalized with the
// package's statistics, writes their files into the package and returns
// their held-out accuracy. NOT_FOUND / INVALID_ARGUMENT as for loading
// the package or the data.
absl::StatusOr<ContentGuardAccuracy> TrainContentGuard(const ContentGuardTrainOptions& options);

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
