#include "motion/kinematics.h"

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "tests/test_support.h"

namespace stylus::motion {
namespace {

void ExpectVecNear(const Vec3& a, const Vec3& b, double tol = 1e-9) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// Hips at (0,20,0); Knee 10 below; Ankle 10 below the knee; End Site 5 ahead.
TEST(KinematicsTest, ThreeJointChainHasKnownPositions) {
  absl::StatusOr<Motion> m = ReadBvhFile(testing::FixturePath("bvh/good/three_joint.bvh"));
  ASSERT_TRUE(m.ok()) << m.status();
  ASSERT_EQ(m->num_frames, 2);
  // Frame 0: rest.
  GlobalPose g = ForwardKinematics(m->skeleton, PoseAt(*m, 0));
  ExpectVecNear(g.positions[0], {0, 20, 0});
  ExpectVecNear(g.positions[1], {0, 10, 0});
  ExpectVecNear(g.positions[2], {0, 0, 0});
  // Frame 1: root moved to (1,20,2) and turned 90 deg about Z (down becomes +X);
  // the knee bends a further 90 deg about X.
  g = ForwardKinematics(m->skeleton, PoseAt(*m, 1));
  ExpectVecNear(g.positions[0], {1, 20, 2});
  ExpectVecNear(g.positions[1], {11, 20, 2});  // Rz(90) (0,-10,0) = (10,0,0).
  // Knee frame = Rz(90) Rx(90): its (0,-10,0) goes to Rz(90) (0,0,-10) = (0,0,-10).
  ExpectVecNear(g.positions[2], {11, 20, -8});
}

TEST(KinematicsTest, LocalFromGlobalInvertsForwardKinematics) {
  absl::StatusOr<Motion> m = ReadBvhFile(testing::FixturePath("bvh/good/mixed_orders_crlf.bvh"));
  ASSERT_TRUE(m.ok()) << m.status();
  for (int f = 0; f < m->num_frames; ++f) {
    const LocalPose local = PoseAt(*m, f);
    const LocalPose back = LocalFromGlobal(m->skeleton, ForwardKinematics(m->skeleton, local));
    for (int j = 0; j < m->skeleton.num_joints(); ++j) {
      ExpectVecNear(back.translations[j], local.translations[j]);
      EXPECT_NEAR(AngleBetween(back.rotations[j], local.rotations[j]), 0, 1e-6);
    }
  }
}

}  // namespace
}  // namespace stylus::motion
