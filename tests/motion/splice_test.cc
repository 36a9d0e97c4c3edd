// Body parts and splicing, on the shipped sample clips (Bandai's skeleton).
#include "motion/splice.h"

#include <cmath>
#include <set>
#include <string>

#include "absl/strings/str_cat.h"
#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/kinematics.h"

namespace stylus::motion {
namespace {

Motion Sample(const std::string& name) {
  return *ReadBvhFile(std::string(STYLUS_SOURCE_DIR) + "/samples/" + name + ".bvh");
}

std::set<std::string> Names(const Skeleton& s, const std::vector<int>& joints) {
  std::set<std::string> names;
  for (int j : joints) names.insert(s.joint(j).name);
  return names;
}

TEST(SpliceTest, BodyPartsOfTheBandaiRigAreDisjointAndLeaveThePath) {
  const Motion walk = Sample("walk_normal");
  const HumanoidRoles roles = *FindHumanoidRoles(walk.skeleton);
  const Skeleton& s = walk.skeleton;
  EXPECT_EQ(Names(s, BodyPartJoints(s, roles, BodyPart::kTorso)),
            (std::set<std::string>{"Spine", "Chest", "Neck", "Head"}));
  EXPECT_EQ(Names(s, BodyPartJoints(s, roles, BodyPart::kLeftArm)),
            (std::set<std::string>{"Shoulder_L", "UpperArm_L", "LowerArm_L", "Hand_L"}));
  EXPECT_EQ(Names(s, BodyPartJoints(s, roles, BodyPart::kRightArm)),
            (std::set<std::string>{"Shoulder_R", "UpperArm_R", "LowerArm_R", "Hand_R"}));
  EXPECT_EQ(Names(s, BodyPartJoints(s, roles, BodyPart::kLegs)),
            (std::set<std::string>{"UpperLeg_L", "LowerLeg_L", "Foot_L", "Toes_L", "UpperLeg_R",
                                   "LowerLeg_R", "Foot_R", "Toes_R"}));
  for (BodyPart p : kBodyParts) EXPECT_EQ(*ParseBodyPart(BodyPartName(p)), p);
  const absl::Status bad = ParseBodyPart("tail").status();
  EXPECT_NE(bad.message().find("unknown body part 'tail' (legs, torso"), std::string::npos) << bad;
}

TEST(SpliceTest, SplicedLegsFollowTheDonorAndTheRestTheBase) {
  const Motion base = Sample("walk_normal"), donor = Sample("walk_old");
  ASSERT_GE(donor.num_frames, base.num_frames);
  const HumanoidRoles roles = *FindHumanoidRoles(base.skeleton);
  const std::vector<int> legs = BodyPartJoints(base.skeleton, roles, BodyPart::kLegs);
  absl::StatusOr<Motion> out = SpliceJoints(base, donor, legs);
  ASSERT_TRUE(out.ok()) << out.status();
  ASSERT_EQ(out->num_frames, base.num_frames);
  const Skeleton& s = base.skeleton;
  std::set<int> leg_set(legs.begin(), legs.end());
  double leg_change = 0;
  for (int f = 0; f < base.num_frames; ++f) {
    for (int j = 0; j < s.num_joints(); ++j) {
      const Motion& want = leg_set.count(j) ? donor : base;
      for (size_t c = 0; c < s.joint(j).channels.size(); ++c) {
        const int k = s.channel_start(j) + static_cast<int>(c);
        ASSERT_EQ(out->frame(f)[k], want.frame(f)[k]) << s.joint(j).name << " frame " << f;
        if (leg_set.count(j)) leg_change += std::abs(donor.frame(f)[k] - base.frame(f)[k]);
      }
    }
  }
  EXPECT_GT(leg_change, 1.0);  // The two walks' legs differ, so the splice did something.
  // The arms hang from the base's pelvis and spine: their world positions stay.
  const auto before = GlobalPositions(base), after = GlobalPositions(*out);
  const int hand = *s.Find("Hand_L"), toe = *s.Find("Toes_L");
  double toe_moved = 0;
  for (int f = 0; f < base.num_frames; ++f) {
    EXPECT_NEAR(after[f][hand].x, before[f][hand].x, 1e-9);
    EXPECT_NEAR(after[f][hand].y, before[f][hand].y, 1e-9);
    toe_moved = std::max(toe_moved, std::abs(after[f][toe].y - before[f][toe].y));
  }
  EXPECT_GT(toe_moved, 0.1);
}

TEST(SpliceTest, ShortDonorsAndOtherSkeletonsAreRefusedByName) {
  const Motion base = Sample("walk_normal");
  Motion short_donor = base;
  short_donor.num_frames = base.num_frames - 1;
  short_donor.values.resize(static_cast<size_t>(short_donor.num_frames) *
                            base.skeleton.num_channels());
  absl::Status s = SpliceJoints(base, short_donor, {1}, "a.bvh", "b.bvh").status();
  EXPECT_EQ(s.code(), absl::StatusCode::kInvalidArgument);
  EXPECT_NE(
      s.message().find(absl::StrCat("b.bvh has ", base.num_frames - 1, " frames, fewer than the ",
                                    base.num_frames, " of a.bvh")),
      std::string::npos)
      << s;
  const Motion other =
      *ReadBvhFile(std::string(STYLUS_SOURCE_DIR) + "/tests/fixtures/bvh/good/three_joint.bvh");
  s = SpliceJoints(base, other, {1}, "a.bvh", "c.bvh").status();
  EXPECT_NE(s.message().find("c.bvh is on another skeleton than a.bvh"), std::string::npos) << s;
}

}  // namespace
}  // namespace stylus::motion
