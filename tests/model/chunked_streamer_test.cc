// model/chunked_streamer: streaming any family through its whole-clip
// transfer, on a tiny cyclic package.
#include "model/chunked_streamer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "model/content_guard.h"
#include "model/cyclic/cyclic_model.h"
#include "model/family_registry.h"
#include "model/package.h"
#include "motion/bvh.h"
#include "motion/features.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"
#include "tests/model/cyclic/cyclic_support.h"
#include "tests/model/transfer_support.h"
#include "tests/test_support.h"
#include "train/cyclic_trainer.h"

namespace stylus::model {
namespace {

using ::stylus::testing::MotionOf;
using namespace cyclic_testing;  // NOLINT: the family's test fixtures.

namespace fs = std::filesystem;

TEST(ChunkedStreamerTest, StreamsEveryFrameInOrderWithAContinuousRoot) {
  CyclicTrainOptions o = TinyOptions(Dir("stream"));
  o.config.iterations = 80;
  ASSERT_TRUE(TrainCyclic(o).ok());
  auto loaded = LoadStyleModel(o.out);
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  std::shared_ptr<const StyleModel> m = std::move(*loaded);
  const motion::Motion content = Clip(3), style = Clip(1);  // A turning walk.
  const StyleCode code = *m->EncodeStyle(style);
  auto bad = ChunkedStreamer::Create(
      m, {StyleCode{{1, 2}}, content.skeleton, content.frame_time, motion::PostProcessMode::kFull});
  EXPECT_EQ(bad.status().code(), absl::StatusCode::kInvalidArgument);
  auto st = ChunkedStreamer::Create(
      m, {code, content.skeleton, content.frame_time, motion::PostProcessMode::kFull},
      /*chunk=*/16, /*context=*/24);
  ASSERT_TRUE(st.ok()) << st.status();
  EXPECT_EQ((*st)->Finish().status().code(), absl::StatusCode::kFailedPrecondition);
  motion::Motion out = motion::RestMotion(content.skeleton, 0, content.frame_time);
  for (int f = 0; f < content.num_frames; f += 5) {  // Arrives 5 frames at a time.
    absl::StatusOr<motion::Motion> part =
        (*st)->Push(testing::Frames(content, f, std::min(f + 5, content.num_frames)));
    ASSERT_TRUE(part.ok()) << part.status();
    EXPECT_EQ((*st)->emitted() % 16, 0);
    out.values.insert(out.values.end(), part->values.begin(), part->values.end());
    out.num_frames += part->num_frames;
  }
  EXPECT_EQ(out.num_frames, 64);  // 4 full chunks; nothing left for Finish.
  absl::StatusOr<motion::Motion> rest = (*st)->Finish();
  ASSERT_TRUE(rest.ok());
  EXPECT_EQ(rest->num_frames, 0);
  EXPECT_EQ((*st)->received(), 64);
  // The root path has no jump at the chunk seams: no step is more than twice
  // the largest step of the whole-clip transfer.
  const motion::Motion whole = m->Transfer(content, code)->motion;
  const size_t c = content.skeleton.num_channels();
  auto largest_step = [&](const motion::Motion& x) {
    double worst = 0;
    for (int f = 1; f < x.num_frames; ++f)
      worst = std::max(worst, std::hypot(x.values[f * c] - x.values[(f - 1) * c],
                                         x.values[f * c + 2] - x.values[(f - 1) * c + 2]));
    return worst;
  };
  EXPECT_LT(largest_step(out), 2 * largest_step(whole) + 1e-3);
  EXPECT_LT(motion::MaxPositionDifference(out, whole),
            0.25 * motion::FindHumanoidRoles(content.skeleton)->leg_length);
}

}  // namespace
}  // namespace stylus::model
