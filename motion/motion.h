// Motion: a skeleton plus per-frame channel values (what a BVH MOTION section
// holds), and conversion between those raw channels and joint poses.
#ifndef STYLUS_MOTION_MOTION_H_
#define STYLUS_MOTION_MOTION_H_

#include <vector>

#include "motion/rotation.h"
#include "motion/skeleton.h"

namespace stylus::motion {

struct Motion {
  Skeleton skeleton;
  double frame_time = 1.0 / 30.0;  // Seconds per frame.
  int num_frames = 0;
  // num_frames rows of skeleton.num_channels() values, in file order: positions in
  // the file's units, rotations in degrees.
  std::vector<double> values;

  double fps() const { return 1.0 / frame_time; }
  double* frame(int f) { return values.data() + static_cast<size_t>(f) * skeleton.num_channels(); }
  const double* frame(int f) const {
    return values.data() + static_cast<size_t>(f) * skeleton.num_channels();
  }
};

// The local (parent-relative) transform of every joint in one frame.
struct LocalPose {
  std::vector<Vec3> translations;
  std::vector<Quat> rotations;
};

// Reads frame `f` as a pose. A joint's translation is its OFFSET with each
// component that has a position channel replaced by that channel's value (the
// convention of Blender and of the Bandai data, whose non-root joints carry
// position channels equal to their offsets); its rotation composes its rotation
// channels in their listed order.
LocalPose PoseAt(const Motion& motion, int f);

// Writes `pose` into frame `f`. Components of a translation without a position
// channel are dropped (they are fixed by the OFFSET). Rotations become Euler
// angles in each joint's own order, chosen nearest to `previous_euler` (one Vec3
// per joint, updated in place) so a sequence written frame by frame stays
// continuous; pass a vector of zeros for the first frame.
void SetPose(Motion* motion, int f, const LocalPose& pose, std::vector<Vec3>* previous_euler);

// An all-zero-rotation motion of `num_frames` frames whose translations are the
// skeleton's offsets.
Motion RestMotion(const Skeleton& skeleton, int num_frames, double frame_time);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_MOTION_H_
