// A live package streams one frame per step with carried state: each output
// frame leaves once `lookahead` more input frames have arrived, its raw
// values equal the whole-clip transfer's, any chunking gives the same
// frames, steps batched across streams equal steps run alone, and a
// stream's state does not grow with its length.
#include "model/contrastive/live_streamer.h"

#include <algorithm>
#include <random>
#include <string>
#include <tuple>

#include "gtest/gtest.h"
#include "model/contrastive/contrastive_model.h"
#include "model/family_registry.h"
#include "model/style_schedule.h"
#include "motion/bvh.h"
#include "motion/kinematics.h"
#include "tests/model/contrastive/contrastive_support.h"
#include "tests/test_support.h"

namespace stylus::model {
namespace {

using contrastive_testing::Clip;
using contrastive_testing::Dir;
using contrastive_testing::LivePackage;
using contrastive_testing::TinyOptions;
using testing::Append;
using testing::Frames;

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

// (lookahead, frame_residual, dilation_growth)
class LiveStreamerTest : public ::testing::TestWithParam<std::tuple<int, bool, int>> {
 protected:
  std::shared_ptr<const ContrastiveModel> Model() const {
    return LivePackage(std::get<0>(GetParam()), std::get<1>(GetParam()), std::get<2>(GetParam()));
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
  const motion::Motion out =
      Stream(model, *model->EncodeStyle(Clip(2)), content, 1, motion::PostProcessMode::kFull);
  ASSERT_EQ(out.num_frames, content.num_frames);
  const motion::Skeleton& sk = out.skeleton;
  for (int f = 0; f < out.num_frames; f += 9) {
    const motion::GlobalPose g = motion::ForwardKinematics(sk, motion::PoseAt(out, f));
    for (int j = 0; j < sk.num_joints(); ++j) {
      const int p = sk.joint(j).parent;
      if (p < 0 || j == model->data().roles.pelvis) continue;
      EXPECT_NEAR(motion::Norm(g.positions[j] - g.positions[p]), motion::Norm(sk.joint(j).offset),
                  1e-3)
          << "frame " << f << " joint " << sk.joint(j).name;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Lookahead, LiveStreamerTest,
                         ::testing::Values(std::tuple{1, false, 1}, std::tuple{2, false, 1},
                                           std::tuple{2, true, 1}, std::tuple{2, true, 2},
                                           std::tuple{8, true, 1}));

TEST(LiveStreamerBatchTest, StepsBatchedAcrossStreamsEqualStepsRunAlone) {
  const auto model = LivePackage(2);
  const motion::Motion clips[3] = {Clip(0), Clip(1), Clip(3)};
  const StyleCode styles[3] = {*model->EncodeStyle(Clip(2)), *model->EncodeStyle(Clip(3)),
                               *model->EncodeStyle(Clip(0))};
  std::vector<std::unique_ptr<LiveStreamer>> streams;
  std::vector<motion::Motion> out;
  for (int i = 0; i < 3; ++i) {
    auto s = LiveStreamer::Create(
        model, {styles[i], clips[i].skeleton, clips[i].frame_time, motion::PostProcessMode::kFull});
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
    const motion::Motion alone =
        Stream(model, styles[i], Frames(clips[i], 0, clips[i].num_frames - i * 5), 1,
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
  std::printf("stream state: %zu bytes (networks' carried state %zu)\n", (*s)->state_bytes(),
              (*s)->carry_bytes());
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

namespace stylus::model {
namespace {

// The shipped live package on real sample clips.
class LiveControlTest : public ::testing::Test {
 protected:
  void SetUp() override {
    absl::StatusOr<std::unique_ptr<ContrastiveModel>> m =
        ContrastiveModel::Load(std::string(STYLUS_SOURCE_DIR) + "/models/live/v3");
    ASSERT_TRUE(m.ok()) << m.status();
    model_ = std::move(*m);
    content_ = Sample("walk_normal.bvh");
    old_ = *model_->EncodeStyle(Sample("walk_old.bvh"));
    run_ = *model_->EncodeStyle(Sample("run.bvh"));
  }
  static motion::Motion Sample(const std::string& name) {
    return *motion::ReadBvhFile(std::string(STYLUS_SOURCE_DIR) + "/samples/" + name);
  }
  // Streams the content frame by frame with `changes` sent before their frames.
  motion::Motion Run(const StyleCode& style, const std::vector<StyleChange>& changes) {
    auto s = model_->OpenStream(
        {style, content_.skeleton, content_.frame_time, motion::PostProcessMode::kFull});
    EXPECT_TRUE(s.ok()) << s.status();
    motion::Motion out = Frames(content_, 0, 0);
    size_t next = 0;
    for (int f = 0; f < content_.num_frames; ++f) {
      while (next < changes.size() && changes[next].from_frame == f)
        EXPECT_TRUE((*s)->ChangeStyle(changes[next++]).ok());
      Append(*(*s)->Push(Frames(content_, f, f + 1)), &out);
    }
    Append(*(*s)->Finish(), &out);
    return out;
  }
  // The largest move of any joint between consecutive frames in [begin, end).
  static double MaxStep(const motion::Motion& m, int begin, int end) {
    double worst = 0;
    for (int f = std::max(1, begin); f < end; ++f)
      worst =
          std::max(worst, motion::MaxPositionDifference(Frames(m, f - 1, f), Frames(m, f, f + 1)));
    return worst;
  }
  std::shared_ptr<const ContrastiveModel> model_;
  motion::Motion content_;
  StyleCode old_, run_;
};

TEST_F(LiveControlTest, AStyleChangeCrossFadesWithoutAPop) {
  const motion::Motion plain = Run(old_, {});
  const motion::Motion changed = Run(old_, {{40, run_, std::nullopt, 15}});
  const motion::Motion other = Run(run_, {});
  ASSERT_EQ(changed.num_frames, content_.num_frames);
  // Untouched before the change.
  EXPECT_LT(motion::MaxPositionDifference(Frames(plain, 0, 40), Frames(changed, 0, 40)), 1e-6);
  // Changed after it.
  EXPECT_GT(motion::MaxPositionDifference(Frames(plain, 60, 110), Frames(changed, 60, 110)), 1.0);
  // No frame-to-frame move through the fade beyond what either style makes.
  const double own = std::max(MaxStep(plain, 30, 70), MaxStep(other, 30, 70));
  const double through = MaxStep(changed, 38, 60);
  std::printf("largest joint step: through the fade %.2f, either style alone %.2f\n", through, own);
  EXPECT_LT(through, 1.25 * own);
}

TEST_F(LiveControlTest, StrengthZeroGivesTheContentBack) {
  const motion::Motion out = Run(old_, {{30, std::nullopt, 0.0, 10}});
  // From the fade's end on, the pose is the content's own (the path always
  // is): per frame, the farthest joint from the content's, on average.
  const auto mean_gap = [&](const motion::Motion& m) {
    double sum = 0;
    for (int f = 45; f < 110; ++f)
      sum += motion::MaxPositionDifference(Frames(m, f, f + 1), Frames(content_, f, f + 1));
    return sum / 65;
  };
  const double gap = mean_gap(out);
  const double styled = mean_gap(Run(old_, {}));
  std::printf("strength 0 vs the content: %.2f; strength 1: %.2f\n", gap, styled);
  EXPECT_LT(gap, 0.5 * styled);
}

TEST_F(LiveControlTest, TheShippedPackagesStreamStateIsFixedOverTenMinutes) {
  auto s = LiveStreamer::Create(
      model_, {old_, content_.skeleton, content_.frame_time, motion::PostProcessMode::kFull});
  ASSERT_TRUE(s.ok()) << s.status();
  size_t first = 0;
  // 10 minutes at 30 Hz: the clip looped 150 times. The state fills its
  // windows over the first 5 seconds (the longest, the content's last 4 s
  // that its action is read from) and stays that size.
  const int filled = 5 * 30;
  for (int loop = 0; loop < 150; ++loop) {
    ASSERT_TRUE((*s)->Push(content_).ok());
    if ((*s)->received() < filled) continue;
    if (first == 0) first = (*s)->state_bytes();
    ASSERT_EQ((*s)->state_bytes(), first) << "after loop " << loop;
  }
  EXPECT_EQ((*s)->received(), 150 * content_.num_frames);
  std::printf("live/v3 stream state: %zu bytes (networks' carried state %zu) after %lld frames\n",
              (*s)->state_bytes(), (*s)->carry_bytes(), static_cast<long long>((*s)->received()));
}

TEST_F(LiveControlTest, OfflineStreamsRefuseStyleChanges) {
  std::shared_ptr<const StyleModel> offline(
      *LoadStyleModel(testing::DefaultPackageDir()));
  auto s = offline->OpenStream({*offline->EncodeStyle(Sample("walk_old.bvh")), content_.skeleton,
                                content_.frame_time, motion::PostProcessMode::kFull});
  ASSERT_TRUE(s.ok()) << s.status();
  const absl::Status refused = (*s)->ChangeStyle({10, std::nullopt, 0.5, 0});
  EXPECT_EQ(refused.code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(refused.message().find("live model"), std::string::npos) << refused;
}

}  // namespace
}  // namespace stylus::model
