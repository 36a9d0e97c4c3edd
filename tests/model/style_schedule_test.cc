#include "model/style_schedule.h"

#include "gtest/gtest.h"

namespace stylus::model {
namespace {

StyleCode Code(float v) { return StyleCode{{v, 2 * v}}; }

TEST(StyleScheduleTest, ChangesCrossFadeLinearlyFromTheNamedFrame) {
  StyleSchedule s(Code(0), 1);
  ASSERT_TRUE(s.Add({10, Code(1), std::nullopt, 4}, 0).ok());
  for (int t = 0; t < 10; ++t) {
    const StyleSchedule::At at = s.Advance(t);
    EXPECT_FLOAT_EQ(at.code.values[0], 0) << t;
    EXPECT_FALSE(at.changed) << t;
  }
  const float expected[] = {0.25f, 0.5f, 0.75f, 1, 1};
  for (int t = 10; t < 15; ++t) {
    const StyleSchedule::At at = s.Advance(t);
    EXPECT_FLOAT_EQ(at.code.values[0], expected[t - 10]) << t;
    EXPECT_FLOAT_EQ(at.code.values[1], 2 * expected[t - 10]) << t;
    EXPECT_EQ(at.changed, t < 14) << t;
    EXPECT_DOUBLE_EQ(at.strength, 1);
  }
}

TEST(StyleScheduleTest, AChangeMidFadeStartsFromWhereTheStyleIs) {
  StyleSchedule s(Code(0), 1);
  ASSERT_TRUE(s.Add({0, Code(1), 0.5, 4}, 0).ok());
  ASSERT_TRUE(s.Add({2, std::nullopt, 1.0, 2}, 0).ok());
  EXPECT_FLOAT_EQ(s.Advance(0).code.values[0], 0.25f);
  const StyleSchedule::At at1 = s.Advance(1);
  EXPECT_FLOAT_EQ(at1.code.values[0], 0.5f);
  EXPECT_DOUBLE_EQ(at1.strength, 0.75);
  // The second change keeps the code's target and fades the strength back
  // from 0.75, over 2 frames; the code finishes its move in those frames.
  const StyleSchedule::At at2 = s.Advance(2);
  EXPECT_FLOAT_EQ(at2.code.values[0], 0.75f);
  EXPECT_DOUBLE_EQ(at2.strength, 0.875);
  const StyleSchedule::At at3 = s.Advance(3);
  EXPECT_FLOAT_EQ(at3.code.values[0], 1);
  EXPECT_DOUBLE_EQ(at3.strength, 1);
}

TEST(StyleScheduleTest, LateChangesApplyFromTheNextFrameAndBadOnesAreRefused) {
  StyleSchedule s(Code(0), 1);
  ASSERT_TRUE(s.Add({3, Code(1), std::nullopt, 0}, /*earliest=*/7).ok());
  EXPECT_FLOAT_EQ(s.Advance(6).code.values[0], 0);
  EXPECT_FLOAT_EQ(s.Advance(7).code.values[0], 1);
  EXPECT_EQ(s.Add({9, std::nullopt, std::nullopt, 0}, 0).code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(s.Add({9, StyleCode{{1}}, std::nullopt, 0}, 0).code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(s.Add({9, std::nullopt, 1.5, 0}, 0).code(), absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(s.Add({9, std::nullopt, 0.5, -1}, 0).code(), absl::StatusCode::kInvalidArgument);
  ASSERT_TRUE(s.Add({20, std::nullopt, 0.5, 0}, 0).ok());
  const absl::Status out_of_order = s.Add({15, std::nullopt, 0.5, 0}, 0);
  EXPECT_EQ(out_of_order.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(out_of_order.message().find("frame order"), std::string::npos) << out_of_order;
}

// Changes waiting for later frames are capped: a client cannot queue
// without bound.
TEST(StyleScheduleTest, QueuedChangesAreCapped) {
  StyleSchedule s(Code(0), 1);
  for (int i = 0; i < StyleSchedule::kMaxQueuedChanges; ++i) {
    ASSERT_TRUE(s.Add({100 + i, std::nullopt, 0.5, 0}, 0).ok()) << i;
  }
  const absl::Status over = s.Add({1000, std::nullopt, 0.5, 0}, 0);
  EXPECT_EQ(over.code(), absl::StatusCode::kResourceExhausted);
  // Once due, they leave the queue, and there is room again.
  (void)s.Advance(100 + StyleSchedule::kMaxQueuedChanges);
  EXPECT_TRUE(s.Add({1000, std::nullopt, 0.5, 0}, 0).ok());
}

}  // namespace
}  // namespace stylus::model
