// Real-data tests over the Bandai clips (../shared/data/bandai or $STYLUS_DATA).
#include <algorithm>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/dataset.h"
#include "motion/features.h"
#include "motion/kinematics.h"
#include "tests/test_support.h"

namespace stylus::motion {
namespace {

TEST(BandaiTest, EveryClipRoundTripsThroughTheWriter) {
  STYLUS_REQUIRE_BANDAI(dir);
  absl::StatusOr<DatasetIndex> index = IndexDataset({dir});
  ASSERT_TRUE(index.ok()) << index.status();
  ASSERT_GE(index->clips.size(), 870u);
  double worst = 0;
  std::string worst_clip;
  for (const ClipEntry& clip : index->clips) {
    absl::StatusOr<Motion> m = ReadBvhFile(clip.path);
    ASSERT_TRUE(m.ok()) << m.status();
    absl::StatusOr<Motion> back = ParseBvh(FormatBvh(*m), clip.path + " (rewritten)");
    ASSERT_TRUE(back.ok()) << back.status();
    ASSERT_EQ(back->num_frames, m->num_frames);
    const double err = MaxPositionDifference(*m, *back);
    if (err > worst) worst = err, worst_clip = clip.path;
  }
  std::printf("round trip over %zu clips: max FK error %g (%s)\n", index->clips.size(), worst,
              worst_clip.c_str());
  EXPECT_LT(worst, 1e-4);
}

TEST(BandaiTest, FeaturesRebuildRealClips) {
  STYLUS_REQUIRE_BANDAI(dir);
  absl::StatusOr<DatasetIndex> index = IndexDataset({dir});
  ASSERT_TRUE(index.ok());
  // Every 25th clip: walks, runs, turns, waves and dances of both datasets.
  for (size_t i = 0; i < index->clips.size(); i += 25) {
    SCOPED_TRACE(index->clips[i].path);
    absl::StatusOr<Motion> m = ReadBvhFile(index->clips[i].path);
    ASSERT_TRUE(m.ok());
    absl::StatusOr<HumanoidRoles> roles = FindHumanoidRoles(m->skeleton);
    ASSERT_TRUE(roles.ok()) << roles.status();
    absl::StatusOr<FeatureClip> f = ExtractFeatures(*m, *roles);
    ASSERT_TRUE(f.ok());
    absl::StatusOr<Motion> rebuilt =
        MotionFromFeatures(*f, m->skeleton, *roles, m->frame_time, RootAt(*m, *roles, 0));
    ASSERT_TRUE(rebuilt.ok()) << rebuilt.status();
    // Float features and an integrated root over several seconds: within 1 mm.
    EXPECT_LT(MaxPositionDifference(*m, *rebuilt), 0.1);
  }
}

}  // namespace
}  // namespace stylus::motion
