#include "motion/mirror.h"

#include <cmath>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/features.h"
#include "motion/humanoid.h"
#include "motion/kinematics.h"
#include "tests/test_support.h"

namespace stylus::motion {
namespace {

Motion Load(const std::string& data, const std::string& name) {
  absl::StatusOr<Motion> m = ReadBvhFile(data + "/" + name);
  EXPECT_TRUE(m.ok()) << m.status();
  return *m;
}

int JointIndex(const Skeleton& s, const std::string& name) { return *s.Find(name); }

// The sign-aligned mean of joint j's local rotation over a clip.
Quat MeanRotation(const Motion& m, int j) {
  Quat sum{0, 0, 0, 0};
  const Quat first = PoseAt(m, 0).rotations[j];
  for (int f = 0; f < m.num_frames; ++f) {
    Quat q = PoseAt(m, f).rotations[j];
    if (Dot(q, first) < 0) q = {-q.w, -q.x, -q.y, -q.z};
    sum = {sum.w + q.w, sum.x + q.x, sum.y + q.y, sum.z + q.z};
  }
  return Normalized(sum);
}

// A real walk mirrored: every joint lands where its counterpart's mirror
// image was (x -> -x), on the same skeleton; mirroring twice gives the clip
// back; the chosen rotations look like the other side's own.
TEST(MirrorTest, RealWalkLandsOnItsMirrorImageAndBack) {
  STYLUS_REQUIRE_BANDAI(data);
  const Motion walk = Load(data, "dataset-2/dataset-2_walk_normal_001.bvh");
  const Motion raise = Load(data, "dataset-2/dataset-2_raise-up-left-hand_normal_001.bvh");
  absl::StatusOr<MirrorMap> map = PlanMirror(walk.skeleton, {&walk, &raise});
  ASSERT_TRUE(map.ok()) << map.status();
  const Skeleton& sk = walk.skeleton;
  EXPECT_EQ(map->counterpart[JointIndex(sk, "UpperArm_L")], JointIndex(sk, "UpperArm_R"));
  EXPECT_EQ(map->counterpart[JointIndex(sk, "Toes_R")], JointIndex(sk, "Toes_L"));
  EXPECT_EQ(map->counterpart[JointIndex(sk, "Hips")], JointIndex(sk, "Hips"));

  const Motion mirrored = MirrorMotion(walk, *map);
  ASSERT_EQ(mirrored.num_frames, walk.num_frames);
  ASSERT_EQ(mirrored.values.size(), walk.values.size());
  const double worst = MaxMirrorError(walk, mirrored, *map);
  // The rig is symmetric to within a fraction of a unit (cm); a wrong
  // reflection anywhere puts a limb tens of units off.
  EXPECT_LT(worst, 0.5) << worst;

  const Motion back = MirrorMotion(mirrored, *map);
  const auto before = GlobalPositions(walk), again = GlobalPositions(back);
  double round_trip = 0;
  for (int f = 0; f < walk.num_frames; ++f)
    for (int j = 0; j < sk.num_joints(); ++j)
      round_trip = std::max(round_trip, Norm(again[f][j] - before[f][j]));
  EXPECT_LT(round_trip, 1e-6);
  for (int f = 0; f < walk.num_frames; f += 7) {
    const LocalPose a = PoseAt(walk, f), b = PoseAt(back, f);
    for (int j = 0; j < sk.num_joints(); ++j)
      EXPECT_LT(AngleBetween(a.rotations[j], b.rotations[j]), 1e-6) << sk.joint(j).name;
  }

  // Where the offsets leave the twist about a bone open, the samples decide:
  // the mirrored arms and legs turn, on average, like the other side's own,
  // not half a turn about the bone away from them.
  for (const char* name : {"UpperArm_L", "LowerArm_R", "UpperLeg_L", "Foot_R", "Spine"}) {
    const int j = JointIndex(sk, name), k = map->counterpart[j];
    const double gap = AngleBetween(MeanRotation(mirrored, k), MeanRotation(walk, k));
    std::printf("%s mirrored onto %s: mean rotation %.3f rad from its own\n", name,
                sk.joint(k).name.c_str(), gap);
    EXPECT_LT(gap, 0.35) << name;
  }
  std::printf("mirror: worst joint gap %.3f units\n", worst);
}

// One clip is enough to plan the mirror, whatever it does: a one-sided
// action (a raised left hand) gives the plan of a walk, and a dataset-1 clip
// whose hips' OFFSET is a world position 452 units off the origin (the hips'
// channels place them) is mirrored as exactly as the walk.
TEST(MirrorTest, EveryClipPlansTheSameMirrorOnItsOwn) {
  STYLUS_REQUIRE_BANDAI(data);
  const Motion walk = Load(data, "dataset-2/dataset-2_walk_normal_001.bvh");
  const Motion raise = Load(data, "dataset-2/dataset-2_raise-up-left-hand_normal_001.bvh");
  const Motion bow = Load(data, "dataset-1/dataset-1_bow_active_001.bvh");
  ASSERT_GT(std::fabs(bow.skeleton.joint(JointIndex(bow.skeleton, "Hips")).offset.z), 400);
  const MirrorMap both = *PlanMirror(walk.skeleton, {&walk, &raise});
  for (const Motion* m : {&raise, &bow}) {
    absl::StatusOr<MirrorMap> alone = PlanMirror(m->skeleton, {m});
    ASSERT_TRUE(alone.ok()) << alone.status();
    for (int j = 0; j < m->skeleton.num_joints(); ++j) {
      EXPECT_EQ(alone->flip[j].x, both.flip[j].x) << m->skeleton.joint(j).name;
      EXPECT_EQ(alone->flip[j].y, both.flip[j].y) << m->skeleton.joint(j).name;
      EXPECT_EQ(alone->flip[j].z, both.flip[j].z) << m->skeleton.joint(j).name;
    }
    EXPECT_LT(MaxMirrorError(*m, MirrorMotion(*m, *alone), *alone), 0.5);
  }
}

// Features of the mirrored walk: the root turns and sidesteps the other
// way, the feet's contacts swap sides.
TEST(MirrorTest, MirroredFeaturesTurnTheOtherWayAndSwapTheFeet) {
  STYLUS_REQUIRE_BANDAI(data);
  const Motion turn = Load(data, "dataset-2/dataset-2_walk-turn-left_normal_001.bvh");
  absl::StatusOr<MirrorMap> map = PlanMirror(turn.skeleton, {&turn});
  ASSERT_TRUE(map.ok()) << map.status();
  const HumanoidRoles roles = *FindHumanoidRoles(turn.skeleton);
  const FeatureClip a = *ExtractFeatures(turn, roles);
  const FeatureClip b = *ExtractFeatures(MirrorMotion(turn, *map), roles);
  const FeatureLayout layout(turn.skeleton.num_joints());
  const int t = layout.trajectory(), c = layout.contacts();
  double yaw = 0, mirrored_yaw = 0, yaw_gap = 0;
  int contacts_swapped = 0;
  for (int f = 0; f < a.frames; ++f) {
    yaw += a.row(f)[t + 2], mirrored_yaw += b.row(f)[t + 2];
    yaw_gap = std::max(yaw_gap, double(std::fabs(a.row(f)[t + 2] + b.row(f)[t + 2])));
    contacts_swapped += a.row(f)[c] == b.row(f)[c + 2] && a.row(f)[c + 3] == b.row(f)[c + 1];
  }
  EXPECT_GT(std::fabs(yaw), 1.0);  // The clip turns ...
  EXPECT_NEAR(mirrored_yaw, -yaw, 0.05 * std::fabs(yaw));  // ... and its mirror the other way.
  EXPECT_GE(contacts_swapped, 0.95 * a.frames);
  std::printf("turn: yaw rate sum %.2f -> %.2f (largest per-frame gap %.3f), contacts swapped in "
              "%d of %d frames\n",
              yaw, mirrored_yaw, yaw_gap, contacts_swapped, a.frames);
}

TEST(MirrorTest, LabelsSwapSidesAndRigsWithoutCounterpartsAreRefused) {
  EXPECT_EQ(MirrorLabel("raise-up-left-hand"), "raise-up-right-hand");
  EXPECT_EQ(MirrorLabel("walk-turn-right"), "walk-turn-left");
  EXPECT_EQ(MirrorLabel("bow"), "bow");

  std::vector<Joint> joints(3);
  joints[0].name = "Hips";
  joints[1].name = "UpperArm_L", joints[1].parent = 0, joints[1].offset = {10, 0, 0};
  joints[2].name = "Hand_L", joints[2].parent = 1, joints[2].offset = {10, 0, 0};
  const Skeleton lopsided = *Skeleton::Create(joints);
  absl::StatusOr<MirrorMap> map = PlanMirror(lopsided, {});
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.status().message(),
            "cannot mirror the skeleton: joint 'UpperArm_L' has no counterpart 'UpperArm_R'");

  joints[2].name = "UpperArm_R", joints[2].parent = 0, joints[2].offset = {0, 7, 3};
  const Skeleton skewed = *Skeleton::Create(joints);
  map = PlanMirror(skewed, {});
  ASSERT_FALSE(map.ok());
  EXPECT_NE(map.status().message().find("not left-right symmetric at joint 'Hips'"),
            std::string::npos)
      << map.status();
}

}  // namespace
}  // namespace stylus::motion
