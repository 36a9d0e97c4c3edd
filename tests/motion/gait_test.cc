// Gait curves and their summary: synthesized walks whose stride, lift, arm
// swing, bounce and speed are known; a clip that does not move; the same walk
// on rigs of other sizes, names and up axes.
#include "motion/gait.h"

#include <cmath>

#include "gtest/gtest.h"
#include "motion/rig_roles.h"
#include "motion/synth.h"
#include "tests/support/test_rigs.h"

namespace stylus::motion {
namespace {

Motion Walk(const std::string& spec) { return *Synthesize(*ParseSynthStyle(spec)); }

GaitSummary Summary(const Motion& clip) {
  absl::StatusOr<Gait> g = MeasureGait(clip, *HumanoidRolesOf(clip));
  EXPECT_TRUE(g.ok()) << g.status();
  return g.ok() ? g->summary : GaitSummary{};
}

TEST(GaitTest, EachKnobOfASynthesizedWalkMovesItsOwnFigure) {
  const std::string base = "normal,frames=150,speed=130,stride=125";
  const GaitSummary normal = Summary(Walk(base));
  const GaitSummary long_stride = Summary(Walk("normal,frames=150,speed=130,stride=170"));
  const GaitSummary swinging = Summary(Walk(base + ",arm_swing=40"));
  const GaitSummary lifting = Summary(Walk(base + ",foot_lift=25"));
  // A short stride, so that the pelvis bobs by the knob and not by how far
  // the planted feet reach.
  const std::string short_steps = "normal,frames=150,speed=100,stride=90";
  const GaitSummary level = Summary(Walk(short_steps + ",bounce=0.5"));
  const GaitSummary bouncing = Summary(Walk(short_steps + ",bounce=8"));
  EXPECT_GT(long_stride.stride, 1.2 * normal.stride);
  EXPECT_GT(swinging.arm_swing, 1.5 * normal.arm_swing);
  EXPECT_GT(lifting.foot_lift, 1.5 * normal.foot_lift);
  EXPECT_GT(bouncing.bob, 2 * level.bob);
  // Each knob leaves the other figures about where they were.
  EXPECT_NEAR(swinging.stride, normal.stride, 0.05 * normal.stride);
  EXPECT_NEAR(lifting.arm_swing, normal.arm_swing, 0.05 * normal.arm_swing);
  EXPECT_NEAR(bouncing.foot_lift, level.foot_lift, 0.1 * level.foot_lift);
  // Speed in leg lengths per second, the step period from the feet.
  const Motion walk = Walk(base);
  const HumanoidRoles roles = *HumanoidRolesOf(walk);
  EXPECT_NEAR(normal.speed * roles.leg_length, 130, 0.05 * 130);
  ASSERT_TRUE(normal.cadence.has_value());
  EXPECT_NEAR(normal.cadence->period_s, 125.0 / 130 / 2, 0.05);
  ASSERT_TRUE(long_stride.cadence.has_value());
  EXPECT_GT(long_stride.cadence->period_s, normal.cadence->period_s);
}

TEST(GaitTest, AClipThatDoesNotMoveHasFlatCurvesAndNoCadence) {
  const Motion walk = Walk("normal,frames=60");
  Motion still = walk;
  for (int f = 0; f < still.num_frames; ++f) {
    std::copy(walk.frame(0), walk.frame(0) + walk.skeleton.num_channels(), still.frame(f));
  }
  const GaitSummary s = Summary(still);
  EXPECT_NEAR(s.stride, 0, 1e-9);
  EXPECT_NEAR(s.foot_lift, 0, 1e-9);
  EXPECT_NEAR(s.arm_swing, 0, 1e-9);
  EXPECT_NEAR(s.bob, 0, 1e-9);
  EXPECT_NEAR(s.speed, 0, 1e-9);
  EXPECT_FALSE(s.cadence.has_value());
  absl::StatusOr<Gait> gait = MeasureGait(still, *HumanoidRolesOf(still));
  ASSERT_TRUE(gait.ok());
  EXPECT_EQ(gait->curves.foot_forward.size(), 60u);
  Motion empty = walk;
  empty.num_frames = 0;
  empty.values.clear();
  EXPECT_EQ(MeasureGait(empty, *HumanoidRolesOf(walk)).status().code(),
            absl::StatusCode::kInvalidArgument);
}

TEST(GaitTest, TheSameWalkOnOtherRigsReadsTheSame) {
  // Leg lengths as the unit: metres, Z up, other names, twist bones and props.
  const Motion walk = Walk("old,frames=120");
  const GaitSummary want = Summary(walk);
  for (testing::TestRig rig :
       {testing::TestRig::kMixamoMetres, testing::TestRig::kRigify, testing::TestRig::kUnreal}) {
    absl::StatusOr<Motion> other = testing::BuildTestRig(walk, rig);
    ASSERT_TRUE(other.ok()) << other.status();
    const GaitSummary got = Summary(*other);
    const std::string name = testing::TestRigName(rig);
    // The rigs' legs are not Bandai's bone for bone (their ankles and hips
    // sit elsewhere), so allow some difference in scale.
    EXPECT_NEAR(got.stride, want.stride, 0.15 * want.stride) << name;
    EXPECT_NEAR(got.foot_lift, want.foot_lift, 0.15 * want.foot_lift) << name;
    EXPECT_NEAR(got.arm_swing, want.arm_swing, 0.15 * want.arm_swing) << name;
    EXPECT_NEAR(got.speed, want.speed, 0.15 * want.speed) << name;
    ASSERT_TRUE(got.cadence.has_value()) << name;
    EXPECT_NEAR(got.cadence->period_s, want.cadence->period_s, 0.05) << name;
  }
}

}  // namespace
}  // namespace stylus::motion
