// Clips and streams at any capture rate from 24 to 240 Hz: resampled to the
// model's 30 Hz on the way in and back on the way out, output frames one to
// one with input frames; a live stream's latency in time does not grow with
// the rate.
#include <algorithm>
#include <cmath>

#include "gtest/gtest.h"
#include "model/contrastive/contrastive_model.h"
#include "motion/kinematics.h"
#include "motion/resample.h"
#include "tests/model/contrastive/contrastive_support.h"
#include "tests/test_support.h"

namespace stylus::model {
namespace {

using contrastive_testing::Clip;
using contrastive_testing::LivePackage;
using testing::Frames;

// Mean distance of the joints' world positions between frame fa of a and fb of b.
double MeanJointDistance(const motion::Motion& a, int fa, const motion::Motion& b, int fb) {
  const motion::GlobalPose ga = motion::ForwardKinematics(a.skeleton, motion::PoseAt(a, fa));
  const motion::GlobalPose gb = motion::ForwardKinematics(b.skeleton, motion::PoseAt(b, fb));
  double d = 0;
  for (size_t j = 0; j < ga.positions.size(); ++j)
    d += motion::Norm(ga.positions[j] - gb.positions[j]);
  return d / ga.positions.size();
}

class FrameRateTest : public ::testing::TestWithParam<double> {};

TEST_P(FrameRateTest, TransfersComeBackAtTheContentsRate) {
  const double fps = GetParam();
  const auto model = LivePackage(2);
  const motion::Motion at30 = Clip(0);
  const motion::Motion content = motion::Resample(at30, 1 / fps);
  const StyleCode style = *model->EncodeStyle(motion::Resample(Clip(1), 1 / fps));
  absl::StatusOr<TransferResult> out = model->Transfer(content, style);
  ASSERT_TRUE(out.ok()) << out.status();
  EXPECT_EQ(out->motion.num_frames, content.num_frames);
  EXPECT_DOUBLE_EQ(out->motion.frame_time, content.frame_time);
  // The same motion as the 30 Hz transfer, at the shared instants (up to
  // the resampling's and post-processing's differences).
  absl::StatusOr<TransferResult> ref = model->Transfer(at30, *model->EncodeStyle(Clip(1)));
  ASSERT_TRUE(ref.ok());
  // Against a yardstick: how far the reference moves in a quarter second.
  double match = 0, moved = 0;
  int n = 0;
  for (int f = 0; f + 8 < at30.num_frames; f += 4, ++n) {
    const int g = static_cast<int>(std::lround(f * fps / 30));
    match += MeanJointDistance(ref->motion, f, out->motion, g);
    moved += MeanJointDistance(ref->motion, f, ref->motion, f + 8);
  }
  EXPECT_LT(match / n, 0.25 * moved / n) << "mean joint distances, in the clip's units";
}

TEST_P(FrameRateTest, LiveStreamsMatchInputFramesOneToOneWithinTheLookaheadInTime) {
  const double fps = GetParam();
  const auto model = LivePackage(2);
  const double model_ft = model->data().frame_time;
  const motion::Motion content = motion::Resample(Clip(2), 1 / fps);
  auto s = model->OpenStream({*model->EncodeStyle(Clip(3)), content.skeleton, content.frame_time,
                              motion::PostProcessMode::kFull});
  ASSERT_TRUE(s.ok()) << s.status();
  int out = 0;
  for (int f = 0; f < content.num_frames; ++f) {
    absl::StatusOr<motion::Motion> got = (*s)->Push(Frames(content, f, f + 1));
    ASSERT_TRUE(got.ok()) << got.status();
    EXPECT_DOUBLE_EQ(got->frame_time, content.frame_time);
    out += got->num_frames;
    // The newest frame out is at most the lookahead in time (plus one input
    // frame) behind the newest frame in.
    if (f * content.frame_time > 4 * model_ft) {
      EXPECT_LE((f - (out - 1)) * content.frame_time,
                model->config().lookahead * model_ft + content.frame_time + 1e-9)
          << "after input frame " << f;
    }
  }
  absl::StatusOr<motion::Motion> rest = (*s)->Finish();
  ASSERT_TRUE(rest.ok()) << rest.status();
  EXPECT_EQ(out + rest->num_frames, content.num_frames);
}

INSTANTIATE_TEST_SUITE_P(Rates, FrameRateTest, ::testing::Values(24.0, 60.0, 120.0, 240.0, 47.95));

TEST(FrameRateRefusalTest, RatesOutsideTheServedRangeAreRefusedByName) {
  const auto model = LivePackage(2);
  const motion::Motion fast = motion::Resample(Clip(0), 1.0 / 250);
  absl::StatusOr<TransferResult> out = model->Transfer(fast, *model->EncodeStyle(Clip(1)));
  ASSERT_EQ(out.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(out.status().message().find("content clip is at 250 fps"), std::string::npos)
      << out.status();
  EXPECT_EQ(model->EncodeStyle(fast).status().code(), absl::StatusCode::kInvalidArgument);
  auto s = model->OpenStream({*model->EncodeStyle(Clip(1)), fast.skeleton, fast.frame_time,
                              motion::PostProcessMode::kFull});
  EXPECT_EQ(s.status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(FrameRateOfflineTest, WindowedStreamsAtSixtyHertzGiveEveryFrame) {
  // An offline package streams window by window at its rate, resampled the same way.
  const std::string dir = contrastive_testing::Dir("offline_rates");
  ASSERT_TRUE(TrainContrastive(contrastive_testing::TinyOptions(dir, 4)).ok());
  std::shared_ptr<const ContrastiveModel> model = *ContrastiveModel::Load(dir);
  const motion::Motion content = motion::Resample(Clip(0), 1.0 / 60);
  auto s = model->OpenStream({*model->EncodeStyle(Clip(1)), content.skeleton, content.frame_time,
                              motion::PostProcessMode::kFull});
  ASSERT_TRUE(s.ok()) << s.status();
  int out = 0;
  for (int f = 0; f < content.num_frames; f += 5) {
    absl::StatusOr<motion::Motion> got =
        (*s)->Push(Frames(content, f, std::min(content.num_frames, f + 5)));
    ASSERT_TRUE(got.ok()) << got.status();
    out += got->num_frames;
  }
  absl::StatusOr<motion::Motion> rest = (*s)->Finish();
  ASSERT_TRUE(rest.ok()) << rest.status();
  EXPECT_EQ(out + rest->num_frames, content.num_frames);
}

}  // namespace
}  // namespace stylus::model
