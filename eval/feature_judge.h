// The feature judge: a denoising autoencoder trained on real clips (normalized
// features, Gaussian noise and dropped channels in, the clean clip out). Its
// hidden layer is the fixed motion network the distribution and distance
// metrics read (docs/notes/contrastive.md "Metrics"): FMD, KID, diversity, content
// distance and style (Gram) distance. Torch stays in the .cc.
#ifndef STYLUS_EVAL_FEATURE_JUDGE_H_
#define STYLUS_EVAL_FEATURE_JUDGE_H_

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "model/package.h"
#include "motion/motion.h"

namespace stylus::model {

// Hidden features of a clip: `channels` rows of `frames` values (half the
// clip's frames), channel major.
struct FeatureMap {
  int channels = 0, frames = 0;
  std::vector<float> values;
  const float* row(int c) const { return values.data() + static_cast<size_t>(c) * frames; }
};

struct DaeTrainResult {
  double noisy_mse = 0;     // Held-out: noisy input vs clean.
  double denoised_mse = 0;  // Held-out: the autoencoder's output vs clean.
  int clips = 0;
};

// Trains on the training split of `data` with the statistics of `norm` (the
// judges' own) and writes `dae.pt` into `out`.
absl::StatusOr<DaeTrainResult> TrainFeatureJudge(
    const std::vector<std::string>& data, const std::string& out, int iterations, uint64_t seed,
    const std::function<void(const std::string&)>& log);

class FeatureJudge {
 public:
  // Reads norm.txt, skeleton.bvh and dae.pt from `dir` (a judges directory).
  static absl::StatusOr<std::unique_ptr<FeatureJudge>> Load(const std::string& dir);
  ~FeatureJudge();
  // INVALID_ARGUMENT for a clip the judges cannot take. Thread-safe.
  absl::StatusOr<FeatureMap> Features(const motion::Motion& clip) const;

 private:
  struct Impl;
  explicit FeatureJudge(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Clip embedding for distribution metrics: each channel's temporal mean and
// standard deviation.
std::vector<double> Embedding(const FeatureMap& f);
// Frechet distance between Gaussian fits of two embedding sets.
double FrechetDistance(const std::vector<std::vector<double>>& a,
                       const std::vector<std::vector<double>>& b);
// Unbiased MMD^2 with the kernel (x.y / d + 1)^3 over `subsets` random subsets
// of `subset_size` from each set (seeded): mean and standard deviation.
std::pair<double, double> KernelInceptionDistance(const std::vector<std::vector<double>>& a,
                                                  const std::vector<std::vector<double>>& b,
                                                  int subsets, int subset_size, uint64_t seed);
// Mean Euclidean distance between `pairs` random pairs of the set (seeded).
double Diversity(const std::vector<std::vector<double>>& set, int pairs, uint64_t seed);
// Mean squared difference of two feature maps over their common frames.
double ContentDistance(const FeatureMap& a, const FeatureMap& b);
// Squared Frobenius distance of the Gram matrices (H H^T / frames), per entry.
double StyleDistance(const FeatureMap& a, const FeatureMap& b);

}  // namespace stylus::model

#endif  // STYLUS_EVAL_FEATURE_JUDGE_H_
