#include "client/schedule_file.h"

#include "gtest/gtest.h"

namespace stylus {
namespace {

TEST(ScheduleFileTest, KeyframesHoldAndRunLinearly) {
  auto rows = ParseSchedule("# walk into the run\n10 1 0\n20, 0, 1  # halfway at 15\n", "s.txt", 2, 25);
  ASSERT_TRUE(rows.ok()) << rows.status();
  ASSERT_EQ(rows->size(), 25u);
  EXPECT_EQ((*rows)[0], (std::vector<double>{1, 0}));
  EXPECT_EQ((*rows)[10], (std::vector<double>{1, 0}));
  EXPECT_DOUBLE_EQ((*rows)[15][0], 0.5);
  EXPECT_DOUBLE_EQ((*rows)[15][1], 0.5);
  EXPECT_EQ((*rows)[20], (std::vector<double>{0, 1}));
  EXPECT_EQ((*rows)[24], (std::vector<double>{0, 1}));
}

TEST(ScheduleFileTest, ErrorsNameTheFileAndLine) {
  EXPECT_EQ(ParseSchedule("0 1 0\n5 1\n", "s.txt", 2, 10).status().message(),
            "s.txt:2: 1 weights for 2 styles (one per --style, in their order)");
  EXPECT_EQ(ParseSchedule("5 1 0\n5 0 1\n", "s.txt", 2, 10).status().message(),
            "s.txt:2: frame 5 after frame 5: keyframes go in increasing order");
  EXPECT_EQ(ParseSchedule("x 1 0\n", "s.txt", 2, 10).status().message(),
            "s.txt:1: expected a frame number >= 0 first, not 'x'");
  EXPECT_EQ(ParseSchedule("0 1 nan\n", "s.txt", 2, 10).status().message(),
            "s.txt:1: 'nan' is not a number");
  EXPECT_EQ(ParseSchedule("# nothing\n", "s.txt", 2, 10).status().message(),
            "s.txt: no keyframes (lines like '0 1 0' then '60 0 1')");
}

}  // namespace
}  // namespace stylus
