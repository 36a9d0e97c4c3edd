#include "motion/windowing.h"

#include "gtest/gtest.h"

namespace stylus::motion {
namespace {

TEST(WindowingTest, DefaultIsThirtyTwoFramesWithQuarterOverlap) {
  const WindowSpec spec;
  EXPECT_EQ(spec.length, 32);
  EXPECT_EQ(spec.hop, 24);
  EXPECT_EQ(WindowSpec::WithLength(60).hop, 45);
}

TEST(WindowingTest, Counts) {
  const WindowSpec spec;
  EXPECT_TRUE(WindowStarts(31, spec)->empty());
  EXPECT_EQ(WindowStarts(32, spec)->size(), 1u);
  EXPECT_EQ(WindowStarts(55, spec)->size(), 1u);
  EXPECT_EQ(WindowStarts(56, spec)->size(), 2u);
  EXPECT_EQ(*WindowStarts(100, spec), (std::vector<int>{0, 24, 48}));
  // (n - T) / hop + 1 in general.
  for (int n = 32; n < 500; n += 7) {
    EXPECT_EQ(static_cast<int>(WindowStarts(n, spec)->size()), (n - 32) / 24 + 1) << n;
  }
}

TEST(WindowingTest, CoverTailAddsAWindowEndingAtTheLastFrame) {
  const WindowSpec spec;
  EXPECT_EQ(*WindowStarts(100, spec, true), (std::vector<int>{0, 24, 48, 68}));
  EXPECT_EQ(*WindowStarts(80, spec, true), (std::vector<int>{0, 24, 48}));  // Already ends at 80.
}

TEST(WindowingTest, RejectsBadSpecs) {
  EXPECT_FALSE(WindowStarts(100, {0, 1}).ok());
  EXPECT_FALSE(WindowStarts(100, {32, 0}).ok());
}

TEST(WindowingTest, SliceCopiesRows) {
  FeatureClip clip;
  clip.frames = 5;
  clip.dim = 2;
  clip.values = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
  const FeatureClip s = Slice(clip, 1, 3);
  EXPECT_EQ(s.frames, 3);
  EXPECT_EQ(s.values, (std::vector<float>{2, 3, 4, 5, 6, 7}));
}

}  // namespace
}  // namespace stylus::motion
