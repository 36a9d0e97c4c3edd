// Post-processing: leg IK, foot locking, bone lengths, Euler continuity.
#include "motion/postprocess.h"

#include <cmath>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/contacts.h"
#include "motion/ik.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"
#include "tests/test_support.h"

namespace stylus::motion {
namespace {

double Dist(const Vec3& a, const Vec3& b) { return Norm(a - b); }

TEST(TwoBoneIkTest, ReachesReachableTargetsKeepingLengthsAndBendPlane) {
  const Vec3 hip{0, 100, 0}, knee{0, 55, 5}, ankle{0, 10, 0};
  for (const Vec3& target :
       {Vec3{10, 20, 15}, Vec3{-20, 30, 0}, Vec3{5, 60, -10}, Vec3{0, 12, 0}}) {
    const TwoBoneResult r = SolveTwoBone(hip, knee, ankle, target);
    EXPECT_TRUE(r.reached);
    EXPECT_LT(Dist(r.ankle, target), 1e-3);
    EXPECT_NEAR(Dist(r.knee, hip), Dist(knee, hip), 1e-9);
    EXPECT_NEAR(Dist(r.ankle, r.knee), Dist(ankle, knee), 1e-9);
    // The deltas move the bones where the positions say.
    EXPECT_LT(Dist(hip + Rotate(r.hip_delta, knee - hip), r.knee), 1e-6);
    EXPECT_LT(Dist(r.knee + Rotate(r.knee_delta, Rotate(Conjugate(r.hip_delta),
                                                        Rotate(r.hip_delta, ankle - knee))),
                   r.ankle),
              1e-6);
  }
  // The knee still points forward (+z), as in the input pose.
  const TwoBoneResult r = SolveTwoBone(hip, knee, ankle, {0, 30, 0});
  EXPECT_GT(r.knee.z, 0);
}

TEST(TwoBoneIkTest, UnreachableTargetsGiveAStraightLegNotNan) {
  const Vec3 hip{0, 100, 0}, knee{0, 55, 5}, ankle{0, 10, 0};
  const double l1 = Dist(knee, hip), l2 = Dist(ankle, knee);
  const TwoBoneResult far = SolveTwoBone(hip, knee, ankle, {0, -200, 50});
  EXPECT_FALSE(far.reached);
  EXPECT_NEAR(Dist(far.ankle, hip), l1 + l2, 1e-9);
  // Straight: the knee lies on the hip-ankle segment.
  EXPECT_NEAR(Dist(hip, far.knee) + Dist(far.knee, far.ankle), Dist(hip, far.ankle), 1e-6);
  // The straight leg points at the target.
  const Vec3 dir = Normalized(Vec3{0, -200, 50} - hip);
  EXPECT_LT(Dist(Normalized(far.ankle - hip), dir), 1e-9);
  // A straight input leg (no bend plane) and a target at the hip: finite.
  const TwoBoneResult degenerate = SolveTwoBone(hip, {0, 55, 0}, ankle, hip);
  for (double v : {degenerate.knee.x, degenerate.knee.y, degenerate.knee.z, degenerate.ankle.x,
                   degenerate.ankle.y, degenerate.ankle.z, degenerate.hip_delta.w})
    EXPECT_TRUE(std::isfinite(v));
}

TEST(TwoBoneIkTest, TheKneeTurnsOnlyAboutItsHingeAndStaysPutForItsOwnAnkle) {
  const Vec3 hip{0, 100, 0}, knee{0, 55, 5}, ankle{0, 10, 0};
  TwoBoneParams params;
  params.hinge = Vec3{1, 0.1, 0};  // Not quite the pose's own (x).
  const TwoBoneResult r = SolveTwoBone(hip, knee, ankle, {8, 25, 12}, params);
  EXPECT_TRUE(r.reached);
  // What the knee gets beyond the hip's swing is a turn about the hinge.
  const Quat bend = Conjugate(r.hip_delta) * r.knee_delta;
  const Vec3 axis{bend.x, bend.y, bend.z};
  EXPECT_GT(Norm(axis), 1e-3);
  EXPECT_LT(Norm(Cross(Normalized(axis), Normalized(*params.hinge))), 1e-9);
  // The ankle's own position as target: nothing moves, straight leg and soft
  // reach included.
  for (double soft : {0.0, 5.0}) {
    params.soft = soft;
    for (const Vec3& k : {knee, Vec3{0, 55, 0.2}}) {
      const TwoBoneResult same = SolveTwoBone(hip, k, ankle, ankle, params);
      EXPECT_LT(Dist(same.knee, k), 1e-9) << soft;
      EXPECT_LT(AngleBetween(same.knee_delta, Quat{}), 1e-9) << soft;
    }
  }
}

// A nearly straight leg whose target slides through its full reach: without a
// soft reach the knee races as the leg snaps straight (the knee angle's
// sensitivity to the hip-ankle distance has no bound there); with one it
// eases.
TEST(TwoBoneIkTest, SoftReachKeepsTheKneeFromRacingAtFullStretch) {
  const Vec3 hip{0, 100, 0}, knee{0, 55, 3}, ankle{0, 10, 0};
  const double reach = Dist(knee, hip) + Dist(ankle, knee);
  auto fastest_knee = [&](double soft) {
    TwoBoneParams params;
    params.soft = soft;
    double worst = 0;
    Vec3 previous = SolveTwoBone(hip, knee, ankle, {0, 100 - 0.95 * reach, 0}, params).knee;
    for (int i = 1; i <= 100; ++i) {  // Target steps of 0.001 reach.
      const Vec3 target{0, 100 - (0.95 + 0.001 * i) * reach, 0};
      const TwoBoneResult r = SolveTwoBone(hip, knee, ankle, target, params);
      EXPECT_TRUE(std::isfinite(r.knee.z));
      worst = std::max(worst, Dist(r.knee, previous) / (0.001 * reach));
      previous = r.knee;
    }
    return worst;
  };
  const double hard = fastest_knee(0), soft = fastest_knee(0.02 * reach);
  EXPECT_GT(hard, 4.0);
  EXPECT_LT(soft, 0.5 * hard);
  // From a pose and to a target both short of the soft zone, the solve is
  // exact.
  TwoBoneParams params;
  params.soft = 0.02 * reach;
  EXPECT_TRUE(SolveTwoBone(hip, {0, 55, 15}, ankle, {10, 30, 10}, params).reached);
}

// A generated root may wobble while its child turns the other way (the body
// itself still): smoothing must not put the root's wobble into the body.
TEST(PostProcessTest, SmoothingKeepsARootWobbleOutOfTheBody) {
  std::vector<Joint> joints(3);
  joints[0].name = "root";
  joints[1].name = "hips";
  joints[2].name = "head";
  joints[1].parent = 0;
  joints[2].parent = 1;
  joints[2].offset = {0, 50, 0};
  for (int j = 0; j < 3; ++j) {
    for (const char* c : {"Zrotation", "Xrotation", "Yrotation"})
      joints[j].channels.push_back(*ParseChannel(c));
  }
  Motion m = RestMotion(*Skeleton::Create(joints), 40, 1.0 / 30);
  const Quat lean = AxisAngle({1, 0, 0}, 0.3);
  for (int f = 0; f < m.num_frames; ++f) {
    LocalPose pose = PoseAt(m, f);
    pose.rotations[0] = AxisAngle({0.2, 1, 0.1}, (f % 2 ? 8.0 : -8.0) * M_PI / 180);
    pose.rotations[1] = Conjugate(pose.rotations[0]) * lean;
    std::vector<Vec3> previous(3);
    SetPose(&m, f, pose, &previous);
  }
  const double before = Jitter(m);
  SmoothRotations(&m, 2);
  const auto pos = GlobalPositions(m);
  for (int f = 1; f < m.num_frames; ++f) EXPECT_LT(Dist(pos[f][2], pos[0][2]), 1e-6) << f;
  EXPECT_LE(Jitter(m), before + 1e-6);
}

// One joint spinning 720 degrees, 5 degrees a frame, about the order's first
// axis tilted by ~12 degrees (away from gimbal lock, where even continuous
// angles must swing), written as wrapped (discontinuous) Euler angles.
Motion Spin(const std::string& order) {
  std::vector<Joint> joints(1);
  joints[0].name = "spinner";
  for (char c : order) {
    joints[0].channels.push_back(*ParseChannel(std::string(1, c) + "rotation"));
  }
  Motion m;
  m.skeleton = *Skeleton::Create(joints);
  m.num_frames = 145;
  m.values.resize(145 * 3);
  Vec3 axis{0.15, 0.15, 0.15};
  axis[m.skeleton.rotation_order(0).axes[0]] = 1;
  axis = Normalized(axis);
  for (int f = 0; f < m.num_frames; ++f) {
    const Quat q = AxisAngle(axis, f * 5.0 * M_PI / 180);
    const Vec3 e = MatToEuler(QuatToMat(q), m.skeleton.rotation_order(0));
    for (int k = 0; k < 3; ++k) m.frame(f)[k] = e[k];  // Degrees.
  }
  return m;
}

TEST(EulerContinuityTest, A720DegreeSpinHasNoJumpsInAnyOrder) {
  for (const std::string order : {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"}) {
    Motion m = Spin(order);
    const Motion original = m;
    ASSERT_GT(MaxEulerStep(m), 300.0) << order;  // The wrapped input jumps.
    MakeEulerContinuous(&m);
    EXPECT_LT(MaxEulerStep(m), 90.0) << order;
    for (int f = 0; f < m.num_frames; ++f) {
      EXPECT_LT(AngleBetween(PoseAt(m, f).rotations[0], PoseAt(original, f).rotations[0]), 1e-6)
          << order << " frame " << f;
    }
  }
}

TEST(PostProcessTest, ModeNamesParse) {
  EXPECT_EQ(*ParsePostProcessMode("full"), PostProcessMode::kFull);
  EXPECT_EQ(*ParsePostProcessMode("feet"), PostProcessMode::kFeet);
  EXPECT_EQ(*ParsePostProcessMode("none"), PostProcessMode::kNone);
  EXPECT_EQ(ParsePostProcessMode("most").status().code(), absl::StatusCode::kInvalidArgument);
}

TEST(ContactSpanTest, HysteresisKeepsOneSpanThroughJitterAndDropsBlips) {
  // A foot joint that rests, jitters just above the entry height (but below
  // the exit height), rests, lifts, and touches down for one frame.
  Motion walk = *ReadBvhFile(testing::SourceDir() + "/samples/walk_normal.bvh");
  const HumanoidRoles roles = *FindHumanoidRoles(walk.skeleton);
  const int j = FootJoints(roles)[0];
  const double leg = roles.leg_length;
  std::vector<std::vector<Vec3>> pos(60, std::vector<Vec3>(walk.skeleton.num_joints()));
  for (int f = 0; f < 60; ++f) {
    double y = 0;
    if (f >= 10 && f < 14) y = 0.06 * leg;  // Between height_on and height_off.
    if (f >= 30) y = 0.5 * leg;             // Lifted...
    if (f == 45) y = 0;                     // ...a one-frame touch.
    pos[f][j] = {0, y, 0};
  }
  const auto spans = DetectContactSpans(pos, roles, 30);
  ASSERT_EQ(spans[0].size(), 1u);
  EXPECT_EQ(spans[0][0].begin, 0);
  EXPECT_EQ(spans[0][0].end, 30);
}

TEST(PostProcessTest, SlidingFeetGetLockedKeepingFramesAndRoot) {
  const Motion content = *ReadBvhFile(testing::SourceDir() + "/samples/walk_normal.bvh");
  const HumanoidRoles roles = *FindHumanoidRoles(content.skeleton);
  // The "output": the content with its hips swaying sideways and forwards
  // (a sliding foot wherever the content's foot is planted).
  Motion output = content;
  const int hips = roles.pelvis;
  const int cx = output.skeleton.channel_start(hips);
  for (int f = 0; f < output.num_frames; ++f) {
    output.frame(f)[cx + 0] += 6 * std::sin(f * 0.21);
    output.frame(f)[cx + 2] += 4 * std::sin(f * 0.13);
  }
  const double before = FootSkating(output, content, roles);
  ASSERT_GT(before, 20.0);
  for (PostProcessMode mode : {PostProcessMode::kFeet, PostProcessMode::kFull}) {
    absl::StatusOr<Motion> fixed = PostProcess(output, content, roles, mode);
    ASSERT_TRUE(fixed.ok()) << fixed.status();
    EXPECT_EQ(fixed->num_frames, output.num_frames);
    const double after = FootSkating(*fixed, content, roles);
    EXPECT_LT(after, 0.25 * before)
        << PostProcessModeName(mode) << " " << before << " -> " << after;
    EXPECT_LT(after, 2 * FootSkating(content, content, roles) + 1.0);
    // Root and hips untouched.
    const auto a = GlobalPositions(*fixed), b = GlobalPositions(output);
    for (int f = 0; f < output.num_frames; ++f) {
      ASSERT_LT(Dist(a[f][0], b[f][0]), 1e-9);
      ASSERT_LT(Dist(a[f][hips], b[f][hips]), 1e-9);
    }
    EXPECT_LT(BoneLengthError(*fixed, roles), 1e-6);
    EXPECT_LT(MaxEulerStep(*fixed), 90.0);
  }
  EXPECT_EQ(PostProcess(output, content, roles, PostProcessMode::kNone)->values, output.values);
}

// A stream's history: frames before first_kept given with their world poses
// are final (read as neighbours, not smoothed or posed again), and the world
// poses of every frame come back for the next call.
TEST(PostProcessTest, AHistoryWithItsWorldPosesIsReadAsFinal) {
  const Motion content = *ReadBvhFile(testing::SourceDir() + "/samples/walk_normal.bvh");
  const HumanoidRoles roles = *FindHumanoidRoles(content.skeleton);
  const Skeleton& sk = content.skeleton;
  Motion output = content;
  const int cx = sk.channel_start(roles.pelvis);
  for (int f = 0; f < output.num_frames; ++f) output.frame(f)[cx + 3] += 9 * std::sin(f * 0.9);
  std::vector<LocalPose> poses;
  for (int f = 0; f < 12; ++f) poses.push_back(PoseAt(output, f));
  const auto positions = GlobalPositions(content);
  const absl::Span<const std::vector<Vec3>> span = absl::MakeConstSpan(positions).subspan(0, 12);
  // With no history, the same frames as without `posed`, and a pose per frame back.
  std::vector<GlobalPose> posed;
  auto with = PostProcessPoses(sk, roles, poses, span, content.fps(), PostProcessMode::kFull, {},
                               0, nullptr, &posed);
  auto without = PostProcessPoses(sk, roles, poses, span, content.fps(), PostProcessMode::kFull);
  ASSERT_TRUE(with.ok() && without.ok());
  ASSERT_EQ(posed.size(), 12u);
  for (int f = 0; f < 12; ++f) {
    for (int j = 0; j < sk.num_joints(); ++j) {
      EXPECT_LT(AngleBetween((*with)[f].rotations[j], (*without)[f].rotations[j]), 1e-12);
    }
  }
  // With 8 frames of history, the history is not smoothed again: the poses
  // handed back for it are the ones given.
  std::vector<GlobalPose> history(posed.begin(), posed.begin() + 8);
  history[3].positions[0] = history[3].positions[0] + Vec3{1, 2, 3};  // Marked.
  auto kept = PostProcessPoses(sk, roles, poses, span, content.fps(), PostProcessMode::kFull, {},
                               8, nullptr, &history);
  ASSERT_TRUE(kept.ok()) << kept.status();
  EXPECT_EQ(kept->size(), 4u);
  ASSERT_EQ(history.size(), 12u);
  EXPECT_LT(Dist(history[3].positions[0], posed[3].positions[0] + Vec3{1, 2, 3}), 1e-12);
  // A history of the wrong length is refused.
  std::vector<GlobalPose> short_history(posed.begin(), posed.begin() + 5);
  EXPECT_FALSE(PostProcessPoses(sk, roles, poses, span, content.fps(), PostProcessMode::kFull, {},
                                8, nullptr, &short_history)
                   .ok());
}

TEST(PostProcessTest, RestoreBoneLengthsUndoesStretchedBones) {
  Motion m = *ReadBvhFile(testing::SourceDir() + "/samples/walk_normal.bvh");
  const HumanoidRoles roles = *FindHumanoidRoles(m.skeleton);
  const int knee = m.skeleton.joint(roles.left_ankle).parent;
  const int c = m.skeleton.channel_start(knee);
  for (int f = 0; f < m.num_frames; ++f) m.frame(f)[c + 0] *= 1.2;  // Its Xposition: the bone.
  ASSERT_GT(BoneLengthError(m, roles), 1e-3);
  RestoreBoneLengths(&m, roles);
  EXPECT_LT(BoneLengthError(m, roles), 1e-9);
}

TEST(PostProcessTest, RealDataIsAlreadyCleanAndStaysPut) {
  STYLUS_REQUIRE_BANDAI(dir);
  const Motion clip = *ReadBvhFile(dir + "/dataset-1/dataset-1_walk_normal_001.bvh");
  const HumanoidRoles roles = *FindHumanoidRoles(clip.skeleton);
  EXPECT_LT(BoneLengthError(clip, roles), 1e-4);
  absl::StatusOr<Motion> fixed = PostProcess(clip, clip, roles, PostProcessMode::kFull);
  ASSERT_TRUE(fixed.ok());
  EXPECT_LE(FootSkating(*fixed, clip, roles), FootSkating(clip, clip, roles) + 1e-6);
  // Feet move onto their pins by a few centimetres (the ankle of a rolling
  // heel is not quite still); the result is no shakier than the capture by
  // more than the bound.
  const auto a = GlobalPositions(*fixed), b = GlobalPositions(clip);
  for (size_t f = 0; f < a.size(); ++f) {
    for (int j : FootJoints(roles)) ASSERT_LT(Dist(a[f][j], b[f][j]), 6.0) << "frame " << f;
  }
  EXPECT_LT(Jitter(*fixed), 1.5 * Jitter(clip));
  // Neither do the knees shake: a planted leg near full stretch is solved
  // with a soft reach about the knee's hinge, not snapped straight (a
  // snapped solve gave 2.2-2.5x the capture's knee jerk here).
  auto joint_jerk = [](const std::vector<std::vector<Vec3>>& p, int j) {
    double sum = 0;
    for (size_t f = 3; f < p.size(); ++f)
      sum += Norm(p[f][j] - p[f - 1][j] * 3.0 + p[f - 2][j] * 3.0 - p[f - 3][j]);
    return sum;
  };
  for (int ankle : {roles.left_ankle, roles.right_ankle}) {
    const int knee = clip.skeleton.joint(ankle).parent;
    EXPECT_LT(joint_jerk(a, knee), 1.25 * joint_jerk(b, knee)) << clip.skeleton.joint(knee).name;
  }
}

}  // namespace
}  // namespace stylus::motion
