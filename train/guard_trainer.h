// Training a package's content guard (model/content_guard.h):
// `stylus-tool train-guard`.
#ifndef STYLUS_TRAIN_GUARD_TRAINER_H_
#define STYLUS_TRAIN_GUARD_TRAINER_H_

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"

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

}  // namespace stylus::model

#endif  // STYLUS_TRAIN_GUARD_TRAINER_H_
