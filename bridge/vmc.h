// The VMC protocol's humanoid (OSC over UDP; protocol.vmc.info): Unity's
// HumanBodyBones names and hierarchy, and a performer's frames as Stylus
// motions. Unity is left-handed, Y up; Stylus right-handed, Y up: x is
// mirrored on the way in and out (positions (-x, y, z), rotations
// (x, -y, -z, w)), so a round trip is exact.
#ifndef STYLUS_BRIDGE_VMC_H_
#define STYLUS_BRIDGE_VMC_H_

#include <map>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/motion.h"

namespace stylus::bridge {

// One VMC transform: a local position and rotation, converted to Stylus's
// right-handed axes.
struct VmcTransform {
  motion::Vec3 position;
  motion::Quat rotation;
};

// What a performer sent for one frame: the avatar's root (/VMC/Ext/Root/Pos)
// and its bones (/VMC/Ext/Bone/Pos) by Unity name.
struct VmcFrame {
  VmcTransform root;
  std::map<std::string, VmcTransform> bones;
  double time = 0;  // /VMC/Ext/T, when sent.
};

// Converts between Unity's left-handed axes and Stylus's.
VmcTransform FromUnity(const float p[3], const float q[4]);
void ToUnity(const VmcTransform& t, float p[3], float q[4]);

// The Unity humanoid parent of `bone` ("" for Hips or an unknown name).
std::string UnityParent(const std::string& bone);
// True for a HumanBodyBones name.
bool IsUnityBone(const std::string& bone);

// A performer's skeleton, read from its first frame: the humanoid bones it
// sent (parents first, rooted at Hips; a missing optional bone such as
// UpperChest is skipped over), offsets from their local positions. Frames
// convert to and from rows of a Motion on it: Hips carries its world
// position (root transform applied) and rotation, every other joint its
// local rotation.
class VmcSkeleton {
 public:
  // INVALID_ARGUMENT when the frame has no Hips or no legs and arms to
  // retarget (the message names what is missing).
  static absl::StatusOr<VmcSkeleton> FromFrame(const VmcFrame& frame);

  const motion::Skeleton& skeleton() const { return skeleton_; }
  // The frame's values (skeleton().num_channels()), bones it lacks at rest.
  std::vector<double> Row(const VmcFrame& frame) const;
  // The VMC frame of `row`, with `root` as the avatar's root transform and
  // each bone's local position as the skeleton's offset.
  VmcFrame FrameOf(const double* row, const VmcTransform& root) const;

 private:
  motion::Skeleton skeleton_;
};

}  // namespace stylus::bridge

#endif  // STYLUS_BRIDGE_VMC_H_
