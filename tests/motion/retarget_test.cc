#include "motion/retarget.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/humanoid.h"
#include "motion/kinematics.h"
#include "motion/normalization.h"
#include "motion/resample.h"
#include "tests/support/test_rigs.h"
#include "tests/test_support.h"

namespace stylus::motion {
namespace {

using testing::TestRig;

// The shipped default model's skeleton and its training data's mean pose.
std::shared_ptr<const ModelRig> DefaultModelRig() {
  const std::string dir = testing::DefaultPackageDir();
  absl::StatusOr<Motion> skeleton = ReadBvhFile(dir + "/skeleton.bvh");
  absl::StatusOr<NormStats> norm = NormStats::Load(dir + "/norm.txt");
  EXPECT_TRUE(skeleton.ok() && norm.ok());
  absl::StatusOr<HumanoidRoles> roles = FindHumanoidRoles(skeleton->skeleton);
  EXPECT_TRUE(roles.ok());
  absl::StatusOr<std::shared_ptr<const ModelRig>> rig = MakeModelRig(
      skeleton->skeleton, MeanFeatureRotations(norm->mean, skeleton->skeleton, roles->pelvis));
  EXPECT_TRUE(rig.ok()) << rig.status();
  return *rig;
}

std::string SharedRigs() { return testing::SourceDir() + "/../shared/data/rigs"; }

// Distances between the role joints of two clips on one rig: largest and mean.
struct RoleError {
  double max = 0, mean = 0;
};
RoleError RoleErrors(const Motion& a, const Motion& b, const RigRoles& roles) {
  const auto pa = GlobalPositions(a), pb = GlobalPositions(b);
  RoleError e;
  int n = 0;
  for (int f = 0; f < a.num_frames; ++f) {
    for (int j : roles.joint) {
      if (j < 0) continue;
      const double d = Norm(pa[f][j] - pb[f][j]);
      e.max = std::max(e.max, d);
      e.mean += d;
      ++n;
    }
  }
  e.mean /= std::max(n, 1);
  return e;
}
double MaxRoleError(const Motion& a, const Motion& b, const RigRoles& roles) {
  return RoleErrors(a, b, roles).max;
}

class RetargetTest : public ::testing::Test {
 protected:
  void SetUp() override {
    STYLUS_REQUIRE_BANDAI(data);
    absl::StatusOr<Motion> clip =
        ReadBvhFile(data + "/dataset-2/dataset-2_walk-turn-left_elderly_003.bvh");
    ASSERT_TRUE(clip.ok()) << clip.status();
    bandai_ = *clip;
    model_ = DefaultModelRig();
  }
  Motion bandai_;
  std::shared_ptr<const ModelRig> model_;
};

TEST_F(RetargetTest, FindsTheRolesOfEveryTestRig) {
  for (TestRig rig : testing::AllTestRigs()) {
    SCOPED_TRACE(testing::TestRigName(rig));
    absl::StatusOr<Motion> clip = testing::BuildTestRig(bandai_, rig);
    ASSERT_TRUE(clip.ok()) << clip.status();
    absl::StatusOr<std::unique_ptr<Retargeter>> r =
        Retargeter::Create(model_, clip->skeleton, clip->frame(0));
    ASSERT_TRUE(r.ok()) << r.status();
    const RigRoles& roles = (*r)->roles();
    for (int i = 0; i < kRoleCount; ++i) {
      const std::string bandai_joint = model_->skeleton.joint(model_->roles.joint[i]).name;
      std::string want = testing::TestRigJoint(rig, bandai_joint);
      if (rig == TestRig::kAnonymous || rig == TestRig::kReoriented) {
        want = clip->skeleton.joint(model_->roles.joint[i]).name;  // Same joint order.
      }
      if (want.empty()) continue;  // A role this rig spreads over joints of its own.
      ASSERT_GE(roles.joint[i], 0) << RoleName(static_cast<Role>(i));
      EXPECT_EQ(clip->skeleton.joint(roles.joint[i]).name, want)
          << RoleName(static_cast<Role>(i)) << " found by " << roles.how[i];
    }
    const bool z_up = rig == TestRig::kRigify || rig == TestRig::kUnreal;
    EXPECT_EQ(roles.up.z, z_up ? 1 : 0);
    if (rig == TestRig::kAnonymous) {
      EXPECT_EQ(roles.how[0], "hierarchy");
      EXPECT_EQ(roles.how[static_cast<int>(Role::kLeftFoot)], "geometry");
    }
  }
}

// Every test rig onto the model's skeleton gives back the Bandai clip it was
// built from: the same joint positions, up to the rig's spine and neck
// joints, which sit elsewhere than Bandai's.
TEST_F(RetargetTest, AnyRigOntoTheModelGivesTheOriginalPositions) {
  const double leg = LegLength(model_->skeleton, model_->roles);
  for (TestRig rig : testing::AllTestRigs()) {
    SCOPED_TRACE(testing::TestRigName(rig));
    absl::StatusOr<Motion> clip = testing::BuildTestRig(bandai_, rig);
    ASSERT_TRUE(clip.ok());
    std::unique_ptr<Retargeter> r = *Retargeter::Create(model_, clip->skeleton, clip->frame(0));
    const Motion on_model = r->ToModel(*clip);
    ASSERT_EQ(on_model.num_frames, clip->num_frames);
    ASSERT_TRUE(on_model.skeleton.SameTopology(model_->skeleton));
    // The original at the rig's rate (CMU's is 120 Hz).
    const Motion original = Resample(bandai_, clip->frame_time);
    const auto want = GlobalPositions(original), got = GlobalPositions(on_model);
    double limbs = 0, all = 0;
    for (int f = 0; f < clip->num_frames; ++f) {
      for (int i = 0; i < kRoleCount; ++i) {
        const int j = model_->roles.joint[i];
        const double e =
            Norm(want[f][j] - got[f][j] -
                 (want[f][model_->roles[Role::kPelvis]] - got[f][model_->roles[Role::kPelvis]]));
        all = std::max(all, e);
        const Role role = static_cast<Role>(i);
        if (role >= Role::kLeftThigh) limbs = std::max(limbs, e);
      }
    }
    // Legs are exact up to the IK's tolerance; arms and head follow the
    // chest, whose position depends on how the rig splits the spine.
    std::cout << testing::TestRigName(rig) << " onto the model: limbs " << limbs / leg << ", all "
              << all / leg << " of the leg's length\n";
    EXPECT_LT(limbs / leg, 0.01);
    EXPECT_LT(all / leg, 0.15);
    // The feet land where the rig's are (scaled), to the IK's precision.
    for (int f = 0; f < clip->num_frames; ++f) {
      for (Role foot : {Role::kLeftFoot, Role::kRightFoot}) {
        const Vec3 d = want[f][model_->roles[foot]] - got[f][model_->roles[foot]];
        ASSERT_LT(Norm(d), 1e-4 * leg) << f << " " << RoleName(foot);
      }
    }
  }
}

// Through the model's skeleton and back onto the rig: every role joint
// within 1% of the leg's length of where it was; joints without a role keep
// their input values exactly.
TEST_F(RetargetTest, RoundTripThroughTheModelKeepsPositions) {
  for (TestRig rig : testing::AllTestRigs()) {
    SCOPED_TRACE(testing::TestRigName(rig));
    absl::StatusOr<Motion> clip = testing::BuildTestRig(bandai_, rig);
    ASSERT_TRUE(clip.ok());
    std::unique_ptr<Retargeter> r = *Retargeter::Create(model_, clip->skeleton, clip->frame(0));
    const Motion on_model = r->ToModel(*clip);
    absl::StatusOr<Motion> back = r->FromModel(on_model, *clip);
    ASSERT_TRUE(back.ok()) << back.status();
    EXPECT_TRUE(back->skeleton.SameTopology(clip->skeleton));
    const double leg = LegLength(clip->skeleton, r->roles());
    const RoleError e = RoleErrors(*back, *clip, r->roles());
    std::cout << "round trip " << testing::TestRigName(rig) << ": max " << e.max / leg << ", mean "
              << e.mean / leg << " of the leg's length\n";
    EXPECT_LT(e.max / leg, 0.01);
    // Offsets are the input's, so bones keep their lengths.
    for (int j = 0; j < clip->skeleton.num_joints(); ++j) {
      const Vec3 d = back->skeleton.joint(j).offset - clip->skeleton.joint(j).offset;
      ASSERT_EQ(Norm(d), 0);
    }
  }
}

// A rig retargeted onto itself (its own skeleton as the model's, renamed so
// that nothing short-cuts) gives back exactly its input.
TEST_F(RetargetTest, OntoItsOwnRigIsTheIdentity) {
  for (TestRig rig : {TestRig::kMixamo, TestRig::kUnreal, TestRig::kCmu}) {
    SCOPED_TRACE(testing::TestRigName(rig));
    const Motion clip = *testing::BuildTestRig(bandai_, rig);
    const LocalPose first = PoseAt(clip, 0);
    absl::StatusOr<std::shared_ptr<const ModelRig>> self =
        MakeModelRig(clip.skeleton, first.rotations);
    ASSERT_TRUE(self.ok()) << self.status();
    std::unique_ptr<Retargeter> r = *Retargeter::Create(*self, clip.skeleton, clip.frame(0));
    EXPECT_NEAR(r->scale(), 1, 1e-12);
    const Motion on_self = r->ToModel(clip);
    const double leg = LegLength(clip.skeleton, r->roles());
    EXPECT_LT(MaxRoleError(on_self, clip, r->roles()) / leg, 1e-6);
    const Motion back = *r->FromModel(on_self, clip);
    double worst = 0;
    for (size_t i = 0; i < clip.values.size(); ++i) {
      worst = std::max(worst, std::fabs(back.values[i] - clip.values[i]));
    }
    EXPECT_LT(worst, 1e-6);
  }
}

TEST_F(RetargetTest, SharedRealRigsAreMapped) {
  if (!std::filesystem::exists(SharedRigs())) {
    if (testing::UnderCi()) FAIL() << SharedRigs() << " missing (required under CI)";
    GTEST_SKIP() << SharedRigs() << " missing; skipping";
  }
  struct Case {
    const char* file;
    std::vector<std::pair<Role, std::string>> want;
    bool toe_end_site;
  };
  const Case cases[] = {
      {"mixamo_55joints_30fps.bvh",
       {{Role::kPelvis, "mixamorig:Hips"},
        {Role::kChest, "mixamorig:Spine2"},
        {Role::kLeftClavicle, "mixamorig:LeftShoulder"},
        {Role::kLeftUpperArm, "mixamorig:LeftArm"},
        {Role::kRightHand, "mixamorig:RightHand"},
        {Role::kLeftShin, "mixamorig:LeftLeg"},
        {Role::kLeftToe, "mixamorig:LeftToeBase"},
        {Role::kHead, "mixamorig:Head"}},
       false},
      {"mocapbank_19joints_30fps.bvh",
       {{Role::kPelvis, "Hips"},
        {Role::kSpine, "Chest"},
        {Role::kChest, "Chest2"},
        {Role::kLeftClavicle, "LeftCollar"},
        {Role::kLeftUpperArm, "LeftShoulder"},
        {Role::kLeftForearm, "LeftElbow"},
        {Role::kRightHand, "RightWrist"},
        {Role::kLeftThigh, "LeftHip"},
        {Role::kRightFoot, "RightAnkle"}},
       true},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.file);
    absl::StatusOr<Motion> clip = ReadBvhFile(SharedRigs() + "/" + c.file);
    ASSERT_TRUE(clip.ok()) << clip.status();
    absl::StatusOr<std::unique_ptr<Retargeter>> r =
        Retargeter::Create(model_, clip->skeleton, clip->frame(0));
    ASSERT_TRUE(r.ok()) << r.status();
    for (const auto& [role, name] : c.want) {
      ASSERT_TRUE((*r)->roles().has(role)) << RoleName(role);
      EXPECT_EQ(clip->skeleton.joint((*r)->roles()[role]).name, name) << RoleName(role);
    }
    EXPECT_EQ((*r)->roles().toe_is_end_site[0], c.toe_end_site);
    const Motion on_model = (*r)->ToModel(*clip);
    absl::StatusOr<Motion> back = (*r)->FromModel(on_model, *clip);
    ASSERT_TRUE(back.ok());
    // Exact but where a leg is stretched straight on this rig and cannot be
    // on the model's (hip joints placed wider or lower than the model's).
    const double leg = LegLength(clip->skeleton, (*r)->roles());
    const RoleError e = RoleErrors(*back, *clip, (*r)->roles());
    std::cout << "round trip " << c.file << ": max " << e.max / leg << ", mean " << e.mean / leg
              << " of the leg's length\n";
    EXPECT_LT(e.max / leg, 0.07);
    EXPECT_LT(e.mean / leg, 0.01);
  }
}

// Rounding-level changes of a frame move the model's joints by as little:
// also on mocapbank's rig, whose two clavicles share one place (the chest's
// turn is then read from the upper arms; it was left to rounding, and 1e-4
// on the root's x turned the arms by 8 cm).
TEST_F(RetargetTest, SmallChangesOfAFrameMoveTheModelLittle) {
  if (!std::filesystem::exists(SharedRigs())) {
    if (testing::UnderCi()) FAIL() << SharedRigs() << " missing (required under CI)";
    GTEST_SKIP() << SharedRigs() << " missing";
  }
  for (const char* file : {"mocapbank_19joints_30fps.bvh", "mixamo_55joints_30fps.bvh"}) {
    SCOPED_TRACE(file);
    absl::StatusOr<Motion> clip = ReadBvhFile(SharedRigs() + "/" + file);
    ASSERT_TRUE(clip.ok()) << clip.status();
    std::unique_ptr<Retargeter> r = *Retargeter::Create(model_, clip->skeleton, clip->frame(0));
    const Skeleton& msk = model_->skeleton;
    Motion a = RestMotion(msk, 1, clip->frame_time), b = a;
    double worst = 0;
    for (int f = 0; f < clip->num_frames; f += 7) {
      for (int c = 0; c < clip->skeleton.num_channels(); c += 5) {
        std::vector<double> frame(clip->frame(f), clip->frame(f) + clip->skeleton.num_channels());
        r->Reset();
        r->ToModel(frame.data(), a.frame(0));
        frame[c] += 1e-4;
        r->Reset();
        r->ToModel(frame.data(), b.frame(0));
        worst = std::max(worst, MaxPositionDifference(a, b));
      }
    }
    std::printf("%s: 1e-4 on one channel moves the model's joints by at most %.2e\n", file, worst);
    EXPECT_LT(worst, 1e-2);
  }
}

TEST_F(RetargetTest, JointMapOverridesAndNamesItsErrors) {
  const Motion clip = *testing::BuildTestRig(bandai_, TestRig::kAnonymous);
  // The limb ends given by hand: the geometry fallback is then not needed.
  auto name = [&](Role r) { return clip.skeleton.joint(model_->roles[r]).name; };
  absl::StatusOr<JointMap> map =
      ParseJointMap(absl::StrCat("# hands and feet\nleft_hand = ", name(Role::kLeftHand),
                                 "\nright-hand=", name(Role::kRightHand),
                                 "\n LEFT_FOOT = ", name(Role::kLeftFoot),
                                 "\nright_foot = ", name(Role::kRightFoot), "\n"),
                    "map.txt");
  ASSERT_TRUE(map.ok()) << map.status();
  absl::StatusOr<std::unique_ptr<Retargeter>> r =
      Retargeter::Create(model_, clip.skeleton, clip.frame(0), *map);
  ASSERT_TRUE(r.ok()) << r.status();
  for (int i = 0; i < kRoleCount; ++i) {
    EXPECT_EQ((*r)->roles().joint[i], model_->roles.joint[i]) << RoleName(static_cast<Role>(i));
    EXPECT_NE((*r)->roles().how[i], "geometry");
  }
  EXPECT_EQ((*r)->roles().how[static_cast<int>(Role::kLeftHand)], "joint map");
  EXPECT_EQ((*r)->roles().how[static_cast<int>(Role::kLeftShin)], "hierarchy");

  EXPECT_EQ(ParseJointMap("left_foot LeftFoot\n", "m.txt").status().message(),
            "m.txt:1: expected 'role = joint name' (e.g. left_foot = LeftFoot)");
  EXPECT_TRUE(absl::StrContains(ParseJointMap("\nleft_paw = X\n", "m.txt").status().message(),
                                "m.txt:2: unknown role 'left_paw'"));
  EXPECT_TRUE(absl::StrContains(
      ParseJointMap("pelvis = A\npelvis = B\n", "m.txt").status().message(), "given twice"));
  absl::StatusOr<std::unique_ptr<Retargeter>> bad =
      Retargeter::Create(model_, clip.skeleton, clip.frame(0), {{Role::kPelvis, "nope"}});
  EXPECT_EQ(bad.status().message(), "joint map: pelvis = 'nope': the skeleton has no such joint");
}

// A skeleton without legs is no biped: the error names what is missing.
TEST_F(RetargetTest, RigWithoutLegsIsRefusedNamingTheRoles) {
  const Motion legless = testing::WithoutLegs(bandai_);
  absl::StatusOr<std::unique_ptr<Retargeter>> r =
      Retargeter::Create(model_, legless.skeleton, legless.frame(0));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), absl::StatusCode::kInvalidArgument);
  EXPECT_TRUE(absl::StrContains(r.status().message(), "left_thigh, left_shin, left_foot"))
      << r.status();
}

}  // namespace
}  // namespace stylus::motion
