#include "motion/synth.h"

#include <cmath>

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/contacts.h"
#include "motion/humanoid.h"
#include "motion/kinematics.h"

namespace stylus::motion {
namespace {

TEST(SynthTest, BandaiSkeletonMatchesTheDatasetLayout) {
  const Skeleton sk = BandaiSkeleton();
  EXPECT_EQ(sk.num_joints(), 22);  // joint_Root + the 21 joints of methods.md.
  EXPECT_EQ(sk.num_channels(), 132);
  EXPECT_EQ(sk.joint(1).name, "Hips");
  EXPECT_EQ(sk.rotation_order(5).Name(), "ZXY");
  EXPECT_TRUE(FindHumanoidRoles(sk).ok());
}

TEST(SynthTest, StanceFeetStayPlantedAndBonesKeepTheirLength) {
  for (const char* style : {"normal", "old", "run", "proud,turn=45"}) {
    SCOPED_TRACE(style);
    absl::StatusOr<Motion> m = Synthesize(*ParseSynthStyle(style));
    ASSERT_TRUE(m.ok()) << m.status();
    const HumanoidRoles roles = *FindHumanoidRoles(m->skeleton);
    const auto pos = GlobalPositions(*m);
    const auto contacts = DetectFootContacts(pos, roles, m->fps());
    const auto feet = FootJoints(roles);
    int contact_frames = 0;
    double slide = 0;
    for (size_t f = 1; f < pos.size(); ++f) {
      for (int k = 1; k < 4; k += 2) {  // Toes: planted through the whole stance.
        if (!contacts[f][k] || !contacts[f - 1][k]) continue;
        const Vec3 d = pos[f][feet[k]] - pos[f - 1][feet[k]];
        slide += std::hypot(d.x, d.z) * m->fps();
        ++contact_frames;
      }
    }
    ASSERT_GT(contact_frames, 20);
    EXPECT_LT(slide / contact_frames, 5.0);  // cm/s while planted.
    // Bone lengths equal the skeleton's offsets in every frame.
    for (size_t f = 0; f < pos.size(); f += 10) {
      for (int j = 2; j < m->skeleton.num_joints(); ++j) {
        const int p = m->skeleton.joint(j).parent;
        EXPECT_NEAR(Norm(pos[f][j] - pos[f][p]), Norm(m->skeleton.joint(j).offset), 1e-6);
      }
    }
  }
}

TEST(SynthTest, KnobsChangeTheMotion) {
  auto mean_speed_and_height = [](const std::string& style) {
    const Motion m = *Synthesize(*ParseSynthStyle(style));
    const HumanoidRoles roles = *FindHumanoidRoles(m.skeleton);
    const auto pos = GlobalPositions(m);
    const Vec3 d = pos.back()[roles.pelvis] - pos.front()[roles.pelvis];
    double stoop = 0;  // Head ahead of the pelvis (the walk heads along +Z).
    for (const auto& p : pos) stoop += p[5].z - p[roles.pelvis].z;
    return std::pair{std::hypot(d.x, d.z) / ((m.num_frames - 1) * m.frame_time),
                     stoop / pos.size()};
  };
  const auto normal = mean_speed_and_height("normal");
  const auto old = mean_speed_and_height("old");
  const auto fast = mean_speed_and_height("normal,speed=200,stride=170");
  EXPECT_NEAR(normal.first, 130, 5);
  EXPECT_NEAR(fast.first, 200, 8);
  EXPECT_LT(old.first, 80);
  EXPECT_GT(old.second, normal.second + 4);  // Stooped: the head leads.
}

TEST(SynthTest, StyleParsingErrors) {
  EXPECT_FALSE(ParseSynthStyle("bogus").ok());
  EXPECT_FALSE(ParseSynthStyle("speed=fast").ok());
  EXPECT_FALSE(ParseSynthStyle("wings=2").ok());
  EXPECT_FALSE(ParseSynthStyle("gait=hop").ok());
  EXPECT_TRUE(ParseSynthStyle("run,speed=400,frames=10")->run);
  EXPECT_FALSE(Synthesize(*ParseSynthStyle("speed=0")).ok());
  EXPECT_FALSE(Synthesize(*ParseSynthStyle("frames=-3")).ok());
}

TEST(SynthTest, OutputIsValidBvh) {
  const Motion m = *Synthesize(*ParseSynthStyle("happy,frames=60"));
  absl::StatusOr<Motion> back = ParseBvh(FormatBvh(m), "synth");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->num_frames, 60);
  EXPECT_LT(MaxPositionDifference(m, *back), 1e-6);
}

}  // namespace
}  // namespace stylus::motion
