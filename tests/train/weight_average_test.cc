// train/weight_average: the running mean of sampled weights.
#include "train/weight_average.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <sstream>

#include "gtest/gtest.h"
#include "model/contrastive/contrastive_model.h"
#include "model/contrastive/contrastive_net.h"
#include "model/guard_net.h"
#include "model/weights_io.h"
#include "motion/bvh.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"
#include "motion/normalization.h"
#include "motion/windowing.h"
#include "tests/model/synth_clips.h"
#include "tests/model/transfer_support.h"
#include "tests/test_support.h"
#include "tests/train/contrastive_training_support.h"
#include "train/clip_classes.h"
#include "train/contrastive_trainer.h"
#include "train/label_critic.h"
#include "train/training_set.h"

namespace stylus::model {
namespace {

using ::stylus::testing::MotionOf;
using namespace contrastive_testing;  // NOLINT: the trainer's test fixtures.

namespace fs = std::filesystem;

TEST(WeightAverageTest, FoldsSamplesIntoTheirMean) {
  EXPECT_EQ(AveragedSamples(19, 20, 10), 0);
  EXPECT_EQ(AveragedSamples(20, 20, 10), 1);
  EXPECT_EQ(AveragedSamples(39, 20, 10), 2);
  EXPECT_EQ(AveragedSamples(100, 0, 10), 0);  // Off.
  EXPECT_TRUE(IsAveragedIteration(30, 20, 10));
  EXPECT_FALSE(IsAveragedIteration(31, 20, 10));
  EXPECT_FALSE(IsAveragedIteration(10, 20, 10));
  torch::nn::Linear net(3, 2), average(3, 2);
  std::vector<torch::Tensor> seen;
  for (int i = 1; i <= 3; ++i) {
    {
      torch::NoGradGuard g;
      net->weight.normal_();
    }
    seen.push_back(net->weight.clone());
    FoldIntoAverage(*net, average.get(), i);
  }
  EXPECT_TRUE(torch::allclose(average->weight, (seen[0] + seen[1] + seen[2]) / 3, 1e-6, 1e-6));
}

}  // namespace
}  // namespace stylus::model
