#include "motion/position_fit.h"

#include <cmath>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/synth.h"
#include "tests/test_support.h"

namespace stylus::motion {
namespace {

double MaxPositionGap(const FeatureClip& a, const FeatureClip& b, int joints) {
  double worst = 0;
  for (int f = 0; f < a.frames; ++f)
    for (int c = 0; c < 3 * joints; ++c)
      worst = std::max(worst, std::fabs(double(a.row(f)[c]) - b.row(f)[c]));
  return worst;
}

// Positions of a real motion, rotations replaced by the identity (no twist
// information at all): the fit must rebuild the positions.
void ExpectRecovers(const Motion& m, double tolerance) {
  const HumanoidRoles roles = *FindHumanoidRoles(m.skeleton);
  const FeatureClip truth = *ExtractFeatures(m, roles);
  const int joints = m.skeleton.num_joints();
  const FeatureLayout layout(joints);
  FeatureClip guess = truth;
  for (int f = 0; f < guess.frames; ++f)
    for (int j = 0; j < joints; ++j) {
      float* q = guess.row(f) + layout.rotation(j);
      q[0] = 1, q[1] = q[2] = q[3] = 0;
    }
  FitRotationsToPositions(m.skeleton, roles, &guess);
  EXPECT_LT(MaxPositionGap(guess, truth, joints), tolerance * roles.leg_length);
  // Fitted rotations are unit quaternions, and decoding them gives a motion.
  for (int f = 0; f < guess.frames; ++f) {
    const float* q = guess.row(f) + layout.rotation(roles.pelvis);
    EXPECT_NEAR(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3], 1.0, 1e-4);
  }
  EXPECT_TRUE(MotionFromFeatures(guess, m.skeleton, roles, m.frame_time).ok());
}

TEST(PositionFitTest, RebuildsSyntheticPositionsFromIdentityRotations) {
  ExpectRecovers(*Synthesize(*ParseSynthStyle("normal,frames=60")), 2e-3);
}

TEST(PositionFitTest, RebuildsRealPositionsFromIdentityRotations) {
  STYLUS_REQUIRE_BANDAI(data);
  absl::StatusOr<Motion> m =
      ReadBvhFile(data + "/dataset-1/"
                         "dataset-1_walk_normal_001.bvh");
  ASSERT_TRUE(m.ok()) << m.status();
  ExpectRecovers(*m, 2e-3);
}

TEST(PositionFitTest, KeepsBoneLengthsWhenTargetsAreOutOfReach) {
  const Motion m = *Synthesize(*ParseSynthStyle("old,frames=30"));
  const HumanoidRoles roles = *FindHumanoidRoles(m.skeleton);
  const FeatureClip truth = *ExtractFeatures(m, roles);
  const int joints = m.skeleton.num_joints();
  const FeatureLayout layout(joints);
  // Targets stretched 20% away from the pelvis: bones cannot follow; the fit
  // keeps the skeleton's lengths and reaches towards the targets.
  FeatureClip stretched = truth;
  for (int f = 0; f < stretched.frames; ++f) {
    const float* pelvis = truth.row(f) + layout.position(roles.pelvis);
    for (int j = roles.pelvis + 1; j < joints; ++j)
      for (int a = 0; a < 3; ++a) {
        float* p = stretched.row(f) + layout.position(j) + a;
        *p = pelvis[a] + 1.2f * (*p - pelvis[a]);
      }
  }
  const FeatureClip targets = stretched;
  FitRotationsToPositions(m.skeleton, roles, &stretched);
  auto at = [&](const FeatureClip& c, int f, int j) {
    const float* p = c.row(f) + layout.position(j);
    return Vec3{p[0], p[1], p[2]};
  };
  for (int f = 0; f < stretched.frames; ++f) {
    for (int j = roles.pelvis + 1; j < joints; ++j) {
      const double bone = Norm(at(stretched, f, j) - at(stretched, f, m.skeleton.joint(j).parent));
      EXPECT_NEAR(bone, Norm(m.skeleton.joint(j).offset), 1e-4 * roles.leg_length)
          << "frame " << f << " joint " << m.skeleton.joint(j).name;
    }
    for (int ankle : {roles.left_ankle, roles.right_ankle}) {
      EXPECT_LT(Norm(at(stretched, f, ankle) - at(targets, f, ankle)),
                Norm(at(truth, f, ankle) - at(targets, f, ankle)))
          << "frame " << f;
    }
  }
}

}  // namespace
}  // namespace stylus::motion

