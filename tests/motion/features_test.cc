#include "motion/features.h"

#include <algorithm>
#include <cmath>

#include "gtest/gtest.h"
#include "motion/kinematics.h"
#include "motion/synth.h"

namespace stylus::motion {
namespace {

struct Fixture {
  Motion motion;
  HumanoidRoles roles;
};

Fixture Walk(const std::string& style) {
  Fixture fx;
  fx.motion = *Synthesize(*ParseSynthStyle(style));
  fx.roles = *FindHumanoidRoles(fx.motion.skeleton);
  return fx;
}

TEST(FeaturesTest, LayoutAndNames) {
  const Fixture fx = Walk("normal,frames=40");
  absl::StatusOr<FeatureClip> f = ExtractFeatures(fx.motion, fx.roles);
  ASSERT_TRUE(f.ok());
  const int j = fx.motion.skeleton.num_joints();
  EXPECT_EQ(f->dim, 7 * j + 8);
  EXPECT_EQ(f->frames, 40);
  const auto names = FeatureLayout(j).ChannelNames(fx.motion.skeleton, fx.roles);
  ASSERT_EQ(static_cast<int>(names.size()), f->dim);
  EXPECT_EQ(names[FeatureLayout(j).position(fx.roles.pelvis) + 1], "Hips.py");
  EXPECT_EQ(names.back(), "contact.Toes_R");
  // The pelvis sits above the root: its local x and z are zero.
  for (int t = 0; t < f->frames; ++t) {
    EXPECT_NEAR(f->row(t)[FeatureLayout(j).position(fx.roles.pelvis)], 0, 1e-4);
    EXPECT_NEAR(f->row(t)[FeatureLayout(j).position(fx.roles.pelvis) + 2], 0, 1e-4);
  }
}

TEST(FeaturesTest, QuaternionsStayInOneHemisphere) {
  const Fixture fx = Walk("normal,turn=90,frames=120");  // A full turn and a half.
  absl::StatusOr<FeatureClip> f = ExtractFeatures(fx.motion, fx.roles);
  ASSERT_TRUE(f.ok());
  const FeatureLayout layout(fx.motion.skeleton.num_joints());
  for (int t = 1; t < f->frames; ++t) {
    for (int j = 0; j < layout.num_joints; ++j) {
      const float* a = f->row(t - 1) + layout.rotation(j);
      const float* b = f->row(t) + layout.rotation(j);
      EXPECT_GE(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3], 0)
          << "frame " << t << " joint " << j;
    }
  }
}

TEST(FeaturesTest, AVagueGeneratedRotationKeepsThePreviousFrames) {
  const Fixture fx = Walk("normal,frames=20");
  absl::StatusOr<FeatureClip> f = ExtractFeatures(fx.motion, fx.roles);
  ASSERT_TRUE(f.ok()) << f.status();
  const FeatureLayout layout(fx.motion.skeleton.num_joints());
  const int knee = fx.motion.skeleton.joint(fx.roles.left_ankle).parent;
  // Frame 10's knee: a short quaternion pointing somewhere else entirely.
  float* q = f->row(10) + layout.rotation(knee);
  const float vague[4] = {0.05f, -0.2f, 0.1f, 0.05f};
  std::copy(vague, vague + 4, q);
  absl::StatusOr<Motion> m = MotionFromFeatures(
      *f, fx.motion.skeleton, fx.roles, fx.motion.frame_time, RootAt(fx.motion, fx.roles, 0));
  ASSERT_TRUE(m.ok()) << m.status();
  const Quat at9 = PoseAt(*m, 9).rotations[knee], at10 = PoseAt(*m, 10).rotations[knee];
  EXPECT_LT(AngleBetween(at9, at10), 1e-4);
  // Scaled, but clear: taken as it is.
  std::copy(vague, vague + 4, q);
  for (int c = 0; c < 4; ++c) q[c] *= 5;
  m = MotionFromFeatures(*f, fx.motion.skeleton, fx.roles, fx.motion.frame_time,
                         RootAt(fx.motion, fx.roles, 0));
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_GT(AngleBetween(PoseAt(*m, 9).rotations[knee], PoseAt(*m, 10).rotations[knee]), 0.3);
}

TEST(FeaturesTest, FeaturesToMotionToFeaturesIsIdentity) {
  for (const char* style : {"normal", "run", "old,turn=-40"}) {
    SCOPED_TRACE(style);
    const Fixture fx = Walk(style);
    absl::StatusOr<FeatureClip> f1 = ExtractFeatures(fx.motion, fx.roles);
    ASSERT_TRUE(f1.ok());
    absl::StatusOr<Motion> m =
        MotionFromFeatures(*f1, fx.motion.skeleton, fx.roles, fx.motion.frame_time, {3, -2, 0.7});
    ASSERT_TRUE(m.ok()) << m.status();
    absl::StatusOr<FeatureClip> f2 = ExtractFeatures(*m, fx.roles);
    ASSERT_TRUE(f2.ok());
    double worst = 0;
    for (size_t i = 0; i < f1->values.size(); ++i) {
      worst = std::max(worst, static_cast<double>(std::fabs(f1->values[i] - f2->values[i])));
    }
    EXPECT_LT(worst, 2e-3);  // cm, cm/s, rad/s and quaternion units alike.
  }
}

TEST(FeaturesTest, MotionRebuiltFromFeaturesMatchesTheOriginal) {
  const Fixture fx = Walk("happy,turn=25");
  absl::StatusOr<FeatureClip> f = ExtractFeatures(fx.motion, fx.roles);
  ASSERT_TRUE(f.ok());
  absl::StatusOr<Motion> m = MotionFromFeatures(
      *f, fx.motion.skeleton, fx.roles, fx.motion.frame_time, RootAt(fx.motion, fx.roles, 0));
  ASSERT_TRUE(m.ok());
  EXPECT_LT(MaxPositionDifference(fx.motion, *m), 0.05);
}

TEST(FeaturesTest, TrajectoryIsInTheFacingFrame) {
  // Walking straight at 130 cm/s: forward velocity ~130, sideways ~0, whichever
  // way the walk heads in the world.
  const Fixture fx = Walk("normal,frames=90");
  absl::StatusOr<FeatureClip> f = ExtractFeatures(fx.motion, fx.roles);
  ASSERT_TRUE(f.ok());
  const FeatureLayout layout(fx.motion.skeleton.num_joints());
  double vx = 0, vz = 0;
  for (int t = 0; t < f->frames; ++t) {
    vx += f->row(t)[layout.trajectory()];
    vz += f->row(t)[layout.trajectory() + 1];
  }
  EXPECT_NEAR(vz / f->frames, 130, 10);
  EXPECT_NEAR(vx / f->frames, 0, 10);
}

TEST(FeaturesTest, RejectsMismatchedOrNonFiniteFeatures) {
  const Fixture fx = Walk("normal,frames=10");
  FeatureClip f = *ExtractFeatures(fx.motion, fx.roles);
  FeatureClip narrow = f;
  narrow.dim -= 1;
  EXPECT_FALSE(MotionFromFeatures(narrow, fx.motion.skeleton, fx.roles, 1 / 30.0).ok());
  f.values[17] = NAN;
  const absl::Status s = MotionFromFeatures(f, fx.motion.skeleton, fx.roles, 1 / 30.0).status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(s.message().find("channel 17"), std::string::npos) << s;
}

TEST(FeaturesTest, HumanoidRolesNeedNamedLegs) {
  std::vector<Joint> joints(2);
  joints[0].name = "a";
  joints[1].name = "b";
  joints[1].parent = 0;
  const absl::Status s = FindHumanoidRoles(*Skeleton::Create(joints)).status();
  EXPECT_FALSE(s.ok());
  EXPECT_NE(s.message().find("not a recognizable humanoid"), std::string::npos);
}

namespace {

// ExtractFeatures with the running floor, frame by frame through a FeatureStream.
FeatureClip Streamed(const Fixture& fx) {
  FeatureStream stream(fx.motion.skeleton, fx.roles, fx.motion.frame_time, {});
  FeatureClip out;
  out.dim = stream.dim();
  std::vector<float> row(out.dim);
  for (int f = 0; f < fx.motion.num_frames; ++f) {
    if (stream.Push(fx.motion.frame(f), row.data())) {
      out.values.insert(out.values.end(), row.begin(), row.end());
      ++out.frames;
    }
    EXPECT_EQ(out.frames, f) << "frame f's features wait for frame f + 1";
  }
  EXPECT_TRUE(stream.Finish(row.data()));
  EXPECT_FALSE(stream.Finish(row.data()));
  out.values.insert(out.values.end(), row.begin(), row.end());
  ++out.frames;
  return out;
}

}  // namespace

TEST(FeatureStreamTest, FrameByFrameEqualsTheWholeClipWithTheRunningFloor) {
  // A walk that starts with a foot in the air and turns, so contacts,
  // hemisphere flips and yaw rates all occur.
  const Fixture fx = Walk("old,turn=60,frames=90");
  ContactParams running;
  running.running_floor = true;
  absl::StatusOr<FeatureClip> whole = ExtractFeatures(fx.motion, fx.roles, running);
  ASSERT_TRUE(whole.ok()) << whole.status();
  const FeatureClip streamed = Streamed(fx);
  ASSERT_EQ(streamed.frames, whole->frames);
  ASSERT_EQ(streamed.dim, whole->dim);
  int contacts = 0;
  for (size_t i = 0; i < whole->values.size(); ++i) {
    ASSERT_NEAR(streamed.values[i], whole->values[i], 1e-5)
        << "frame " << i / whole->dim << " channel " << i % whole->dim;
    if (static_cast<int>(i % whole->dim) >=
        FeatureLayout(fx.motion.skeleton.num_joints()).contacts())
      contacts += whole->values[i] > 0.5f;
  }
  EXPECT_GT(contacts, 0);
}

TEST(FeatureStreamTest, TheRunningFloorOnlyDiffersBeforeTheFeetHaveTouchedDown) {
  const Fixture fx = Walk("normal,frames=90");
  ContactParams running;
  running.running_floor = true;
  const FeatureClip a = *ExtractFeatures(fx.motion, fx.roles);
  const FeatureClip b = *ExtractFeatures(fx.motion, fx.roles, running);
  const FeatureLayout layout(fx.motion.skeleton.num_joints());
  int differ = 0, late = 0;
  for (int f = 0; f < a.frames; ++f) {
    for (int k = 0; k < 4; ++k) {
      if (a.row(f)[layout.contacts() + k] != b.row(f)[layout.contacts() + k]) {
        ++differ;
        late += f >= 45;
      }
    }
  }
  EXPECT_EQ(late, 0) << "after a full stride both floors agree";
  SUCCEED() << differ << " contact values differ in the first stride";
}

TEST(FeatureStreamTest, OneFrameHasStillFeatures) {
  const Fixture fx = Walk("normal,frames=1");
  FeatureStream stream(fx.motion.skeleton, fx.roles, fx.motion.frame_time, {});
  std::vector<float> row(stream.dim(), -1.f);
  EXPECT_FALSE(stream.Push(fx.motion.frame(0), row.data()));
  ASSERT_TRUE(stream.Finish(row.data()));
  const FeatureLayout layout(fx.motion.skeleton.num_joints());
  for (int c = 0; c < 4; ++c) EXPECT_EQ(row[layout.trajectory() + c], 0.f);
}

}  // namespace
}  // namespace stylus::motion
