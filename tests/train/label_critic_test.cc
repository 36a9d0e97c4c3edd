// train/label_critic: the critic of label-guided training.
#include "train/label_critic.h"

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
#include "train/training_set.h"
#include "train/weight_average.h"

namespace stylus::model {
namespace {

using ::stylus::testing::MotionOf;
using namespace contrastive_testing;  // NOLINT: the trainer's test fixtures.

namespace fs = std::filesystem;

// The label critic learns the labels of real windows; its verdict on a
// window is the label loss, differentiable in the window.
TEST(LabelCriticTest, LearnsTheLabelsAndJudgesDifferentiably) {
  torch::manual_seed(7);
  LabelCritic critic(4, 2, 2);
  const torch::Tensor t = torch::arange(16, torch::kFloat32);
  auto windows = [&](double freq) {
    return torch::sin(t * freq).view({1, 1, 16}).expand({8, 4, 16}) +
           0.1 * torch::randn({8, 4, 16});
  };
  const torch::Tensor zeros = torch::zeros({8}, torch::kLong),
                      ones = torch::ones({8}, torch::kLong);
  // Slow sines are style 0 / content 0, fast ones style 1 / content 1.
  auto learn = [&] {
    return critic.Learn({{windows(0.2), zeros, zeros}, {windows(1.1), ones, ones}});
  };
  const double first = learn();
  double last = first;
  for (int i = 0; i < 100; ++i) last = learn();
  std::printf("label loss %.4f -> %.4f\n", first, last);
  EXPECT_LT(last, 0.2 * first);

  const torch::Tensor x = windows(1.1).requires_grad_();
  const torch::Tensor verdict = critic.Verdict(x, ones, zeros, 2.0);
  EXPECT_NEAR(verdict.item<double>(),
              LabelLoss(critic.net()->forward(x), ones, zeros, 2.0).item<double>(), 1e-6);
  verdict.backward();
  EXPECT_GT(x.grad().abs().sum().item<double>(), 0);

  std::vector<TorchFile> files;
  critic.AddFiles("critic", "opt_c", &files);
  std::vector<std::string> names;
  for (const TorchFile& f : files) names.push_back(f.name);
  EXPECT_EQ(names, (std::vector<std::string>{"critic.pt", "opt_c.pt"}));
}

}  // namespace
}  // namespace stylus::model
