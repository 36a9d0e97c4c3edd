// Movement from examples frame by frame: a stream steps at the example's
// cadence scaled by its walk ratio, never reads past its look-ahead, keeps
// the network's legs while the content stands, follows a gesture, and plays
// neither a gesture on a walk nor a run on a walk; with an action gate, a
// take plays only while the content's action reads as its own.
#include "motion/live_movement.h"

#include <cmath>
#include <functional>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/gait.h"
#include "motion/rig_roles.h"
#include "motion/synth.h"
#include "tests/test_support.h"

namespace stylus::motion {
namespace {

Motion Walk(const std::string& spec) { return *Synthesize(*ParseSynthStyle(spec)); }

struct Followed {
  Motion out;
  std::vector<std::optional<std::array<bool, 4>>> contacts;
  std::vector<double> step_weight, gesture_weight, gesture_time, gesture_cost;
  int gesture_take_at_end = -1;
};

// The content streamed through a follower, the network's output taken to be
// the content itself. `all_first`: every content frame is added before the
// first output frame is made (a stream pushed in one chunk).
// `actions(f)`, when given, is the content's action read before output
// frame f (empty: no new reading).
Followed Follow(const Motion& content, const StreamExamples& examples, int lookahead,
                bool all_first = false, double strength = 1, FollowOptions options = {},
                const std::function<std::vector<double>(int)>& actions = nullptr) {
  const HumanoidRoles roles = *HumanoidRolesOf(content);
  ContentTrack track(content.skeleton, roles, content.frame_time, lookahead);
  MovementFollower follower(examples, track, options);
  Followed r{content, {}, {}, {}, {}, {}};
  std::vector<Vec3> euler(content.skeleton.num_joints());
  int added = 0;
  for (int f = 0; f < content.num_frames; ++f) {
    const int want = all_first ? content.num_frames : std::min(content.num_frames, f + lookahead + 1);
    for (; added < want; ++added) track.Add(PoseAt(content, added));
    if (actions) follower.ReadActions(actions(f));
    std::optional<std::array<bool, 4>> on;
    const LocalPose pose = follower.Apply(track, track.Read(f), PoseAt(content, f), strength, &on);
    track.Forget(f + 1);
    SetPose(&r.out, f, pose, &euler);
    r.contacts.push_back(on);
    r.step_weight.push_back(follower.step_weight());
    r.gesture_weight.push_back(follower.gesture_weight());
    r.gesture_time.push_back(follower.gesture_time());
    r.gesture_cost.push_back(follower.gesture_cost());
    r.gesture_take_at_end = follower.gesture_take();
  }
  return r;
}

std::shared_ptr<const MovementClip> Read(const Motion& m) {
  return std::make_shared<const MovementClip>(*AnalyzeMovement(m, *HumanoidRolesOf(m)));
}

TEST(LiveMovementTest, AStreamStepsAtTheExamplesCadenceScaledByItsWalkRatio) {
  const Motion content = Walk("normal,frames=360,speed=130,stride=125");
  const Motion example = Walk("normal,frames=180,speed=70,stride=70,foot_lift=5,bounce=1");
  const HumanoidRoles roles = *HumanoidRolesOf(content);
  StreamExamples ex;
  ex.steps.push_back(Read(example));
  const Followed r = Follow(content, ex, 2);
  // Stepping from the first second on.
  EXPECT_EQ(r.step_weight.back(), 1);
  EXPECT_TRUE(r.contacts.back().has_value());
  Motion tail = r.out;
  const int skip = 60;
  tail.num_frames -= skip;
  tail.values.erase(tail.values.begin(),
                    tail.values.begin() + static_cast<size_t>(skip) * content.skeleton.num_channels());
  const GaitSummary c = MeasureGait(content, roles)->summary,
                    e = MeasureGait(example, roles)->summary,
                    o = MeasureGait(tail, roles)->summary;
  ASSERT_TRUE(o.cadence.has_value());
  const double want = e.cadence->period_s / std::sqrt(c.speed / e.speed);
  EXPECT_NEAR(o.cadence->period_s, want, 0.15 * want);
  EXPECT_NEAR(o.speed, c.speed, 0.08 * c.speed);
  // At strength 0 the output is the network's.
  const Followed none = Follow(content, ex, 2, false, 0);
  for (size_t i = 0; i < none.out.values.size(); ++i)
    ASSERT_NEAR(none.out.values[i], content.values[i], 1e-6);
}

TEST(LiveMovementTest, NoFrameReadsPastTheLookAhead) {
  const Motion content = Walk("normal,frames=150,speed=130,stride=125");
  StreamExamples ex;
  ex.steps.push_back(Read(Walk("normal,frames=180,speed=70,stride=70")));
  const Followed a = Follow(content, ex, 2), b = Follow(content, ex, 2, /*all_first=*/true);
  ASSERT_EQ(a.out.values.size(), b.out.values.size());
  for (size_t i = 0; i < a.out.values.size(); ++i) ASSERT_EQ(a.out.values[i], b.out.values[i]) << i;
}

TEST(LiveMovementTest, AStandingContentKeepsTheNetworksLegs) {
  const Motion content = RestMotion(Walk("normal,frames=2").skeleton, 90, 1.0 / 30);
  StreamExamples ex;
  ex.steps.push_back(Read(Walk("normal,frames=180,speed=70,stride=70")));
  const Followed r = Follow(content, ex, 2);
  for (double w : r.step_weight) EXPECT_EQ(w, 0);
  for (size_t i = 0; i < r.out.values.size(); ++i)
    ASSERT_NEAR(r.out.values[i], content.values[i], 1e-9);
}

TEST(LiveMovementTest, AGestureTakeFollowsTheContentsGestureToItsEnd) {
  STYLUS_REQUIRE_BANDAI(data);
  const std::string d = data + "/dataset-2/dataset-2_";
  const Motion content = *ReadBvhFile(d + "raise-up-both-hands_normal_001.bvh");
  const Motion example = *ReadBvhFile(d + "raise-up-both-hands_elderly_002.bvh");
  StreamExamples ex;
  ex.gestures.push_back(Read(example));
  const Followed r = Follow(content, ex, 2);
  const int n = content.num_frames, m = example.num_frames;
  EXPECT_EQ(r.gesture_take_at_end, 0);
  // It follows (the registration fits) for most of the clip, forward only.
  int following = 0;
  for (int f = 0; f < n; ++f) following += r.gesture_weight[f] == 1;
  EXPECT_GT(following, n / 2);
  double furthest = 0;
  for (int f = 1; f < n; ++f) {
    if (r.gesture_time[f] > 0) {
      EXPECT_GE(r.gesture_time[f], r.gesture_time[f - 1]);
    }
    furthest = std::max(furthest, r.gesture_time[f]);
  }
  // Through the example's raise: past its middle by the content's end (the
  // take is ~3x as long, and plays at most twice as fast as the content).
  EXPECT_GT(furthest, 0.5 * m);
  // The arms and legs are the example's, its contacts the output's.
  const HumanoidRoles roles = *HumanoidRolesOf(content);
  const LocalPose a = PoseAt(r.out, n / 2), c = PoseAt(content, n / 2);
  EXPECT_GT(1 - std::abs(Dot(a.rotations[roles.left_shoulder], c.rotations[roles.left_shoulder])),
            1e-6);
  EXPECT_GT(1 - std::abs(Dot(a.rotations[roles.left_hip], c.rotations[roles.left_hip])), 1e-6);
  EXPECT_TRUE(r.contacts[n / 2].has_value());
}

TEST(LiveMovementTest, OfSeveralGestureTakesTheOneThatShowsTheContentsGesturePlays) {
  STYLUS_REQUIRE_BANDAI(data);
  const std::string d = data + "/dataset-2/dataset-2_";
  const Motion content = *ReadBvhFile(d + "raise-up-left-hand_normal_003.bvh");
  StreamExamples ex;
  for (const char* take : {"wave-both-hands_elderly_001", "raise-up-right-hand_elderly_001",
                           "raise-up-left-hand_elderly_004"}) {
    ex.gestures.push_back(Read(*ReadBvhFile(d + take + ".bvh")));
  }
  const Followed r = Follow(content, ex, 2);
  EXPECT_EQ(r.gesture_take_at_end, 2);
}

TEST(LiveMovementTest, AGestureTakeNeverMovesTheLegsOfAContentThatWalks) {
  STYLUS_REQUIRE_BANDAI(data);
  const std::string d = data + "/dataset-2/dataset-2_";
  const Motion content = *ReadBvhFile(d + "walk_normal_004.bvh");
  StreamExamples ex;
  ex.gestures.push_back(Read(*ReadBvhFile(d + "raise-up-right-hand_elderly_009.bvh")));
  const Followed r = Follow(content, ex, 2);
  // Once it walks (its first second aside), the network's movement only.
  const int n = content.num_frames;
  for (int f = 45; f < n - 15; ++f) {
    ASSERT_EQ(r.gesture_weight[f], 0) << "frame " << f;
    ASSERT_FALSE(r.contacts[f].has_value()) << "frame " << f;
  }
}

TEST(LiveMovementTest, ARunTakeDoesNotStepAWalkButAWalkTakeDoes) {
  STYLUS_REQUIRE_BANDAI(data);
  const std::string d = data + "/dataset-2/dataset-2_";
  const Motion content = *ReadBvhFile(d + "walk_normal_004.bvh");
  const std::shared_ptr<const MovementClip> run = Read(*ReadBvhFile(d + "run_normal_002.bvh"));
  ASSERT_TRUE(run->steps);
  std::printf("the run take's flight: %.2f\n", run->flight);
  StreamExamples runs;
  runs.steps.push_back(run);
  for (double w : Follow(content, runs, 2).step_weight) ASSERT_EQ(w, 0);
  StreamExamples walks;
  walks.steps.push_back(Read(*ReadBvhFile(d + "walk_elderly_003.bvh")));
  EXPECT_EQ(Follow(content, walks, 2).step_weight[content.num_frames / 2], 1);
}

TEST(LiveMovementTest, AnActionGatePlaysATakeOnlyWhileTheContentReadsAsItsAction) {
  const Motion content = Walk("normal,frames=300,speed=130,stride=125");
  StreamExamples ex;
  ex.steps.push_back(Read(Walk("old,frames=180")));
  ex.step_actions = {{0.9, 0.1}};  // Mostly action 0.
  FollowOptions gated;
  gated.action_gate = 0.2;
  const std::vector<double> as_its_own = {0.7, 0.3}, as_another = {0.05, 0.95};
  const int n = content.num_frames;
  // Not read yet: the take plays.
  EXPECT_EQ(Follow(content, ex, 2, false, 1, gated).step_weight[n / 2], 1);
  // Read as its own action (overlap 0.8): it plays.
  const Followed own = Follow(content, ex, 2, false, 1, gated, [&](int) { return as_its_own; });
  EXPECT_EQ(own.step_weight[n / 2], 1);
  EXPECT_TRUE(own.contacts[n / 2].has_value());
  // Read as another (overlap 0.15 < 0.2) from the first frame: never.
  const Followed other = Follow(content, ex, 2, false, 1, gated, [&](int) { return as_another; });
  for (int f = 0; f < n; ++f) {
    ASSERT_EQ(other.step_weight[f], 0) << "frame " << f;
    ASSERT_FALSE(other.contacts[f].has_value()) << "frame " << f;
  }
  // Read as its own, then as another from frame 150: it fades out within a
  // recheck and a fade (0.5 s + 0.25 s).
  const Followed changed = Follow(content, ex, 2, false, 1, gated,
                                  [&](int f) { return f < 150 ? as_its_own : as_another; });
  EXPECT_EQ(changed.step_weight[149], 1);
  EXPECT_EQ(changed.step_weight[150 + 30], 0);
  EXPECT_EQ(changed.step_weight[n - 1], 0);
  // Without the gate, or for a take whose action is not known, the reading
  // does not matter.
  EXPECT_EQ(
      Follow(content, ex, 2, false, 1, {}, [&](int) { return as_another; }).step_weight[n / 2], 1);
  StreamExamples unknown = ex;
  unknown.step_actions = {{}};
  EXPECT_EQ(Follow(content, unknown, 2, false, 1, gated, [&](int) { return as_another; })
                .step_weight[n / 2],
            1);
}

TEST(LiveMovementTest, AnActionGateRefusesAGestureTakeOfAnotherAction) {
  STYLUS_REQUIRE_BANDAI(data);
  const std::string d = data + "/dataset-2/dataset-2_";
  const Motion content = *ReadBvhFile(d + "raise-up-both-hands_normal_001.bvh");
  StreamExamples ex;
  ex.gestures.push_back(Read(*ReadBvhFile(d + "raise-up-both-hands_elderly_002.bvh")));
  ex.gesture_actions = {{1, 0}};
  FollowOptions gated;
  gated.action_gate = 0.2;
  const Followed own = Follow(content, ex, 2, false, 1, gated, [](int) {
    return std::vector<double>{0.8, 0.2};
  });
  const Followed other = Follow(content, ex, 2, false, 1, gated, [](int) {
    return std::vector<double>{0.1, 0.9};
  });
  double most = 0;
  for (double w : own.gesture_weight) most = std::max(most, w);
  EXPECT_EQ(most, 1);
  for (double w : other.gesture_weight) ASSERT_EQ(w, 0);
}

}  // namespace
}  // namespace stylus::motion
