// train/training_set: random window starts and mirrored clips.
#include "train/training_set.h"

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
#include "train/clip_classes.h"
#include "train/contrastive_trainer.h"

namespace stylus::model {
namespace {

using ::stylus::testing::MotionOf;
using namespace contrastive_testing;  // NOLINT: the trainer's test fixtures.

namespace fs = std::filesystem;

// A 78-frame clip on a 32-frame grid with hop 24 has windows at 0 and 24, so
// frames 56-77 are never drawn; with random_starts every frame is.
TEST(TrainingSetTest, RandomStartsReachTheClipsLastFrames) {
  TrainingSet set;
  set.norm.mean = {0}, set.norm.std = {1};
  motion::FeatureClip clip;
  clip.frames = 78, clip.dim = 1;
  for (int f = 0; f < clip.frames; ++f) clip.values.push_back(static_cast<float>(f));
  set.clips = {clip};
  const absl::StatusOr<std::vector<int>> grid_starts = motion::WindowStarts(clip.frames, {32, 24});
  ASSERT_TRUE(grid_starts.ok());
  for (int s : *grid_starts) set.windows.push_back({0, s});
  ASSERT_EQ(set.windows.size(), 2u);
  const auto frames_seen = [&] {
    std::mt19937_64 rng(3);
    std::vector<float> buf;
    std::set<int> seen, starts;
    for (int i = 0; i < 100; ++i) {
      set.SampleBatch(8, 32, &rng, &buf);
      for (int b = 0; b < 8; ++b) {
        starts.insert(static_cast<int>(buf[b * 32]));
        for (int t = 0; t < 32; ++t) seen.insert(static_cast<int>(buf[b * 32 + t]));
      }
    }
    return std::make_pair(seen, starts);
  };
  const auto [grid, drawn_starts] = frames_seen();
  EXPECT_EQ(*grid.rbegin(), 55);
  EXPECT_EQ(drawn_starts, (std::set<int>{0, 24}));
  set.random_starts = true;
  const auto [anywhere, any_starts] = frames_seen();
  EXPECT_EQ(anywhere.size(), 78u);  // Every frame, the last one included.
  EXPECT_EQ(*any_starts.rbegin(), 46);
  EXPECT_GT(any_starts.size(), 40u);
}

// --mirror: real clips and their mirrors, the mirrors' labels swapped, the
// normalization statistics the real clips' alone.
TEST(TrainingSetTest, MirroredClipsJoinWithSwappedLabelsAndTheRealClipsStatistics) {
  STYLUS_REQUIRE_BANDAI(data);
  const std::vector<std::string> paths = {
      data + "/dataset-2/dataset-2_raise-up-left-hand_normal_001.bvh",
      data + "/dataset-2/dataset-2_walk_elderly_002.bvh"};
  std::vector<std::string> log;
  auto keep = [&](const std::string& line) { log.push_back(line); };
  absl::StatusOr<TrainingSet> plain = LoadTrainingData(paths, {32, 16}, keep);
  absl::StatusOr<TrainingSet> both = LoadTrainingData(paths, {32, 16}, keep, /*mirror=*/true);
  ASSERT_TRUE(plain.ok() && both.ok()) << both.status();
  ASSERT_EQ(both->clips.size(), 4u);
  EXPECT_EQ(both->windows.size(), 2 * plain->windows.size());
  EXPECT_EQ(both->norm.Serialize(), plain->norm.Serialize());
  EXPECT_NE(log.back().find("loaded 4 clips (half of them mirrored)"), std::string::npos)
      << log.back();
  EXPECT_EQ(both->paths[2],
            data + "/dataset-2/mirrored/dataset-2_raise-up-right-hand_normal_001.bvh");
  EXPECT_EQ(both->paths[3], data + "/dataset-2/mirrored/dataset-2_walk_elderly_002.bvh");
  absl::StatusOr<ClipClasses> classes = ClipClasses::FromPaths(both->paths, {});
  ASSERT_TRUE(classes.ok()) << classes.status();
  EXPECT_EQ(classes->contents[classes->content_of[2]], "raise-up-right-hand");
  EXPECT_EQ(classes->style_of[2], classes->style_of[0]);

  // The mirrored raise lifts the right hand exactly as high as the real one
  // lifts the left: the heights (y) of the two hands trade places.
  const motion::Skeleton& sk = both->skeleton;
  const motion::FeatureLayout layout(sk.num_joints());
  const int left_y = layout.position(*sk.Find("Hand_L")) + 1;
  const int right_y = layout.position(*sk.Find("Hand_R")) + 1;
  const motion::FeatureClip& real = both->clips[0];
  const motion::FeatureClip& mirrored = both->clips[2];
  ASSERT_EQ(real.frames, mirrored.frames);
  double gap = 0, raised = 0;
  const auto& mean = both->norm.mean;
  const auto& sd = both->norm.std;
  for (int f = 0; f < real.frames; ++f) {
    const double l = real.row(f)[left_y] * sd[left_y] + mean[left_y];
    const double r = mirrored.row(f)[right_y] * sd[right_y] + mean[right_y];
    const double rest = real.row(f)[right_y] * sd[right_y] + mean[right_y];
    gap = std::max(gap, std::fabs(l - r));
    raised = std::max(raised, l - rest);
  }
  EXPECT_GT(raised, 30.0);  // The real clip does raise its left hand (units: cm).
  EXPECT_LT(gap, 1e-2);
}

}  // namespace
}  // namespace stylus::model
