// The motion-only style judge: its channels carry no pose, it learns from
// labelled clips, and the shipped one reads real held-out clips but cannot
// tell frozen ones apart.
#include "eval/motion_judge.h"

#include <cmath>
#include <string>
#include <vector>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/dataset.h"
#include "motion/features.h"
#include "motion/rig_roles.h"
#include "motion/synth.h"
#include "tests/eval/tiny_dataset.h"
#include "tests/test_support.h"

namespace stylus::model {
namespace {

const std::string kJudges = std::string(STYLUS_SOURCE_DIR) + "/models/judges/v1";

motion::FeatureClip ChannelsOf(const motion::Motion& m) {
  const motion::HumanoidRoles roles = *motion::HumanoidRolesOf(m);
  const motion::FeatureClip f = *motion::ExtractFeatures(m, roles);
  return MotionChannels(f, m.skeleton, roles, m.frame_time);
}

TEST(MotionChannelsTest, AStillClipIsAllZerosAndAGlidingOneIsOnlyItsRootSpeed) {
  const motion::Motion walk = *motion::Synthesize(*motion::ParseSynthStyle("normal,frames=40"));
  const int joints = walk.skeleton.num_joints();
  const motion::FeatureClip moving = ChannelsOf(walk);
  ASSERT_EQ(moving.frames, walk.num_frames);
  ASSERT_EQ(moving.dim, 3 * joints + 4);
  double moving_energy = 0;
  for (float v : moving.values) moving_energy += std::abs(v);
  EXPECT_GT(moving_energy, 1.0);

  const motion::Motion still = Frozen(walk);
  for (int t = 1; t < still.num_frames; ++t) {
    for (int c = 0; c < still.skeleton.num_channels(); ++c) {
      ASSERT_EQ(still.frame(t)[c], walk.frame(walk.num_frames / 2)[c]);
    }
  }
  for (float v : ChannelsOf(still).values) ASSERT_NEAR(v, 0.0f, 1e-3f);

  // The still pose carried along at a constant 150 units/s: the joints do
  // not move relative to the root, the root moves at that speed.
  motion::Motion glide = still;
  const auto& root_channels = glide.skeleton.joint(0).channels;
  const int start = glide.skeleton.channel_start(0);
  for (size_t k = 0; k < root_channels.size(); ++k) {
    if (root_channels[k] != motion::Channel::kXposition) continue;
    for (int t = 0; t < glide.num_frames; ++t)
      glide.frame(t)[start + k] += 150.0 * t * glide.frame_time;
  }
  const motion::FeatureClip glided = ChannelsOf(glide);
  for (int t = 0; t < glided.frames; ++t) {
    const float* row = glided.row(t);
    for (int c = 0; c < 3 * joints; ++c) ASSERT_NEAR(row[c], 0.0f, 1e-2f) << "frame " << t;
    EXPECT_NEAR(std::hypot(row[3 * joints], row[3 * joints + 1]), 150.0, 1.0) << "frame " << t;
  }
}

TEST(MotionJudgeTest, TrainsOnLabelledClipsAndCannotTellFrozenClipsApart) {
  const std::string data = testing::TinyLabelledDataset("motion_judge_tiny");
  JudgeTrainOptions o;
  o.data = {data};
  o.out = ::testing::TempDir() + "/motion_judge";
  o.iterations = 120;
  o.batch = 8;
  o.log = [](const std::string&) {};
  absl::StatusOr<MotionJudgeAccuracy> acc = TrainMotionJudge(o);
  ASSERT_TRUE(acc.ok()) << acc.status();
  EXPECT_DOUBLE_EQ(acc->chance, 0.5);  // Held-out clips of both styles alike.
  EXPECT_GT(acc->clips, 0);
  absl::StatusOr<std::unique_ptr<MotionJudge>> judge = MotionJudge::Load(o.out);
  ASSERT_TRUE(judge.ok()) << judge.status();
  EXPECT_EQ((*judge)->styles(), (std::vector<std::string>{"old", "proud"}));
  EXPECT_NEAR((*judge)->trained_accuracy().held_out, acc->held_out, 1e-4);
  EXPECT_NEAR((*judge)->trained_accuracy().frozen, acc->frozen, 1e-4);
  EXPECT_NEAR((*judge)->trained_accuracy().chance, acc->chance, 1e-4);

  // Two different frozen clips are the same input to it: the same verdict,
  // to the last digit.
  const motion::Motion a = *motion::ReadBvhFile(data + "/dataset-9_walk_old_001.bvh");
  const motion::Motion b = *motion::ReadBvhFile(data + "/dataset-9_run_proud_002.bvh");
  const std::vector<double> pa = *(*judge)->StyleProbabilities(Frozen(a));
  const std::vector<double> pb = *(*judge)->StyleProbabilities(Frozen(b));
  ASSERT_EQ(pa.size(), 2u);
  EXPECT_NEAR(pa[0], pb[0], 1e-6);
  EXPECT_NE(*(*judge)->StyleProbabilities(a), pa);

  // A directory without it: NOT_FOUND, which eval reports and goes on.
  EXPECT_EQ(MotionJudge::Load(data).status().code(), absl::StatusCode::kNotFound);
  // A clip of another rig is refused.
  motion::Motion other = a;
  other.frame_time = 1.0 / 60;
  EXPECT_EQ((*judge)->ClassifyStyle(other).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(MotionJudgeTest, TheShippedJudgeReadsRealClipsButNotFrozenOnes) {
  STYLUS_REQUIRE_BANDAI(dir);
  absl::StatusOr<std::unique_ptr<MotionJudge>> judge = MotionJudge::Load(kJudges);
  ASSERT_TRUE(judge.ok()) << judge.status();
  // It read the held-out split well when trained, and frozen clips near chance.
  EXPECT_GT((*judge)->trained_accuracy().held_out, 0.8);
  EXPECT_LE((*judge)->trained_accuracy().frozen, (*judge)->trained_accuracy().chance + 1e-4);
  absl::StatusOr<motion::DatasetIndex> index =
      motion::IndexDataset({dir + "/dataset-1", dir + "/dataset-2"});
  ASSERT_TRUE(index.ok()) << index.status();
  const std::vector<const motion::ClipEntry*> held_out = index->Split(true);
  ASSERT_GE(held_out.size(), 40u);
  int right = 0, clips = 0;
  std::vector<double> first_frozen;
  for (size_t i = 0; i < held_out.size(); i += 2) {
    const motion::Motion clip = *motion::ReadBvhFile(held_out[i]->path);
    const std::vector<std::string>& styles = (*judge)->styles();
    absl::StatusOr<int> verdict = (*judge)->ClassifyStyle(clip);
    ASSERT_TRUE(verdict.ok()) << verdict.status();
    right += styles[*verdict] == held_out[i]->label.style;
    ++clips;
    const std::vector<double> frozen = *(*judge)->StyleProbabilities(Frozen(clip));
    if (first_frozen.empty()) first_frozen = frozen;
    for (size_t k = 0; k < frozen.size(); ++k) ASSERT_NEAR(frozen[k], first_frozen[k], 1e-6);
  }
  EXPECT_GT(static_cast<double>(right) / clips, 0.7) << right << " of " << clips;
}

}  // namespace
}  // namespace stylus::model
