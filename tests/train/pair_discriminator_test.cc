// train/pair_discriminator: the label-conditional discriminator.
#include "train/pair_discriminator.h"

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
#include "train/weight_average.h"

namespace stylus::model {
namespace {

using ::stylus::testing::MotionOf;
using namespace contrastive_testing;  // NOLINT: the trainer's test fixtures.

namespace fs = std::filesystem;

TEST(PairDiscriminatorTest, JudgesTheLabelPairNotOnlyTheWindow) {
  // Two kinds of window (a slow and a fast sine), real only under their own
  // (style, content) pair: the same window under another pair must come out
  // fake, which a discriminator blind to the labels cannot do.
  torch::manual_seed(5);
  PairDiscriminator d(3, 2, 2, 16);
  torch::optim::Adam opt(d->parameters(), torch::optim::AdamOptions(2e-3));
  const torch::Tensor t = torch::arange(16, torch::kFloat32);
  auto windows = [&](double freq) {
    return torch::sin(t * freq).view({1, 1, 16}).expand({8, 3, 16}) +
           0.1 * torch::randn({8, 3, 16});
  };
  const torch::Tensor zeros = torch::zeros({8}, torch::kLong),
                      ones = torch::ones({8}, torch::kLong);
  namespace F = torch::nn::functional;
  for (int i = 0; i < 150; ++i) {
    const torch::Tensor slow = windows(0.2), fast = windows(1.1);
    opt.zero_grad();
    const torch::Tensor loss =
        F::softplus(-d->forward(slow, zeros, zeros)).mean() +
        F::softplus(-d->forward(fast, ones, ones)).mean() +
        F::softplus(d->forward(slow, ones, zeros)).mean() +  // Slow under another style.
        F::softplus(d->forward(fast, ones, zeros)).mean();   // Fast under another content.
    loss.backward();
    opt.step();
  }
  torch::NoGradGuard no_grad;
  const torch::Tensor slow = windows(0.2), fast = windows(1.1);
  EXPECT_GT(d->forward(slow, zeros, zeros).mean().item<double>(),
            d->forward(slow, ones, zeros).mean().item<double>() + 2);
  EXPECT_GT(d->forward(fast, ones, ones).mean().item<double>(),
            d->forward(fast, ones, zeros).mean().item<double>() + 2);
}

}  // namespace
}  // namespace stylus::model
