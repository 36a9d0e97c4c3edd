#include "bridge/cues.h"

#include "gtest/gtest.h"

namespace stylus::bridge {
namespace {

TEST(CuesTest, StylesAndStrengthsInTime) {
  auto cues = ParseCues("# the show\n0 style old walk\n2.5 strength 0.5\n\n4 style /clips/proud.bvh\n",
                        "show.cues");
  ASSERT_TRUE(cues.ok()) << cues.status();
  ASSERT_EQ(cues->size(), 3u);
  EXPECT_EQ((*cues)[0].style, "old walk");
  EXPECT_TRUE((*cues)[1].strength);
  EXPECT_DOUBLE_EQ((*cues)[1].value, 0.5);
  EXPECT_DOUBLE_EQ((*cues)[1].seconds, 2.5);
  EXPECT_EQ((*cues)[2].style, "/clips/proud.bvh");
}

TEST(CuesTest, ErrorsNameTheFileAndLine) {
  EXPECT_EQ(ParseCues("1 strength 2\n", "s").status().message(),
            "s:1: strength wants a number from 0 to 1, not '2'");
  EXPECT_EQ(ParseCues("2 style a\n1 style b\n", "s").status().message(),
            "s:2: cue at 1 s comes before the one above it");
  EXPECT_EQ(ParseCues("1 tempo 3\n", "s").status().message(),
            "s:1: 'tempo': a cue changes the style or the strength");
  EXPECT_EQ(ParseCues("soon style a\n", "s").status().message(),
            "s:1: expected 'SECONDS style NAME-OR-CLIP' or 'SECONDS strength K'");
}

}  // namespace
}  // namespace stylus::bridge