namespace stylus::motion {
namespace {

// A real walk (Bandai), its features and its left knee: the set-up of the
// knee tests.
class KneeFitTest : public ::testing::Test {
 protected:
  void SetUp() override {
    STYLUS_REQUIRE_BANDAI(data);
    absl::StatusOr<Motion> m = ReadBvhFile(data + "/dataset-2/dataset-2_walk_normal_001.bvh");
    ASSERT_TRUE(m.ok()) << m.status();
    walk_ = *std::move(m);
    roles_ = *FindHumanoidRoles(walk_.skeleton);
    truth_ = *ExtractFeatures(walk_, roles_);
    layout_ = FeatureLayout(walk_.skeleton.num_joints());
    knee_ = walk_.skeleton.children(roles_.left_hip)[0];
    ASSERT_EQ(walk_.skeleton.children(knee_)[0], roles_.left_ankle);
  }
  Motion walk_;
  HumanoidRoles roles_;
  FeatureClip truth_;
  FeatureLayout layout_{0};
  int knee_ = -1;
};

// Knees are hinges in captured motion (Bandai: the local rotation's x and z
// parts vary by ~0.002). A generated pose whose ankle moves off the content's
// (closer to the hip and sideways) is fitted by bending the knee about its
// own axis and turning the hip, never by twisting the knee sideways, which
// would give rotation features dozens of the data's standard deviations off.
TEST_F(KneeFitTest, KneesStayHingesWhenTheAnkleMoves) {
  FeatureClip moved = truth_;
  const double leg = roles_.leg_length;
  for (int f = 0; f < moved.frames; ++f) {
    float* ankle = moved.row(f) + layout_.position(roles_.left_ankle);
    const float* hip = truth_.row(f) + layout_.position(roles_.left_hip);
    for (int a = 0; a < 3; ++a) ankle[a] = hip[a] + 0.93f * (ankle[a] - hip[a]);
    ankle[0] += static_cast<float>(0.05 * leg);  // Sideways.
  }
  const FeatureClip targets = moved;
  FitRotationsToPositions(walk_.skeleton, roles_, &moved);
  double off_axis = 0, ankle_error = 0, bend_change = 0;
  for (int f = 0; f < moved.frames; ++f) {
    const float* q = moved.row(f) + layout_.rotation(knee_);
    off_axis = std::max({off_axis, std::fabs(double(q[1])), std::fabs(double(q[3]))});
    const float* before = truth_.row(f) + layout_.rotation(knee_);
    bend_change = std::max(bend_change, std::fabs(double(q[2]) - before[2]));
    const float* got = moved.row(f) + layout_.position(roles_.left_ankle);
    const float* want = targets.row(f) + layout_.position(roles_.left_ankle);
    ankle_error = std::max(ankle_error, std::hypot(double(got[0] - want[0]),
                                                   double(got[1] - want[1]),
                                                   double(got[2] - want[2])));
  }
  std::printf("knee off-axis %.5f, bend change %.3f, ankle error %.4f leg lengths\n", off_axis,
              bend_change, ankle_error / leg);
  EXPECT_LT(off_axis, 0.02);        // The capture's own: ~0.01 at most.
  EXPECT_GT(bend_change, 0.05);     // The knee did bend to shorten the leg ...
  EXPECT_LT(ankle_error, 0.03 * leg);  // ... and the ankle reached its target.
  // The other (untouched) leg comes back as it was.
  double other = 0;
  for (int f = 0; f < moved.frames; ++f)
    for (int a = 0; a < 3; ++a)
      other = std::max(other, std::fabs(double(moved.row(f)[layout_.position(roles_.right_ankle) + a]) -
                                        truth_.row(f)[layout_.position(roles_.right_ankle) + a]));
  EXPECT_LT(other, 2e-3 * leg);
}

// Generated rotations turn a knee about its axis only nearly; the hinge is
// then found in a reference clip's rotations (the content's), and the knee
// still bends about that axis alone.
TEST_F(KneeFitTest, HingesComeFromTheReferenceWhenTheStartingRotationsAreGenerated) {
  // Every knee rotation turned 6 degrees off its axis, as a network might.
  FeatureClip generated = truth_;
  for (int f = 0; f < generated.frames; ++f) {
    float* q = generated.row(f) + layout_.rotation(knee_);
    const Quat off = Normalized(Quat{q[0], q[1], q[2], q[3]}) * AxisAngle({1, 0, 0}, 0.1);
    q[0] = off.w, q[1] = off.x, q[2] = off.y, q[3] = off.z;
  }
  auto worst_off_axis = [&](const FeatureClip& fitted) {
    double worst = 0;
    for (int f = 0; f < fitted.frames; ++f) {
      const float* q = fitted.row(f) + layout_.rotation(knee_);
      worst = std::max({worst, std::fabs(double(q[1])), std::fabs(double(q[3]))});
    }
    return worst;
  };
  FeatureClip alone = generated, referenced = generated;
  FitRotationsToPositions(walk_.skeleton, roles_, &alone);
  FitRotationsToPositions(walk_.skeleton, roles_, &referenced, &truth_);
  std::printf("knee off-axis: %.4f without the reference, %.4f with it\n", worst_off_axis(alone),
              worst_off_axis(referenced));
  EXPECT_GT(worst_off_axis(alone), 0.04);  // No hinge found: the knee twists.
  EXPECT_LT(worst_off_axis(referenced), 0.02);
  EXPECT_LT(MaxPositionGap(referenced, truth_, walk_.skeleton.num_joints()), 0.01 * roles_.leg_length);
}

}  // namespace
}  // namespace stylus::motion
