// The body-part swap test of the shipped judges, on the real held-out clips.
#include "tool/part_swap.h"

#include <string>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/dataset.h"
#include "tests/test_support.h"

namespace stylus::model {
namespace {

const std::string kJudges = std::string(STYLUS_SOURCE_DIR) + "/models/judges/v1";

TEST(JudgeSwapTest, CountsEveryHeldOutClipAndEveryPart) {
  STYLUS_REQUIRE_BANDAI(dir);
  auto judges = Judges::Load(kJudges);
  ASSERT_TRUE(judges.ok()) << judges.status();
  int progress_calls = 0;
  absl::StatusOr<SwapTestReport> report =
      RunSwapTest(**judges, {dir}, [&](int, int) { ++progress_calls; });
  ASSERT_TRUE(report.ok()) << report.status();
  std::printf("%s", report->Markdown().c_str());

  // The unchanged row is the judge's verdict on each held-out clip as it is.
  const motion::DatasetIndex index = *motion::IndexDataset({dir});
  int held_out = 0, right = 0;
  for (const motion::ClipEntry* c : index.Split(true)) {
    ++held_out;
    right += (*judges)->contents()[*(*judges)->ClassifyContent(*motion::ReadBvhFile(c->path))] ==
             c->label.content;
  }
  EXPECT_EQ(report->unchanged.clips, held_out);
  EXPECT_EQ(report->unchanged.kept, right);
  EXPECT_EQ(progress_calls, held_out);

  // Four parts, each with a donor for most clips (a dataset-1 action may
  // have no long-enough take in another style); the per-action rows pool the
  // same-action swaps of every part.
  ASSERT_EQ(report->parts.size(), 4u);
  int pooled = 0, pooled_kept = 0;
  bool some_swap_changed_a_verdict = false;
  for (const SwapTestRow& r : report->parts) {
    EXPECT_GT(r.same_action.clips, held_out * 3 / 4) << r.part;
    EXPECT_GT(r.other_action.clips, held_out * 3 / 4) << r.part;
    pooled += r.same_action.clips;
    pooled_kept += r.same_action.kept;
    some_swap_changed_a_verdict |= r.same_action.accuracy() != report->unchanged.accuracy();
  }
  int by_action = 0, by_action_kept = 0;
  for (const auto& [action, count] : report->by_action) {
    by_action += count.clips;
    by_action_kept += count.kept;
  }
  EXPECT_EQ(by_action, pooled);
  EXPECT_EQ(by_action_kept, pooled_kept);
  EXPECT_TRUE(some_swap_changed_a_verdict);  // The splices reach the judge.
  EXPECT_NE(report->Markdown().find("| right-arm | "), std::string::npos);
}

}  // namespace
}  // namespace stylus::model
