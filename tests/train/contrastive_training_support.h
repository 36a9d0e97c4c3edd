// Shared by the contrastive trainer's tests: tiny label-guided options on the
// synthesized labelled walks, and a run trained unbroken and resumed.
#ifndef STYLUS_TESTS_TRAIN_CONTRASTIVE_TRAINING_SUPPORT_H_
#define STYLUS_TESTS_TRAIN_CONTRASTIVE_TRAINING_SUPPORT_H_

#include <algorithm>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "model/contrastive/contrastive_config.h"
#include "tests/model/contrastive/contrastive_support.h"
#include "tests/model/synth_clips.h"
#include "train/contrastive_trainer.h"

namespace stylus::model::contrastive_testing {

// TinyOptions for label-guided training on the labelled walks.
inline ContrastiveTrainOptions GuidedOptions(const std::string& out, int iterations) {
  ContrastiveTrainOptions o = TinyOptions(out, iterations);
  o.data = testing::LabelledClips();
  o.config.guided = true;
  o.config.seed = 3;
  return o;
}

// The mean of `field` over the last `rows` rows of a loss curve.
inline double MeanOfLastRows(const std::vector<LossRecord>& curve, double LossRecord::*field,
                             int rows = 5) {
  double sum = 0;
  const int n = std::min<int>(rows, static_cast<int>(curve.size()));
  for (int i = static_cast<int>(curve.size()) - n; i < static_cast<int>(curve.size()); ++i) {
    sum += curve[i].*field;
  }
  return n > 0 ? sum / n : 0;
}

// One run of `make(dir, 80)` unbroken and one stopped at its checkpoint at
// 40 and resumed to 80: their loss curves (the resumed one from 40 on) and
// directories, for tests that a resumed run ends where an unbroken one ends.
struct ResumedRuns {
  std::vector<LossRecord> unbroken, resumed;
  std::string unbroken_dir, resumed_dir;
};

inline void TrainUnbrokenAndResumed(
    const std::string& name,
    const std::function<ContrastiveTrainOptions(const std::string&, int)>& make,
    ResumedRuns* runs) {
  ContrastiveTrainOptions unbroken = make(testing::FreshDir(name + "_a"), 80);
  unbroken.on_record = [runs](const LossRecord& r) { runs->unbroken.push_back(r); };
  ASSERT_TRUE(TrainContrastive(unbroken).ok());
  ContrastiveTrainOptions stopped = make(testing::FreshDir(name + "_b"), 40);
  ASSERT_TRUE(TrainContrastive(stopped).ok());
  ContrastiveTrainOptions resumed = make(stopped.out, 80);
  resumed.resume = true;
  resumed.on_record = [runs](const LossRecord& r) { runs->resumed.push_back(r); };
  ASSERT_TRUE(TrainContrastive(resumed).ok());
  ASSERT_EQ(runs->resumed.size(), 4u);
  runs->unbroken_dir = unbroken.out;
  runs->resumed_dir = stopped.out;
}

// The configuration of the package in `dir`.
inline absl::StatusOr<ContrastiveConfig> ReadPackageConfig(const std::string& dir) {
  std::ifstream in(dir + "/config.txt");
  std::stringstream text;
  text << in.rdbuf();
  return ContrastiveConfig::Parse(text.str(), dir + "/config.txt");
}

}  // namespace stylus::model::contrastive_testing

#endif  // STYLUS_TESTS_TRAIN_CONTRASTIVE_TRAINING_SUPPORT_H_
