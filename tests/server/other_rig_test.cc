// Clips on other humanoid rigs than the model's through a real server on
// localhost: Transfer, Interpolate and TransferStream take them and give the
// output back on the input's rig (same joints, offsets, channels), feet
// planted; joint maps travel with the skeleton; a rig that is no biped is
// refused naming what it lacks.
#include <cmath>
#include <filesystem>
#include <iostream>

#include "absl/strings/match.h"
#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/humanoid.h"
#include "motion/kinematics.h"
#include "motion/metrics.h"
#include "motion/resample.h"
#include "motion/rig_roles.h"
#include "tests/server/server_test_support.h"
#include "tests/support/test_rigs.h"

namespace stylus {
namespace {

using testing::LiveServer;
using testing::TestRig;

CallOptions Full(const std::string& model = "") {
  CallOptions o;
  o.model = model;
  o.postprocess = v1::POSTPROCESS_FULL;
  return o;
}

// Joints of `out` without a humanoid role keep the channel values of `in`.
void ExpectSameRig(const motion::Motion& out, const motion::Motion& in) {
  ASSERT_TRUE(out.skeleton.SameTopology(in.skeleton)) << out.skeleton.DescribeMismatch(in.skeleton);
  ASSERT_EQ(out.num_frames, in.num_frames);
  EXPECT_NEAR(out.frame_time, in.frame_time, 1e-9);
  for (int j = 0; j < in.skeleton.num_joints(); ++j) {
    const motion::Vec3 d = out.skeleton.joint(j).offset - in.skeleton.joint(j).offset;
    ASSERT_LT(motion::Norm(d), 1e-9) << in.skeleton.joint(j).name;
  }
}

double MeanDisplacement(const motion::Motion& a, const motion::Motion& b) {
  const auto pa = motion::GlobalPositions(a), pb = motion::GlobalPositions(b);
  double sum = 0;
  int n = 0;
  for (size_t f = 0; f < pa.size(); ++f) {
    for (size_t j = 0; j < pa[f].size(); ++j, ++n) sum += motion::Norm(pa[f][j] - pb[f][j]);
  }
  return sum / std::max(n, 1);
}

class OtherRigServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    STYLUS_REQUIRE_BANDAI(data);
    const std::string d2 = data + "/dataset-2/dataset-2_";
    content_ = *motion::ReadBvhFile(d2 + "walk_normal_004.bvh");
    style_ = *motion::ReadBvhFile(d2 + "walk_elderly_002.bvh");
    server_ = LiveServer::Start();
    ASSERT_NE(server_, nullptr);
  }
  motion::Motion content_, style_;
  std::unique_ptr<LiveServer> server_;
};

// The must-show case: a CMU-rig clip and a Mixamo-named clip transferred
// through the server, output on the input's rig, feet as planted as the same
// transfer on the model's own rig.
TEST_F(OtherRigServerTest, TransferOnCmuAndMixamoRigsComesBackOnTheirRig) {
  const motion::HumanoidRoles bandai_roles = *motion::FindHumanoidRoles(content_.skeleton);
  for (TestRig rig : {TestRig::kCmu, TestRig::kMixamo, TestRig::kUnreal}) {
    SCOPED_TRACE(testing::TestRigName(rig));
    const motion::Motion clip = *testing::BuildTestRig(content_, rig);
    absl::StatusOr<motion::Motion> out = server_->client->Transfer(clip, {&style_, ""}, Full());
    ASSERT_TRUE(out.ok()) << out.status();
    ExpectSameRig(*out, clip);
    // The style changed the motion...
    const double units = rig == TestRig::kCmu ? 2.54 : 1;  // CMU's rig is in inches.
    EXPECT_GT(units * MeanDisplacement(*out, clip), 1.0);
    // ...but not the joints without a role (fingers, twist bones, props).
    for (const char* extra :
         {"LeftFingerBase", "mixamorig:LeftHandIndex1", "upperarm_twist_01_l", "weapon_r"}) {
      const std::optional<int> j = clip.skeleton.Find(extra);
      if (!j) continue;
      const int at = clip.skeleton.channel_start(*j);
      for (int f = 0; f < clip.num_frames; ++f) {
        for (int c = 0; c < 3; ++c) {  // Degrees; the wire carries quaternions.
          ASSERT_NEAR(out->frame(f)[at + c], clip.frame(f)[at + c], 1e-6);
        }
      }
    }
    // Feet: skating (cm/s while planted) within 1.2x the model rig's.
    absl::StatusOr<motion::HumanoidRoles> roles = motion::HumanoidRolesOf(clip);
    ASSERT_TRUE(roles.ok()) << roles.status();
    EXPECT_LT(motion::BoneLengthError(*out, *roles), 1e-9);
    if (roles->up_axis != 1) continue;  // The metric reads Y as up.
    // The same transfer on the model's own rig at the rig's frame rate.
    const motion::Motion at_rate = motion::Resample(content_, clip.frame_time);
    absl::StatusOr<motion::Motion> own = server_->client->Transfer(at_rate, {&style_, ""}, Full());
    ASSERT_TRUE(own.ok()) << own.status();
    const double own_skating = motion::FootSkating(*own, at_rate, bandai_roles);
    const double skating = units * motion::FootSkating(*out, clip, *roles);
    std::cout << testing::TestRigName(rig) << ": foot skating " << skating
              << " cm/s; on the model's rig " << own_skating << " cm/s\n";
    EXPECT_LE(skating, 1.2 * own_skating + 0.5);
  }
}

