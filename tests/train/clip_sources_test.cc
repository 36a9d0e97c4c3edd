// Training data from folders on any humanoid rig: clips on other rigs are
// retargeted onto the package's skeleton and resampled to its rate, labels
// come from names or a CSV, and what cannot be used is skipped and reported.
#include "train/clip_sources.h"

#include <filesystem>
#include <fstream>

#include "absl/strings/match.h"
#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/kinematics.h"
#include "tests/support/test_rigs.h"
#include "tests/test_support.h"
#include "train/clip_classes.h"
#include "train/training_set.h"

namespace stylus::model {
namespace {

namespace fs = std::filesystem;
using testing::TestRig;

TEST(ClipSourcesTest, MixedRigsAreRetargetedLabelledAndReported) {
  STYLUS_REQUIRE_BANDAI(data);
  const std::string dir = ::testing::TempDir() + "/own_data";
  fs::remove_all(dir);
  fs::create_directories(dir + "/studio");
  const std::string d2 = data + "/dataset-2/dataset-2_";
  const motion::Motion walk = *motion::ReadBvhFile(d2 + "walk_normal_001.bvh");
  const motion::Motion old = *motion::ReadBvhFile(d2 + "walk_elderly_001.bvh");
  // The package's rig (a Bandai-named clip), a Mixamo and a CMU take (120 Hz),
  // a file that is no BVH and a rig that is no humanoid.
  ASSERT_TRUE(motion::WriteBvhFile(walk, dir + "/dataset-2_walk_normal_001.bvh").ok());
  ASSERT_TRUE(motion::WriteBvhFile(*testing::BuildTestRig(old, TestRig::kMixamo),
                                   dir + "/studio/take_a.bvh")
                  .ok());
  ASSERT_TRUE(
      motion::WriteBvhFile(*testing::BuildTestRig(walk, TestRig::kCmu), dir + "/studio/take_b.bvh")
          .ok());
  std::ofstream(dir + "/studio/broken.bvh") << "HIERARCHY\nROOT x\n";
  fs::copy_file(testing::SourceDir() + "/tests/fixtures/bvh/good/three_joint.bvh",
                dir + "/studio/three_joint.bvh");
  std::ofstream(dir + "/labels.csv") << "clip,content,style\nstudio/take_a.bvh,walk,elderly\n"
                                        "studio/take_b.bvh,walk,normal\n";
  TrainingDataOptions options;
  options.labels_csv = dir + "/labels.csv";
  absl::StatusOr<ClipSources> read = ReadClipSources({dir}, false, options);
  ASSERT_TRUE(read.ok()) << read.status();
  std::cout << read->Report() << "\n";
  ASSERT_EQ(read->motions.size(), 3u);
  EXPECT_EQ(read->retargeted, 2);
  EXPECT_EQ(read->other_rigs, 2);
  EXPECT_EQ(read->resampled, 1);
  ASSERT_EQ(read->skipped.size(), 2u);
  EXPECT_TRUE(absl::StrContains(read->Report(), "broken.bvh")) << read->Report();
  EXPECT_TRUE(absl::StrContains(read->Report(), "three_joint.bvh: not a humanoid rig"))
      << read->Report();
  for (const motion::Motion& m : read->motions) {
    EXPECT_TRUE(m.skeleton.SameTopology(walk.skeleton));
    EXPECT_NEAR(m.frame_time, walk.frame_time, 1e-9);
  }
  // Every clip labelled: one by its name, two by the CSV; so guided
  // training can draw them.
  absl::StatusOr<ClipClasses> classes = ClipClasses::FromLabels(read->paths, read->labels, {});
  ASSERT_TRUE(classes.ok()) << classes.status();
  EXPECT_EQ(classes->styles, (std::vector<std::string>{"elderly", "normal"}));
  // The retargeted Mixamo take moves as the elderly clip it was made from.
  const auto want = motion::GlobalPositions(old);
  for (size_t i = 0; i < read->paths.size(); ++i) {
    if (!absl::EndsWith(read->paths[i], "take_a.bvh")) continue;
    const auto got = motion::GlobalPositions(read->motions[i]);
    const int foot = *walk.skeleton.Find("Foot_L");
    double worst = 0;
    for (size_t f = 0; f < got.size(); ++f)
      worst = std::max(worst, motion::Norm(got[f][foot] - want[f][foot]));
    EXPECT_LT(worst, 0.01);  // Centimetres: the BVH text's precision.
  }
  // Without labels, the unnamed takes are simply unlabelled.
  absl::StatusOr<ClipSources> bare = ReadClipSources({dir}, false, {});
  ASSERT_TRUE(bare.ok());
  EXPECT_FALSE(ClipClasses::FromLabels(bare->paths, bare->labels, {}).ok());
  // A training set (features, windows) from it.
  absl::StatusOr<TrainingSet> set =
      LoadTrainingSet({dir}, {32, 16}, {}, false, nullptr, nullptr, {}, options);
  ASSERT_TRUE(set.ok()) << set.status();
  EXPECT_EQ(set->clips.size(), 3u);
  EXPECT_GT(set->windows.size(), 10u);
}

TEST(ClipSourcesTest, NothingUsableIsAClearError) {
  const std::string dir = ::testing::TempDir() + "/nothing_usable";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir + "/broken.bvh") << "not a bvh";
  absl::StatusOr<ClipSources> read = ReadClipSources({dir}, false, {});
  ASSERT_FALSE(read.ok());
  EXPECT_TRUE(absl::StrContains(read.status().message(), "broken.bvh")) << read.status();
  std::ofstream(dir + "/labels.csv") << "clip,content\n";
  TrainingDataOptions bad;
  bad.labels_csv = dir + "/labels.csv";
  std::ofstream(dir + "/labels.csv") << "a.bvh,walk\n";
  read = ReadClipSources({dir}, false, bad);
  ASSERT_FALSE(read.ok());
  EXPECT_TRUE(
      absl::StrContains(read.status().message(), "labels.csv:1: expected clip,content,style"))
      << read.status();
}

}  // namespace
}  // namespace stylus::model
