// A live package streams one frame per step with carried state: each output
// frame leaves once `lookahead` more input frames have arrived, its raw
// values equal the whole-clip transfer's, any chunking gives the same
// frames, steps batched across streams equal steps run alone, and a
// stream's state does not grow with its length.
#include "model/contrastive/live_streamer.h"

#include <algorithm>
#include <random>
#include <string>

#include "gtest/gtest.h"
#include "model/contrastive/contrastive_model.h"
#include "motion/kinematics.h"
#include "tests/model/contrastive/contrastive_support.h"
#include "tests/test_support.h"

namespace stylus::model {
namespace {

using contrastive_testing::Clip;
using contrastive_testing::Dir;
using contrastive_testing::LivePackage;
using contrastive_testing::TinyOptions;
using testing::Frames;

void Append(const motion::Motion& chunk, motion::Motion* all) {
  all->values.insert(all->values.end(), chunk.values.begin(), chunk.values.end());
  all->num_frames += chunk.num_frames;
}

// Streams `clip` in chunks of 1..max_chunk frames (1: frame by frame,
// checking the latency after each).
motion::Motion Stream(const std::shared_ptr<const ContrastiveModel>& model, const StyleCode& style,
                      const motion::Motion& clip, int max_chunk, motion::PostProcessMode post,
                      uint64_t seed = 1) {
  auto s = model->OpenStream({style, clip.skeleton, clip.frame_time, post});
  EXPECT_TRUE(s.ok()) << s.status();
  motion::Motion out = Frames(clip, 0, 0);
  std::mt19937_64 rng(seed);
  const int lookahead = model->config().lookahead;
  for (int f = 0; f < clip.num_frames;) {
    const int n = std::min<int>(clip.num_frames - f, 1 + rng() % max_chunk);
    absl::StatusOr<motion::Motion> got = (*s)->Push(Frames(clip, f, f + n));
    EXPECT_TRUE(got.ok()) << got.status();
    f += n;
    Append(*got, &out);
    // Output frame t is final exactly when input frame t + lookahead is in.
    EXPECT_EQ(out.num_frames, std::max(0, f - lookahead)) << "after " << f << " frames";
  }
  absl::StatusOr<motion::Motion> rest = (*s)->Finish();
  EXPECT_TRUE(rest.ok()) << rest.status();
  EXPECT_EQ(rest->num_frames, std::min(lookahead, clip.num_frames));
  Append(*rest, &out);
  return out;
}

double MaxDifference(const motion::Motion& a, const motion::Motion& b) {
  EXPECT_EQ(a.num_frames, b.num_frames);
  double d = 0;
  for (size_t i = 0; i < std::min(a.values.size(), b.values.size()); ++i)
    d = std::max(d, std::fabs(a.values[i] - b.values[i]));
  return d;
}

// (lookahead, frame_residual)
class LiveStreamerTest : public ::testing::TestWithParam<std::pair<int, bool>> {
 protected:
  std::shared_ptr<const ContrastiveModel> Model() const {
    return LivePackage(GetParam().first, GetParam().second);
  }
};

TEST_P(LiveStreamerTest, FrameByFrameEqualsTheWholeClipTransfer) {
  const auto model = Model();
  const motion::Motion content = Clip(0);
  const StyleCode style = *model->EncodeStyle(Clip(1));
  const motion::Motion streamed = Stream(model, style, content, 1, motion::PostProcessMode::kNone);
  absl::StatusOr<TransferResult> whole =
      model->Transfer(content, style, motion::PostProcessMode::kNone);
  ASSERT_TRUE(whole.ok()) << whole.status();
  EXPECT_LT(MaxDifference(streamed, whole->motion), 1e-2);
}

TEST_P(LiveStreamerTest, AnyChunkingGivesTheSameFrames) {
  const auto model = Model();
  const motion::Motion content = Clip(2);
  const StyleCode style = *model->EncodeStyle(Clip(3));
  for (auto post : {motion::PostProcessMode::kNone, motion::PostProcessMode::kFull}) {
    const motion::Motion one = Stream(model, style, content, 1, post);
    const motion::Motion chunked = Stream(model, style, content, 7, post, /*seed=*/3);
    EXPECT_LT(MaxDifference(one, chunked), 1e-6) << motion::PostProcessModeName(post);
  }
}

TEST_P(LiveStreamerTest, FullPostProcessingKeepsBoneLengths) {
  const auto model = Model();
  const motion::Motion content = Clip(0);
  const motion::Motion out = Stream(model, *model->EncodeStyle(Clip(2)), content, 1,
                                    motion::PostProcessMode::kFull);
  ASSERT_EQ(out.num_frames, content.num_frames);
  const motion::Skeleton& sk = out.skeleton;
  for (int f = 0; f < out.num_frames; f += 9) {
    const motion::GlobalPose g = motion::ForwardKinematics(sk, motion::PoseAt(out, f));
    for (int j = 0; j < sk.num_joints(); ++j) {
      const int p = sk.joint(j).parent;
      if (p < 0 || j == model->data().roles.pelvis) continue;
      EXPECT_NEAR(motion::Norm(g.positions[j] - g.positions[p]),
                  motion::Norm(sk.joint(j).offset), 1e-3)
          << "frame " << f << " joint " << sk.joint(j).name;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Lookahead, LiveStreamerTest,
                         ::testing::Values(std::pair{1, false}, std::pair{2, false},
                                           std::pair{2, true}));

TEST(LiveStreamerBatchTest, StepsBatchedAcrossStreamsEqualStepsRunAlone) {
  const auto model = LivePackage(2);
  const motion::Motion clips[3] = {Clip(0), Clip(1), Clip(3)};
  const StyleCode styles[3] = {*model->EncodeStyle(Clip(2)), *model->EncodeStyle(Clip(3)),
                               *model->EncodeStyle(Clip(0))};
  std::vector<std::unique_ptr<LiveStreamer>> streams;
  std::vector<motion::Motion> out;
  for (int i = 0; i < 3; ++i) {
    auto s = LiveStreamer::Create(model, {styles[i], clips[i].skeleton, clips[i].frame_time,
                                          motion::PostProcessMode::kFull});
    ASSERT_TRUE(s.ok()) << s.status();
    streams.push_back(*std::move(s));
    out.push_back(Frames(clips[i], 0, 0));
  }
  // Frame by frame, every stream's step in one batch; streams end at
  // different times.
  for (int f = 0; f <= clips[0].num_frames; ++f) {
    std::vector<LiveStep> batch;
    std::vector<LiveStreamer*> in_batch;
    for (int i = 0; i < 3; ++i) {
      const int n = clips[i].num_frames - i * 5;  // Stream i stops 5i frames early.
      if (f < n) {
        ASSERT_TRUE(streams[i]->Feed(Frames(clips[i], f, f + 1)).ok());
      } else if (f == n) {
        ASSERT_TRUE(streams[i]->Feed(Frames(clips[i], 0, 0), /*end=*/true).ok());
      }
    }
    for (bool more = true; more;) {
      batch.clear();
      in_batch.clear();
      for (auto& s : streams) {
        LiveStep step;
        if (s->NextStep(&step)) batch.push_back(step), in_batch.push_back(s.get());
      }
      more = !batch.empty();
      ASSERT_TRUE(model->StepLive(batch).ok());
      for (LiveStreamer* s : in_batch) s->StepDone();
    }
    for (int i = 0; i < 3; ++i) {
      absl::StatusOr<motion::Motion> got = streams[i]->Collect();
      ASSERT_TRUE(got.ok()) << got.status();
      Append(*got, &out[i]);
    }
  }
  for (int i = 0; i < 3; ++i) {
    const motion::Motion alone = Stream(model, styles[i], Frames(clips[i], 0, clips[i].num_frames - i * 5), 1,
                                        motion::PostProcessMode::kFull);
    EXPECT_LT(MaxDifference(out[i], alone), 1e-3) << "stream " << i;
  }
}

TEST(LiveStreamerBatchTest, AStreamsStateDoesNotGrowWithItsLength) {
  const auto model = LivePackage(2);
  const motion::Motion clip = Clip(0);
  auto s = LiveStreamer::Create(model, {*model->EncodeStyle(Clip(1)), clip.skeleton,
                                        clip.frame_time, motion::PostProcessMode::kFull});
  ASSERT_TRUE(s.ok()) << s.status();
  EXPECT_GT((*s)->carry_bytes(), 0u);
  size_t after_first_loop = 0;
  for (int loop = 0; loop < 20; ++loop) {  // 20 x 64 frames, the clip looped.
    for (int f = 0; f < clip.num_frames; ++f) ASSERT_TRUE((*s)->Push(Frames(clip, f, f + 1)).ok());
    if (loop == 0) after_first_loop = (*s)->state_bytes();
    EXPECT_EQ((*s)->state_bytes(), after_first_loop) << "after loop " << loop;
  }
  EXPECT_EQ((*s)->emitted(), 20 * clip.num_frames - 2);
}

TEST(LiveStreamerBatchTest, AnOfflinePackageHasNoLiveSteps) {
  const std::string dir = Dir("offline_for_live");
  ASSERT_TRUE(TrainContrastive(TinyOptions(dir, 4)).ok());
  auto model = ContrastiveModel::Load(dir);
  ASSERT_TRUE(model.ok());
  EXPECT_EQ((*model)->LiveStyleParams((*model)->EncodeStyle(Clip(0)).value()).status().code(),
            absl::StatusCode::kFailedPrecondition);
  EXPECT_EQ((*model)->StepLive({}).code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_TRUE((*model)->NewLiveCarry().buffers.empty());
}

}  // namespace
}  // namespace stylus::model