TEST_F(OtherRigServerTest, RealMixamoAndMocapbankFilesAreTransferred) {
  const std::string rigs = testing::SourceDir() + "/../shared/data/rigs";
  if (!std::filesystem::exists(rigs)) {
    if (testing::UnderCi()) FAIL() << rigs << " missing (required under CI)";
    GTEST_SKIP() << rigs << " missing; skipping";
  }
  for (const char* file : {"mixamo_55joints_30fps.bvh", "mocapbank_19joints_30fps.bvh"}) {
    SCOPED_TRACE(file);
    const motion::Motion clip = *motion::ReadBvhFile(rigs + "/" + file);
    absl::StatusOr<motion::Motion> out = server_->client->Transfer(clip, {&style_, ""}, Full());
    ASSERT_TRUE(out.ok()) << out.status();
    ExpectSameRig(*out, clip);
    EXPECT_GT(MeanDisplacement(*out, clip), 1.0);
  }
}

TEST_F(OtherRigServerTest, InterpolateAndStreamsOnAnotherRig) {
  const motion::Motion clip = *testing::BuildTestRig(content_, TestRig::kMixamo);
  const motion::Motion style2 = *testing::BuildTestRig(style_, TestRig::kMixamo);
  // Two styles, one of them on the content's rig.
  absl::StatusOr<motion::Motion> blend =
      server_->client->Interpolate(clip, {{&style_, ""}, {&style2, ""}}, {0.5, 0.5}, {}, Full());
  ASSERT_TRUE(blend.ok()) << blend.status();
  ExpectSameRig(*blend, clip);
  // A live stream: frames back one to one, in order, on the rig.
  absl::StatusOr<StreamResult> live = server_->client->Stream(clip, {&style_, ""}, 0, Full("live"));
  ASSERT_TRUE(live.ok()) << live.status();
  ExpectSameRig(live->output, clip);
  for (size_t i = 0; i < live->indices.size(); ++i) {
    ASSERT_EQ(live->indices[i], static_cast<int64_t>(i));
  }
  // An offline model's stream too, at 120 Hz on the CMU rig.
  const motion::Motion cmu = *testing::BuildTestRig(content_, TestRig::kCmu);
  absl::StatusOr<StreamResult> offline = server_->client->Stream(cmu, {&style_, ""}, 0, Full());
  ASSERT_TRUE(offline.ok()) << offline.status();
  ExpectSameRig(offline->output, cmu);
}

TEST_F(OtherRigServerTest, JointMapsTravelWithTheSkeleton) {
  const motion::Motion clip = *testing::BuildTestRig(content_, TestRig::kAnonymous);
  CallOptions options = Full();
  // The anonymous rig's limb ends (Bandai's joint order: j09 is Hand_L).
  options.joint_map = {{motion::Role::kLeftHand, "j09"},
                       {motion::Role::kRightHand, "j13"},
                       {motion::Role::kLeftFoot, "j16"},
                       {motion::Role::kRightFoot, "j20"}};
  absl::StatusOr<motion::Motion> out = server_->client->Transfer(clip, {&style_, ""}, options);
  ASSERT_TRUE(out.ok()) << out.status();
  ExpectSameRig(*out, clip);
  options.joint_map = {{motion::Role::kLeftFoot, "no_such_joint"}};
  out = server_->client->Transfer(clip, {&style_, ""}, options);
  ASSERT_FALSE(out.ok());
  EXPECT_EQ(out.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(absl::StrContains(out.status().message(), "left_foot = 'no_such_joint'"))
      << out.status();
}

TEST_F(OtherRigServerTest, ARigWithoutLegsIsRefusedNamingTheRoles) {
  const motion::Motion legless = testing::WithoutLegs(content_);
  absl::StatusOr<motion::Motion> out = server_->client->Transfer(legless, {&style_, ""}, Full());
  ASSERT_FALSE(out.ok());
  EXPECT_EQ(out.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(absl::StrContains(out.status().message(), "left_thigh, left_shin, left_foot"))
      << out.status();
  EXPECT_TRUE(absl::StrContains(out.status().message(), "content clip")) << out.status();
}

}  // namespace
}  // namespace stylus
