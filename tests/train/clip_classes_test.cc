// train/clip_classes: labels from clip names, references drawn by label.
#include "train/clip_classes.h"

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
#include "motion/bvh.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"
#include "motion/normalization.h"
#include "motion/windowing.h"
#include "tests/model/synth_clips.h"
#include "tests/model/transfer_support.h"
#include "tests/test_support.h"
#include "tests/train/contrastive_training_support.h"
#include "train/contrastive_trainer.h"
#include "train/training_set.h"

namespace stylus::model {
namespace {

using ::stylus::testing::MotionOf;
using namespace contrastive_testing;  // NOLINT: the trainer's test fixtures.

namespace fs = std::filesystem;
using testing::LabelledClips;

TEST(ClipClassesTest, DrawsReferencesByLabel) {
  const std::vector<std::string> paths = {
      "d/dataset-1_walk_old_001.bvh", "d/dataset-1_run_old_001.bvh",
      "d/dataset-1_walk_proud_001.bvh", "d/dataset-1_bow_proud_001.bvh",
      "d/dataset-1_walk_angry_001.bvh"};
  // The last clip is too short to be drawn.
  absl::StatusOr<ClipClasses> c = ClipClasses::FromPaths(paths, {true, true, true, true, false});
  ASSERT_TRUE(c.ok()) << c.status();
  EXPECT_EQ(c->styles, (std::vector<std::string>{"angry", "old", "proud"}));
  EXPECT_EQ(c->contents, (std::vector<std::string>{"bow", "run", "walk"}));
  std::mt19937_64 rng(1);
  std::set<int> drawn_other;
  for (int i = 0; i < 200; ++i) {
    EXPECT_EQ(c->SameStyle(0, &rng), 1);  // Old, and running rather than walking.
    EXPECT_EQ(c->SameStyle(2, &rng), 3);
    const int other = c->OtherStyle(0, &rng);
    EXPECT_NE(c->style_of[other], c->style_of[0]);
    EXPECT_NE(other, 4);  // Never the unusable clip.
    drawn_other.insert(other);
  }
  // Another style, preferring another content: the proud bow.
  EXPECT_EQ(drawn_other, (std::set<int>{3}));
  // Alone in its style: itself.
  EXPECT_EQ(c->SameStyle(4, &rng), 4);

  absl::StatusOr<ClipClasses> bad = ClipClasses::FromPaths({"d/take1.bvh"}, {true});
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad.status().message().find("d/take1.bvh"), std::string::npos);
}

// --content-balance: the walk has twice the windows of the run and the turn;
// balanced fully, the three actions are drawn alike, and windows keep coming
// from both walks.
TEST(ClipClassesTest, ContentBalanceDrawsEveryActionAlike) {
  absl::StatusOr<TrainingSet> data = LoadTrainingSet(LabelledClips(), {16, 12});
  ASSERT_TRUE(data.ok()) << data.status();
  absl::StatusOr<ClipClasses> c = ClipClasses::ForTraining(*data, 16, {});
  ASSERT_TRUE(c.ok()) << c.status();
  ASSERT_EQ(c->contents, (std::vector<std::string>{"run", "turn", "walk"}));
  const auto drawn = [&](std::vector<double>* share_of_content) {
    std::mt19937_64 rng(5);
    std::vector<float> buf;
    std::vector<int> clips, per_clip(4, 0);
    share_of_content->assign(3, 0.0);
    const int n = 6000;
    for (int i = 0; i < n / 20; ++i) {
      data->SampleBatch(20, 16, &rng, &buf, &clips);
      for (int clip : clips) {
        ++per_clip[clip];
        (*share_of_content)[c->content_of[clip]] += 1.0 / n;
      }
    }
    return per_clip;
  };
  std::vector<double> share;
  drawn(&share);
  EXPECT_NEAR(share[2], 0.5, 0.03);  // Uniform over windows: the walks' half.

  const std::vector<double> planned = data->BalanceWindows(c->content_of, 1.0);
  for (double p : planned) EXPECT_NEAR(p, 1.0 / 3, 1e-9);
  const std::vector<int> per_clip = drawn(&share);
  for (double s : share) EXPECT_NEAR(s, 1.0 / 3, 0.03);
  EXPECT_GT(per_clip[0], 700);  // Both walks still drawn (~1000 each).
  EXPECT_GT(per_clip[1], 700);

  const std::vector<double> half = data->BalanceWindows(c->content_of, 0.5);
  EXPECT_NEAR(half[2], std::sqrt(2.0) / (2 + std::sqrt(2.0)), 1e-9);
  data->BalanceWindows(c->content_of, 0.0);
  drawn(&share);
  EXPECT_NEAR(share[2], 0.5, 0.03);
}

}  // namespace
}  // namespace stylus::model
