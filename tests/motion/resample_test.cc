#include "motion/resample.h"

#include <cmath>

#include "gtest/gtest.h"
#include "motion/kinematics.h"
#include "motion/synth.h"

namespace stylus::motion {
namespace {

Motion Walk() { return *Synthesize(*ParseSynthStyle("normal,turn=45,frames=61")); }

double MaxJointDistance(const Motion& a, int fa, const Motion& b, int fb) {
  const GlobalPose ga = ForwardKinematics(a.skeleton, PoseAt(a, fa));
  const GlobalPose gb = ForwardKinematics(b.skeleton, PoseAt(b, fb));
  double d = 0;
  for (size_t j = 0; j < ga.positions.size(); ++j)
    d = std::max(d, Norm(ga.positions[j] - gb.positions[j]));
  return d;
}

TEST(ResampleTest, FrameCountsFollowTheDuration) {
  const Motion m = Walk();  // 61 frames at 30 Hz: 2 s.
  EXPECT_EQ(Resample(m, 1.0 / 120).num_frames, 241);
  EXPECT_EQ(Resample(m, 1.0 / 24).num_frames, 49);
  EXPECT_EQ(Resample(m, 1.0 / 29.97).num_frames, 60);
  EXPECT_EQ(Resample(m, 1.0 / 60, 7).num_frames, 7);
  EXPECT_DOUBLE_EQ(Resample(m, 1.0 / 60).frame_time, 1.0 / 60);
}

TEST(ResampleTest, SharedInstantsKeepTheirPoseAndInBetweensLieBetween) {
  const Motion m = Walk();
  const Motion up = Resample(m, 1.0 / 120);
  for (int f = 0; f < m.num_frames; f += 5) {
    EXPECT_LT(MaxJointDistance(m, f, up, 4 * f), 1e-6) << "frame " << f;
  }
  // Half-way frames sit near the mean of their neighbours' joint positions.
  for (int f = 0; f + 1 < m.num_frames; f += 7) {
    const GlobalPose a = ForwardKinematics(m.skeleton, PoseAt(m, f));
    const GlobalPose b = ForwardKinematics(m.skeleton, PoseAt(m, f + 1));
    const GlobalPose mid = ForwardKinematics(up.skeleton, PoseAt(up, 4 * f + 2));
    for (size_t j = 0; j < a.positions.size(); ++j) {
      const Vec3 mean = (a.positions[j] + b.positions[j]) * 0.5;
      EXPECT_LT(Norm(mid.positions[j] - mean), 0.5) << "frame " << f << " joint " << j;
    }
  }
}

TEST(ResampleTest, DownAndUpAgainComesBackClose) {
  const Motion m = Walk();
  const Motion back = Resample(Resample(m, 1.0 / 240), m.frame_time, m.num_frames);
  ASSERT_EQ(back.num_frames, m.num_frames);
  for (int f = 0; f < m.num_frames; ++f) EXPECT_LT(MaxJointDistance(m, f, back, f), 1e-6);
}

TEST(ResampleTest, ServedRatesAre24To240Hz) {
  for (double fps : {24.0, 29.97, 60.0, 119.88, 240.0}) {
    EXPECT_TRUE(CheckServedRate(1 / fps, "clip").ok()) << fps;
  }
  for (double fps : {23.0, 241.0, 1000.0}) {
    const absl::Status s = CheckServedRate(1 / fps, "clip");
    EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument) << fps;
    EXPECT_NE(s.message().find("from 24 to 240 fps"), std::string::npos) << s.message();
  }
}

}  // namespace
}  // namespace stylus::motion
