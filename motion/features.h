// Per-frame motion features (docs/motion.md "Features"), the representation the
// models learn on, and their inverse back to a motion on the original skeleton.
//
// Frame layout, d = 7J + 8 channels for J joints:
//   [0, 3J)      joint positions relative to the character root, in its facing
//                frame (joints above the pelvis: their parent-relative translation)
//   [3J, 7J)     joint rotations as unit quaternions (w,x,y,z): the pelvis relative
//                to the facing frame, every other joint relative to its parent;
//                first frame's sign by CanonicalSign, then each frame in the
//                previous frame's hemisphere
//   [7J, 7J+4)   root trajectory: planar velocity (x, z) in the facing frame and
//                yaw rate, both per second, and the pelvis's vertical velocity
//   [7J+4, 7J+8) foot contacts (0/1): left ankle, left toe, right ankle, right toe
// The character root is the pelvis projected onto the floor (y = 0); its facing
// direction is perpendicular to the hip and shoulder lines.
#ifndef STYLUS_MOTION_FEATURES_H_
#define STYLUS_MOTION_FEATURES_H_

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/contacts.h"
#include "motion/humanoid.h"
#include "motion/motion.h"

namespace stylus::motion {

struct FeatureLayout {
  int num_joints = 0;

  // The root trajectory (4) and foot contacts (4): the last channels, the
  // ones that say where the character goes rather than how it poses.
  static constexpr int kPathChannels = 8;

  explicit FeatureLayout(int joints) : num_joints(joints) {}
  int position(int joint) const { return 3 * joint; }
  int rotation(int joint) const { return 3 * num_joints + 4 * joint; }
  int trajectory() const { return 7 * num_joints; }
  int contacts() const { return 7 * num_joints + 4; }
  int dim() const { return 7 * num_joints + kPathChannels; }
  // One name per channel, e.g. "Hips.py", "Hips.qw", "root.vx", "contact.Toes_L".
  std::vector<std::string> ChannelNames(const Skeleton& skeleton, const HumanoidRoles& roles) const;
};

// A frames x dim matrix of features, row-major.
struct FeatureClip {
  int frames = 0;
  int dim = 0;
  std::vector<float> values;

  float* row(int f) { return values.data() + static_cast<size_t>(f) * dim; }
  const float* row(int f) const { return values.data() + static_cast<size_t>(f) * dim; }
};

// Where and how the character stands in the first frame; MotionFromFeatures
// starts integrating the trajectory here.
struct RootStart {
  double x = 0, z = 0;  // Floor position.
  double yaw = 0;       // Facing, radians about +Y (0 faces +Z).
};

// Joints strictly above the pelvis (a root the pelvis hangs from): their
// position channels hold their parent-relative translation, not a position
// relative to the character root.
std::vector<bool> AbovePelvis(const Skeleton& skeleton, const HumanoidRoles& roles);

// Features of every frame. INVALID_ARGUMENT if the motion has no frames.
// `sign_reference` (one per joint), when given, stands for the feature
// quaternions of the frame before the motion's first: the first frame's signs
// follow it instead of CanonicalSign, so the features of a later stretch of a
// clip equal those of the whole clip.
absl::StatusOr<FeatureClip> ExtractFeatures(const Motion& motion, const HumanoidRoles& roles,
                                            const ContactParams& contacts = {},
                                            const std::vector<Quat>* sign_reference = nullptr);
// ExtractFeatures one frame at a time, for streams: each frame's features
// are final once the frame after it has arrived (velocities and contact
// speeds look one frame ahead), and equal ExtractFeatures of the whole clip
// with `contacts.running_floor` (the only floor a stream can know; it is
// used whatever `contacts.running_floor` says).
// O(1) time and memory per frame.
class FeatureStream {
 public:
  FeatureStream(const Skeleton& skeleton, const HumanoidRoles& roles, double frame_time,
                ContactParams contacts);
  // Takes the next frame (skeleton.num_channels() values). When a frame
  // before it is waiting, writes that frame's features into `out` (dim
  // values) and returns true.
  bool Push(const double* frame, float* out);
  // Writes the features of the frame still waiting (the clip's last, whose
  // velocities repeat the frame before it) and returns true; false when no
  // frame waits.
  bool Finish(float* out);
  int dim() const { return layout_.dim(); }
  int64_t frames() const { return frames_; }  // Frames pushed.

 private:
  struct Frame {
    std::vector<Vec3> positions;
    Vec3 root;
    double yaw = 0;
    std::vector<float> row;  // Pose channels filled; the rest zero.
    std::array<bool, 4> low{};
  };
  void Complete(const Frame* after, float* out);
  Skeleton skeleton_;
  Motion one_;  // The frame being read (reused: no skeleton copy per frame).
  HumanoidRoles roles_;
  double fps_;
  ContactParams contacts_;
  FeatureLayout layout_;
  std::vector<bool> above_;
  std::vector<Quat> prev_q_;
  std::array<double, 4> ground_;
  Frame before_, waiting_;  // Frames f - 1 and f (f waits for f + 1).
  bool has_before_ = false, has_waiting_ = false;
  int64_t frames_ = 0;
};

// The feature quaternions of frame `f` of `features` (one per joint): the
// sign_reference for a stretch that starts at frame f + 1.
std::vector<Quat> FeatureRotations(const FeatureClip& features, int f);

// The root's floor position and facing in frame `f` of a motion.
RootStart RootAt(const Motion& motion, const HumanoidRoles& roles, int f);

// The body's facing, radians about +Y (0 faces +Z), from world positions
// with Y up: square to the hip and shoulder lines (left minus right).
double FacingYaw(const std::vector<Vec3>& positions, const HumanoidRoles& roles);

// The inverse of ExtractFeatures: a motion on `skeleton` (same channel layout)
// whose root follows the integrated trajectory from `start`. Joints below the
// pelvis keep the skeleton's offsets (bone lengths), quaternions are
// renormalized, Euler angles are continuous. A generated quaternion shorter
// than kMinRotationNorm says no rotation clearly (a network torn between q
// and -q): the joint keeps its previous frame's rotation instead of snapping
// to an arbitrary one. INVALID_ARGUMENT when the clip's
// width does not match the skeleton or a value is not finite.
absl::StatusOr<Motion> MotionFromFeatures(const FeatureClip& features, const Skeleton& skeleton,
                                          const HumanoidRoles& roles, double frame_time,
                                          const RootStart& start = {});

// Where the reconstruction of a clip stands between consecutive chunks of it
// (streaming): the root's floor position and facing for the next frame, and
// the last Euler angles written (one per joint; zeros before the first frame).
inline constexpr double kMinRotationNorm = 0.5;
struct DecodeState {
  RootStart root;
  std::vector<Vec3> prev_euler;
  std::vector<Quat> prev_rotations;  // Last frame's local rotations (empty at first).
};
// MotionFromFeatures for the next chunk of a clip: starts at `state` and
// leaves it ready for the chunk after, so chunks decoded one after another
// equal the whole clip decoded at once. `state->prev_euler` may be empty.
absl::StatusOr<Motion> MotionFromFeatures(const FeatureClip& features, const Skeleton& skeleton,
                                          const HumanoidRoles& roles, double frame_time,
                                          DecodeState* state);

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_FEATURES_H_
