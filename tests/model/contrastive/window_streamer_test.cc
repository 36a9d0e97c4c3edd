// Streaming transfer gives the frames of a whole-clip transfer, in order, for
// any chunking of the input.
#include "model/contrastive/window_streamer.h"

#include <random>
#include <string>

#include "gtest/gtest.h"
#include "model/window_blend.h"
#include "motion/bvh.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"
#include "tests/test_support.h"

namespace stylus::model {
namespace {

using testing::Append;
using testing::Frames;

const std::string kModel = testing::DefaultPackageDir();


// Streams `clip` in chunks of random sizes (1..max_chunk) and returns the
// output, checking that frames come out in order and only after enough input.
motion::Motion Stream(std::shared_ptr<const ContrastiveModel> model, const StyleCode& style,
                      const motion::Motion& clip, int max_chunk, uint64_t seed,
                      motion::PostProcessMode post = motion::PostProcessMode::kNone) {
  auto s = model->OpenStream({style, clip.skeleton, clip.frame_time, post});
  EXPECT_TRUE(s.ok()) << s.status();
  motion::Motion out = Frames(clip, 0, 0);
  std::mt19937_64 rng(seed);
  const int window = model->config().window, hop = model->config().hop;
  for (int f = 0; f < clip.num_frames;) {
    const int n = std::min<int>(clip.num_frames - f, 1 + rng() % max_chunk);
    absl::StatusOr<motion::Motion> got = (*s)->Push(Frames(clip, f, f + n));
    EXPECT_TRUE(got.ok()) << got.status();
    f += n;
    Append(*got, &out);
    EXPECT_EQ((*s)->emitted(), out.num_frames);
    // Nothing comes out before the window after it is complete; everything
    // comes out within window + hop (+1 for the velocity look-ahead) frames.
    EXPECT_LE(out.num_frames, std::max(0, f - window - 1));
    EXPECT_GE(out.num_frames, f - window - hop - 1 - max_chunk);
  }
  absl::StatusOr<motion::Motion> rest = (*s)->Finish();
  EXPECT_TRUE(rest.ok()) << rest.status();
  Append(*rest, &out);
  return out;
}

TEST(WindowBlenderTest, CrossFadesOverlapsAndReleasesFramesInOrder) {
  WindowBlender b(/*window=*/4, /*overlap=*/2, /*dim=*/1);
  const float ones[4] = {1, 1, 1, 1}, threes[4] = {3, 3, 3, 3};
  b.Add(0, ones);
  b.Add(2, threes);
  const motion::FeatureClip first = b.Take(2);
  ASSERT_EQ(first.frames, 2);
  EXPECT_FLOAT_EQ(first.values[0], 1.f);
  EXPECT_FLOAT_EQ(first.values[1], 1.f);
  const motion::FeatureClip rest = b.Take(6);
  ASSERT_EQ(rest.frames, 4);
  // Frame 2: window 0 fades out (weight 2/3), window 1 fades in (1/3).
  EXPECT_NEAR(rest.values[0], (1 * 2.f / 3 + 3 * 1.f / 3) / 1.f, 1e-6);
  EXPECT_NEAR(rest.values[1], (1 * 1.f / 3 + 3 * 2.f / 3) / 1.f, 1e-6);
  EXPECT_FLOAT_EQ(rest.values[3], 3.f);
  EXPECT_EQ(b.taken(), 6);
}

TEST(StreamTransferTest, RealClipStreamedMatchesWholeClipTransfer) {
  STYLUS_REQUIRE_BANDAI(dir);
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> loaded = ContrastiveModel::Load(kModel);
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  std::shared_ptr<const ContrastiveModel> model = std::move(*loaded);
  const motion::Motion content =
      *motion::ReadBvhFile(dir + "/dataset-1/dataset-1_walk_normal_001.bvh");
  const motion::Motion style = *motion::ReadBvhFile(dir + "/dataset-1/dataset-1_walk_old_001.bvh");
  const StyleCode code = *model->EncodeStyle(style);
  // Streams keep the network's movement (docs/movement.md "Streams").
  TransferOptions network_movement(motion::PostProcessMode::kNone);
  network_movement.movement_from_examples = false;
  const motion::Motion whole = model->Transfer(content, code, network_movement)->motion;
  for (int max_chunk : {1, 7, 40}) {
    const motion::Motion streamed = Stream(model, code, content, max_chunk, max_chunk);
    ASSERT_EQ(streamed.num_frames, whole.num_frames);
    // Tolerance (docs/service.md): 0.5 mm on any joint of any frame. The
    // stream's contact detector sees a bounded, causal history of the feet.
    EXPECT_LT(motion::MaxPositionDifference(streamed, whole), 0.05) << "chunks of " << max_chunk;
  }
}

TEST(StreamTransferTest, StreamedFeetAreLockedCausally) {
  STYLUS_REQUIRE_BANDAI(dir);
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> loaded = ContrastiveModel::Load(kModel);
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  std::shared_ptr<const ContrastiveModel> model = std::move(*loaded);
  const motion::Motion content =
      *motion::ReadBvhFile(dir + "/dataset-1/dataset-1_walk_normal_001.bvh");
  const StyleCode code =
      *model->EncodeStyle(*motion::ReadBvhFile(dir + "/dataset-1/dataset-1_walk_old_001.bvh"));
  const auto& roles = model->data().roles;
  const motion::Motion raw = Stream(model, code, content, 9, 3, motion::PostProcessMode::kNone);
  const motion::Motion locked = Stream(model, code, content, 9, 3, motion::PostProcessMode::kFull);
  ASSERT_EQ(locked.num_frames, content.num_frames);
  const double before = motion::FootSkating(raw, content, roles);
  const double after = motion::FootSkating(locked, content, roles);
  EXPECT_LT(after, 0.5 * before) << before << " -> " << after;
  EXPECT_EQ(motion::EulerDiscontinuities(locked), 0);
}

TEST(StreamTransferTest, ShortStreamIsPaddedLikeAShortClip) {
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> loaded = ContrastiveModel::Load(kModel);
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  std::shared_ptr<const ContrastiveModel> model = std::move(*loaded);
  const motion::Motion clip =
      *motion::ReadBvhFile(testing::SourceDir() + "/samples/walk_normal.bvh");
  const motion::Motion shortclip = Frames(clip, 0, 20);
  const StyleCode code = *model->EncodeStyle(clip);
  // Streams are not guarded (docs/service.md): against the configured form.
  TransferOptions options(motion::PostProcessMode::kNone);
  options.content_guard = false;
  const motion::Motion whole = model->Transfer(shortclip, code, options)->motion;
  const motion::Motion streamed = Stream(model, code, shortclip, 5, 1);
  ASSERT_EQ(streamed.num_frames, 20);
  EXPECT_LT(motion::MaxPositionDifference(streamed, whole), 1e-3);
}

TEST(StreamTransferTest, RejectsAnotherSkeletonAndEmptyStreams) {
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> loaded = ContrastiveModel::Load(kModel);
  ASSERT_TRUE(loaded.ok()) << loaded.status();
  std::shared_ptr<const ContrastiveModel> model = std::move(*loaded);
  const motion::Motion other =
      *motion::ReadBvhFile(testing::FixturePath("bvh/good/three_joint.bvh"));
  const StyleCode code{std::vector<float>(model->config().channels, 0.f)};
  EXPECT_EQ(model->OpenStream({code, other.skeleton, other.frame_time}).status().code(),
            absl::StatusCode::kInvalidArgument);
  EXPECT_EQ(model->OpenStream({StyleCode{{1.f}}, model->data().skeleton, model->data().frame_time})
                .status()
                .code(),
            absl::StatusCode::kInvalidArgument);
  auto s = model->OpenStream({code, model->data().skeleton, model->data().frame_time});
  ASSERT_TRUE(s.ok()) << s.status();
  EXPECT_EQ((*s)->Finish().status().code(), absl::StatusCode::kFailedPrecondition);
  // A model that no std::shared_ptr owns cannot stream.
  absl::StatusOr<std::unique_ptr<ContrastiveModel>> unshared = ContrastiveModel::Load(kModel);
  ASSERT_TRUE(unshared.ok()) << unshared.status();
  EXPECT_EQ((*unshared)
                ->OpenStream({code, model->data().skeleton, model->data().frame_time})
                .status()
                .code(),
            absl::StatusCode::kFailedPrecondition);
}

}  // namespace
}  // namespace stylus::model
