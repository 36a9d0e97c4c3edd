// Movement from examples on synthesized walks and real Bandai takes: the
// output steps at the example's cadence scaled by its walk ratio, keeps the
// content's frame count and path, and plants its feet on its own contacts.
#include "motion/example_motion.h"

#include <cmath>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/cadence.h"
#include "motion/dataset.h"
#include "motion/gait.h"
#include "motion/metrics.h"
#include "motion/rig_roles.h"
#include "motion/synth.h"
#include "tests/test_support.h"

namespace stylus::motion {
namespace {

Motion Walk(const std::string& spec) { return *Synthesize(*ParseSynthStyle(spec)); }

struct Moved {
  Motion raw, planted;
  MovementResult result;
  Registration reg;
};

Moved Move(const Motion& content, const Motion& example, const MovementOptions& options = {}) {
  const HumanoidRoles roles = *HumanoidRolesOf(content);
  absl::StatusOr<MovementClip> c = AnalyzeMovement(content, roles);
  absl::StatusOr<MovementClip> e = AnalyzeMovement(example, roles);
  EXPECT_TRUE(c.ok()) << c.status();
  EXPECT_TRUE(e.ok()) << e.status();
  absl::StatusOr<Registration> reg = RegisterMovement(*c, *e);
  EXPECT_TRUE(reg.ok()) << reg.status();
  absl::StatusOr<MovementResult> r = ApplyMovement(content, *c, *e, *reg, options);
  EXPECT_TRUE(r.ok()) << r.status();
  PostProcessParams params;
  params.contact_spans = &r->contacts;
  absl::StatusOr<Motion> planted =
      PostProcess(r->motion, r->motion, roles, PostProcessMode::kFull, params);
  EXPECT_TRUE(planted.ok()) << planted.status();
  return {r->motion, *planted, *r, *reg};
}

TEST(ExampleMotionTest, ASlowStyleWalksTheContentsPathWithMoreShorterSteps) {
  const Motion content = Walk("normal,frames=180,speed=130,stride=125");
  const Motion example = Walk("normal,frames=180,speed=70,stride=70,foot_lift=5,bounce=1");
  const HumanoidRoles roles = *HumanoidRolesOf(content);
  const Moved m = Move(content, example);
  EXPECT_EQ(m.reg.kind, Registration::Kind::kSteps);
  ASSERT_EQ(m.planted.num_frames, content.num_frames);
  const GaitSummary c = MeasureGait(content, roles)->summary,
                    e = MeasureGait(example, roles)->summary,
                    o = MeasureGait(m.planted, roles)->summary;
  // Walk ratio: at 130/70 of its speed the example steps sqrt(130/70) times
  // faster, so its period is its own over 1.36.
  const double want = e.cadence->period_s / std::sqrt(c.speed / e.speed);
  EXPECT_NEAR(o.cadence->period_s, want, 0.1 * want);
  EXPECT_NEAR(o.speed, c.speed, 0.05 * c.speed);
  EXPECT_LT(FootSkatingOnSpans(m.planted, m.result.contacts, roles),
            1.2 * FootSkating(content, content, roles) + 2);
}

}  // namespace
}  // namespace stylus::motion

