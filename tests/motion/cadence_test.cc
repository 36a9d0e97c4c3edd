// Cadence: the step period of walks whose gait is known, none for a clip
// that does not repeat, real Bandai walks; and the time warp.
#include "motion/cadence.h"

#include <cmath>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/dataset.h"
#include "motion/resample.h"
#include "motion/rig_roles.h"
#include "motion/synth.h"
#include "tests/test_support.h"

namespace stylus::motion {
namespace {

Motion Walk(const std::string& spec) { return *Synthesize(*ParseSynthStyle(spec)); }

TEST(CadenceTest, FindsTheStepPeriodOfSynthesizedWalks) {
  // A full gait cycle is stride / speed seconds; a step is half of it.
  for (const auto& [spec, step_s] : std::vector<std::pair<std::string, double>>{
           {"normal,frames=150,speed=130,stride=125", 125.0 / 130 / 2},
           {"normal,frames=150,speed=100,stride=160", 160.0 / 100 / 2},
           {"old,frames=90,speed=80,stride=110", 110.0 / 80 / 2},
           {"normal,frames=300,fps=60,speed=130,stride=125", 125.0 / 130 / 2}}) {
    const Motion walk = Walk(spec);
    absl::StatusOr<Cadence> c = FindCadence(walk, *HumanoidRolesOf(walk));
    ASSERT_TRUE(c.ok()) << spec << ": " << c.status();
    EXPECT_EQ(c->source, Cadence::Source::kSteps) << spec;
    EXPECT_NEAR(c->period_s, step_s, 0.05 * step_s) << spec;
    EXPECT_GT(c->strength, 0.7) << spec;
  }
}

TEST(CadenceTest, TempoRatiosCompareLikeWithLike) {
  const Motion quick = Walk("normal,frames=90,speed=130,stride=125");
  const Motion slow = Walk("old,frames=90,speed=80,stride=110");
  const HumanoidRoles roles = *HumanoidRolesOf(quick);
  const Cadence q = *FindCadence(quick, roles), s = *FindCadence(slow, roles);
  const double want = (110.0 / 80) / (125.0 / 130);
  EXPECT_NEAR(*TempoRatio(q, s), want, 0.07 * want);
  EXPECT_NEAR(*TempoRatio(s, q), 1 / want, 0.07 / want);
  // Steps and a motion that does not step do not compare.
  Cadence waving{Cadence::Source::kMotion, 0.8, 0.9};
  EXPECT_EQ(TempoRatio(q, waving).status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(CadenceTest, AClipThatDoesNotRepeatHasNone) {
  const Motion walk = Walk("normal,frames=90");
  Motion still = walk;
  for (int f = 0; f < still.num_frames; ++f) {
    std::copy(walk.frame(0), walk.frame(0) + walk.skeleton.num_channels(), still.frame(f));
  }
  EXPECT_EQ(FindCadence(still, *HumanoidRolesOf(still)).status().code(),
            absl::StatusCode::kNotFound);
  Motion short_clip = walk;
  short_clip.num_frames = 12;
  short_clip.values.resize(12 * walk.skeleton.num_channels());
  absl::Status too_short = FindCadence(short_clip, *HumanoidRolesOf(short_clip)).status();
  EXPECT_EQ(too_short.code(), absl::StatusCode::kNotFound);
  EXPECT_NE(too_short.message().find("too short"), std::string::npos) << too_short;
}

TEST(CadenceTest, RealWalksStepAboutTwiceASecond) {
  STYLUS_REQUIRE_BANDAI(dir);
  for (const char* name :
       {"dataset-1/dataset-1_walk_normal_001.bvh", "dataset-1/dataset-1_walk_old_001.bvh",
        "dataset-2/dataset-2_walk_elderly_001.bvh"}) {
    const Motion clip = *ReadBvhFile(dir + "/" + name);
    absl::StatusOr<Cadence> c = FindCadence(clip, *HumanoidRolesOf(clip));
    ASSERT_TRUE(c.ok()) << name << ": " << c.status();
    EXPECT_GT(c->period_s, 0.4) << name;
    EXPECT_LT(c->period_s, 0.8) << name;
    // At 120 Hz the same clip has the same cadence.
    const Motion fast = Resample(clip, 1.0 / 120);
    absl::StatusOr<Cadence> f = FindCadence(fast, *HumanoidRolesOf(fast));
    ASSERT_TRUE(f.ok()) << name << ": " << f.status();
    EXPECT_EQ(c->source, Cadence::Source::kSteps) << name;
    EXPECT_NEAR(f->period_s, c->period_s, 0.02) << name;
  }
}

TEST(TimeWarpTest, PlaysTheClipSlowerOrFasterAndKeepsItsEnds) {
  const Motion walk = Walk("normal,frames=91,speed=120");
  for (double ratio : {0.75, 1.25, 2.0}) {
    const Motion out = TimeWarp(walk, ratio);
    EXPECT_EQ(out.num_frames, static_cast<int>(std::lround(90 * ratio)) + 1) << ratio;
    EXPECT_DOUBLE_EQ(out.frame_time, walk.frame_time);
    EXPECT_LT(
        MaxPositionDifference(Resample(out, out.frame_time, 1), Resample(walk, walk.frame_time, 1)),
        1e-6);
    // Same path, so the mean speed scales by 1 / ratio.
    const HumanoidRoles roles = *HumanoidRolesOf(walk);
    absl::StatusOr<Cadence> before = FindCadence(walk, roles), after = FindCadence(out, roles);
    ASSERT_TRUE(before.ok() && after.ok()) << ratio;
    EXPECT_NEAR(*TempoRatio(*before, *after), ratio, 0.06 * ratio) << ratio;
    for (int c = 0; c < walk.skeleton.num_channels(); ++c) {
      EXPECT_NEAR(out.frame(out.num_frames - 1)[c], walk.frame(walk.num_frames - 1)[c], 1e-6)
          << "channel " << c << " at ratio " << ratio;
    }
  }
}

}  // namespace
}  // namespace stylus::motion
