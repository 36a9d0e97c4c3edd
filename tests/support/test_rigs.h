// Other rigs for tests, built from a clip on the Bandai skeleton: the same
// world motion on skeletons with other joint names, counts and hierarchy
// order, rest poses, joint frames, units, up axes and Euler orders, as
// exported by other tools. Retargeting tests read them as a studio's rigs.
#ifndef STYLUS_TESTS_SUPPORT_TEST_RIGS_H_
#define STYLUS_TESTS_SUPPORT_TEST_RIGS_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/motion.h"

namespace stylus::testing {

enum class TestRig {
  kCmu,           // CMU names, zero-length hip and back joints, two neck joints, fingers, 120 Hz.
  kMixamo,        // "mixamorig:" names, three spine joints, fingers, end joints, ZYX Euler.
  kMixamoMetres,  // kMixamo in metres.
  kRigify,        // Blender Rigify names (thigh.L, spine.003), Z-up, metres, XYZ Euler.
  kUnreal,        // Unreal names (thigh_l, calf_l, ball_l), Z-up, a floor root, twist bones,
                  // a prop, legs listed before the spine, YZX Euler.
  kAnonymous,     // Joints named j00, j01...: only hierarchy and geometry tell the roles.
  kReoriented,    // Bandai's names, every joint frame turned by a fixed random rotation.
};

std::string TestRigName(TestRig rig);
std::vector<TestRig> AllTestRigs();

// The world motion of `bandai` (a clip on the Bandai skeleton) on `rig`.
absl::StatusOr<motion::Motion> BuildTestRig(const motion::Motion& bandai, TestRig rig);

// `bandai` with its legs cut off (no UpperLeg, LowerLeg, Foot, Toes joints):
// a rig that is no biped, which retargeting must refuse.
motion::Motion WithoutLegs(const motion::Motion& bandai);

// The name of the joint of `rig` that stands for Bandai joint `bandai_name`
// ("" when none does).
std::string TestRigJoint(TestRig rig, const std::string& bandai_name);

}  // namespace stylus::testing

#endif  // STYLUS_TESTS_SUPPORT_TEST_RIGS_H_