namespace stylus::motion {
namespace {

MovementClip Read(const std::string& data, const std::string& name) {
  const Motion m = *ReadBvhFile(data + "/dataset-2/dataset-2_" + name + ".bvh");
  return *AnalyzeMovement(m, *HumanoidRolesOf(m));
}

TEST(ExampleMotionTest, RealWalksAndRunsPlantTheirOwnStepsAsFirmlyAsCapture) {
  STYLUS_REQUIRE_BANDAI(data);
  const std::string d = data + "/dataset-2/dataset-2_";
  const Motion content = *ReadBvhFile(d + "walk_normal_004.bvh");
  const HumanoidRoles roles = *HumanoidRolesOf(content);
  const double real = FootSkating(content, content, roles);
  for (const char* style :
       {"walk_elderly_003", "walk_youthful_002", "run_active_001", "walk-turn-left_elderly_002"}) {
    const Motion example = *ReadBvhFile(d + style + ".bvh");
    const Moved m = Move(content, example);
    EXPECT_EQ(m.reg.kind, Registration::Kind::kSteps) << style;
    const double raw = FootSkatingOnSpans(m.raw, m.result.contacts, roles);
    const double planted = FootSkatingOnSpans(m.planted, m.result.contacts, roles);
    EXPECT_LT(planted, 1.2 * real) << style << ": raw " << raw << ", real " << real;
    EXPECT_NEAR(MeasureGait(m.planted, roles)->summary.speed,
                MeasureGait(content, roles)->summary.speed,
                0.05 * MeasureGait(content, roles)->summary.speed)
        << style;
  }
}

TEST(ExampleMotionTest, ArmsAreCompatibleWhenTheSameHandsDoTheSameKindOfThing) {
  STYLUS_REQUIRE_BANDAI(d);
  std::string why;
  EXPECT_TRUE(
      SameArmAction(Read(d, "wave-left-hand_normal_003"), Read(d, "wave-left-hand_youthful_002")));
  EXPECT_TRUE(SameArmAction(Read(d, "raise-up-both-hands_normal_003"),
                            Read(d, "raise-up-both-hands_elderly_002")));
  EXPECT_FALSE(SameArmAction(Read(d, "wave-left-hand_normal_003"),
                             Read(d, "raise-up-left-hand_youthful_002"), &why));
  EXPECT_NE(why.find("swings"), std::string::npos) << why;
  EXPECT_FALSE(SameArmAction(Read(d, "raise-up-right-hand_normal_003"),
                             Read(d, "raise-up-both-hands_elderly_002"), &why));
  EXPECT_NE(why.find("left hand travels"), std::string::npos) << why;
  // A walk does not register to a wave, and the error says which steps.
  absl::StatusOr<Registration> r =
      RegisterMovement(Read(d, "walk_normal_004"), Read(d, "wave-left-hand_normal_003"));
  EXPECT_EQ(r.status().code(), absl::StatusCode::kFailedPrecondition);
  EXPECT_NE(r.status().message().find("content clip steps"), std::string::npos) << r.status();
}

TEST(ExampleMotionTest, AGesturesRegistrationIsMonotoneAndSpansTheExample) {
  STYLUS_REQUIRE_BANDAI(data);
  const MovementClip c = Read(data, "raise-up-both-hands_normal_003");
  const MovementClip e = Read(data, "raise-up-both-hands_elderly_002");
  absl::StatusOr<Registration> r = RegisterMovement(c, e);
  ASSERT_TRUE(r.ok()) << r.status();
  EXPECT_EQ(r->kind, Registration::Kind::kGesture);
  ASSERT_EQ(r->time.size(), static_cast<size_t>(c.clip.num_frames));
  for (size_t f = 1; f < r->time.size(); ++f) ASSERT_GE(r->time[f], r->time[f - 1]) << f;
  EXPECT_EQ(r->time.front(), 0);
  EXPECT_EQ(r->time.back(), e.clip.num_frames - 1);
}

// A clip as long as a server takes (10 minutes) is read with a loop of at
// most kMaxLoopS: the loop search holds nothing per pair of frames.
TEST(ExampleMotionTest, ALongClipsLoopIsBounded) {
  const Motion walk = Walk("normal,frames=18000,speed=130,stride=125");
  absl::StatusOr<MovementClip> m = AnalyzeMovement(walk, *HumanoidRolesOf(walk));
  ASSERT_TRUE(m.ok()) << m.status();
  EXPECT_TRUE(m->steps);
  EXPECT_GT(m->loop_end - m->loop_begin, 0);
  EXPECT_LE((m->loop_end - m->loop_begin) * walk.frame_time, kMaxLoopS + 1e-9);
}

TEST(ExampleMotionTest, PartSourcesParseByName) {
  EXPECT_EQ(*ParsePartSource("layer"), PartSource::kLayer);
  EXPECT_EQ(PartSourceName(*ParsePartSource("example")), std::string("example"));
  const absl::Status bad = ParsePartSource("legs").status();
  EXPECT_EQ(bad.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(bad.message().find("network, example or layer"), std::string::npos);
}

}  // namespace
}  // namespace stylus::motion
