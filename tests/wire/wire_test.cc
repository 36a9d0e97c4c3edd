// wire/: stylus.v1 messages <-> motion types.
#include "wire/wire.h"

#include "gtest/gtest.h"
#include "motion/bvh.h"
#include "motion/kinematics.h"
#include "tests/test_support.h"

namespace stylus {
namespace {

motion::Motion Sample(const std::string& name) {
  return *motion::ReadBvhFile(testing::SourceDir() + "/samples/" + name);
}

TEST(WireTest, ClipRoundTripKeepsEveryJointPosition) {
  const motion::Motion clip = Sample("walk_old.bvh");
  v1::Clip proto;
  wire::ClipToProto(clip, &proto);
  absl::StatusOr<motion::Motion> back = wire::ClipFromProto(proto, "clip");
  ASSERT_TRUE(back.ok()) << back.status();
  EXPECT_EQ(back->num_frames, clip.num_frames);
  EXPECT_LT(motion::MaxPositionDifference(*back, clip), 1e-9);
}

}  // namespace
}  // namespace stylus
