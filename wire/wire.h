// Conversion between the wire types of proto/stylus/v1/motion.proto and the
// motion library's Skeleton and Motion. Shared by the client and the server
// (both speak the same proto; neither needs LibTorch for this).
//
// A Frame holds local quaternions; a Motion holds BVH channels (Euler angles
// in each joint's own order). Converting a clip writes Euler angles frame by
// frame, each nearest to the previous frame's, so the result has no 360-degree
// jumps.
#ifndef STYLUS_WIRE_WIRE_H_
#define STYLUS_WIRE_WIRE_H_

#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/motion.h"
#include "motion/rig_roles.h"
#include "motion/skeleton.h"
#include "stylus/v1/motion.pb.h"

namespace stylus::wire {

void SkeletonToProto(const motion::Skeleton& skeleton, v1::Skeleton* out);
// INVALID_ARGUMENT (prefixed with `what`) naming the joint that is malformed:
// unknown channel names, parents out of order, non-finite offsets, ...
absl::StatusOr<motion::Skeleton> SkeletonFromProto(const v1::Skeleton& skeleton,
                                                   const std::string& what);

// A skeleton's joint map (role -> joint name). INVALID_ARGUMENT (prefixed
// with `what`) for an unknown role or an empty joint name.
absl::StatusOr<motion::JointMap> JointMapFromProto(const v1::Skeleton& skeleton,
                                                   const std::string& what);
void JointMapToProto(const motion::JointMap& map, v1::Skeleton* out);

// Frame `f` of `motion` as a wire frame with the given index.
void FrameToProto(const motion::Motion& motion, int f, int64_t index, v1::Frame* out);
void ClipToProto(const motion::Motion& motion, v1::Clip* out);

// Appends `frame` to `motion` (whose skeleton is set). `prev_euler` carries
// Euler continuity between calls (one Vec3 per joint; zeros before the first
// frame). INVALID_ARGUMENT (prefixed with `what`) names the frame and joint of
// a wrong count, a non-finite value or a zero quaternion.
absl::Status AppendFrame(const v1::Frame& frame, const std::string& what,
                         std::vector<motion::Vec3>* prev_euler, motion::Motion* motion);

// INVALID_ARGUMENT (prefixed with `what`) naming the frame, joint and channel
// of the first NaN or infinite channel value. Clients check before sending:
// a non-finite Euler angle has no quaternion to put on the wire.
absl::Status CheckFinite(const motion::Motion& motion, const std::string& what);

// The whole clip: skeleton, fps (positive, finite), frames in order.
absl::StatusOr<motion::Motion> ClipFromProto(const v1::Clip& clip, const std::string& what);

}  // namespace stylus::wire

#endif  // STYLUS_WIRE_WIRE_H_
