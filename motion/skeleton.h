// Skeleton: the joint hierarchy of a motion clip, as a BVH HIERARCHY describes it.
//
// Joints are stored in depth-first file order, so a joint's parent always has a
// smaller index than the joint itself (index 0 is the root). A Skeleton is an
// immutable value once created: its copies share one set of joints (a copy
// costs a reference count, so a clip or a streamed frame carries its skeleton
// at no cost), and all const methods are thread-safe.
#ifndef STYLUS_MOTION_SKELETON_H_
#define STYLUS_MOTION_SKELETON_H_

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"
#include "motion/rotation.h"

namespace stylus::motion {

enum class Channel { kXposition, kYposition, kZposition, kXrotation, kYrotation, kZrotation };

// "Xposition" ... "Zrotation" (BVH spelling).
absl::string_view ChannelName(Channel c);
// Case-insensitive inverse of ChannelName; nullopt for anything else.
std::optional<Channel> ParseChannel(absl::string_view name);
inline bool IsPosition(Channel c) { return c <= Channel::kZposition; }
// 0, 1, 2 for the X, Y, Z axis of a position or rotation channel.
inline int ChannelAxis(Channel c) { return static_cast<int>(c) % 3; }

struct Joint;
// True when the joint has any position channel (its translation is animated).
bool HasPositionChannel(const Joint& joint);

struct Joint {
  std::string name;
  int parent = -1;  // -1 for the root.
  Vec3 offset;      // Translation from the parent in the parent's frame, at rest.
  std::vector<Channel> channels;
  std::vector<Vec3> end_sites;  // BVH "End Site" offsets below this joint.
};

class Skeleton {
 public:
  // Validates and indexes `joints`: exactly one root (index 0), depth-first
  // order (each parent before its children, subtrees contiguous), unique non-empty names, at most 6
  // channels per joint with no channel repeated, rotation channels (if any) forming a full 3-axis
  // Euler order, and finite offsets. INVALID_ARGUMENT names the offending joint.
  static absl::StatusOr<Skeleton> Create(std::vector<Joint> joints);

  Skeleton();

  int num_joints() const { return static_cast<int>(d_->joints.size()); }
  const Joint& joint(int i) const { return d_->joints[i]; }
  const std::vector<Joint>& joints() const { return d_->joints; }
  const std::vector<int>& children(int i) const { return d_->children[i]; }

  // Index of the joint called `name` (exact match), or nullopt.
  std::optional<int> Find(absl::string_view name) const;

  // Total channels in one frame row, and where joint i's channels start in it.
  int num_channels() const { return d_->num_channels; }
  int channel_start(int i) const { return d_->channel_start[i]; }
  // Euler order of joint i's rotation channels (ZXY when it has none).
  const EulerOrder& rotation_order(int i) const { return d_->rotation_order[i]; }
  bool has_rotation(int i) const { return d_->has_rotation[i]; }

  // True when both have the same joint names, parents and channel layouts
  // (offsets may differ: the same rig at another scale still matches).
  bool SameTopology(const Skeleton& other) const;
  // Empty when SameTopology(other); otherwise a sentence naming the first
  // difference, e.g. "joint 3 is 'Neck' here but 'Spine2' in the other".
  std::string DescribeMismatch(const Skeleton& other) const;

 private:
  struct Data {
    std::vector<Joint> joints;
    std::vector<std::vector<int>> children;
    std::vector<int> channel_start;
    std::vector<EulerOrder> rotation_order;
    std::vector<bool> has_rotation;
    int num_channels = 0;
  };
  std::shared_ptr<const Data> d_;  // Never null; shared by copies.
};

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_SKELETON_H_
