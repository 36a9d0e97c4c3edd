// Retargeting between a clip's own humanoid rig and a model's skeleton.
//
// Both rigs' joints get humanoid roles (motion/rig_roles.h). A rig frame goes
// onto the model's skeleton by its joint positions: taken into the model's
// space (the rig's up axis turned onto the model's, scaled by the ratio of
// leg lengths, which also converts units), they are the targets of a fit
// (motion/aim_fit.h) that starts from the model's reference pose: each model
// joint points at its role's position, thighs and upper arms turn so knees
// and elbows bend the rig's way, feet land where the rig's are. Roles the rig
// lacks (a spine joint, a neck, clavicles) get positions on the line between
// their neighbours; a rig without toes uses its foot's End Site.
//
// Back, a model frame goes onto the rig the same way, starting from the rig's
// own input frame, so what the model did not change (twists, fingers, props,
// joints with no role) keeps its input motion; feet are put on the model's
// feet by IK, so planted feet stay planted. The output has the input's joint
// names, offsets and channel layout.
//
// A Retargeter holds per-clip state (Euler continuity): one per clip or
// stream, not shared between threads.
#ifndef STYLUS_MOTION_RETARGET_H_
#define STYLUS_MOTION_RETARGET_H_

#include <array>
#include <memory>
#include <vector>

#include "absl/status/statusor.h"
#include "motion/aim_fit.h"
#include "motion/motion.h"
#include "motion/rig_roles.h"

namespace stylus::motion {

// A model's side: its skeleton, roles and reference pose (what its joints
// keep where the rig says nothing, e.g. head and hands).
struct ModelRig {
  Skeleton skeleton;
  RigRoles roles;
  LocalPose reference;
  double leg_length = 0;
  // Where the reference pose puts the spine, neck and clavicles between
  // their neighbours (0..1): positions for roles a rig lacks.
  double spine_at = 0.5, neck_at = 0.5;
  std::array<double, 2> clavicle_at{{0.5, 0.5}};  // Left, right.
};

// `reference_rotations`: one local rotation per joint (e.g. the mean pose of
// the training data); the roles are found on that pose.
absl::StatusOr<std::shared_ptr<const ModelRig>> MakeModelRig(
    const Skeleton& skeleton, const std::vector<Quat>& reference_rotations);

// A reference pose from the mean of a model's training features
// (motion/features.h, e.g. NormStats::mean): each joint's mean rotation
// channels, normalized; joints above the pelvis keep no rotation.
std::vector<Quat> MeanFeatureRotations(const std::vector<float>& feature_mean,
                                       const Skeleton& skeleton, int pelvis);

class Retargeter {
 public:
  // `first_frame`: the clip's (or stream's) first frame on `rig`, which gives
  // the up axis and, when names do not tell, the sides. INVALID_ARGUMENT
  // names the roles the rig lacks.
  static absl::StatusOr<std::unique_ptr<Retargeter>> Create(std::shared_ptr<const ModelRig> model,
                                                            const Skeleton& rig,
                                                            const double* first_frame,
                                                            const JointMap& joint_map = {});

  const RigRoles& roles() const { return roles_; }
  const Skeleton& rig() const { return rig_; }
  // Model units per rig unit.
  double scale() const { return scale_; }

  // One frame (rig.num_channels() values) onto the model's skeleton.
  void ToModel(const double* rig_frame, double* model_frame);
  // One model frame back onto the rig, starting from the rig's frame it was
  // made from.
  void FromModel(const double* model_frame, const double* rig_frame, double* out_frame);

  // A whole clip onto the model's skeleton (same frame rate and count).
  Motion ToModel(const Motion& clip);
  // `model_clip` (frame for frame the output of `rig_clip` on the model)
  // back onto the rig. INVALID_ARGUMENT when the frame counts differ.
  absl::StatusOr<Motion> FromModel(const Motion& model_clip, const Motion& rig_clip);

  // Starts a new clip (Euler continuity of ToModel).
  void Reset();

 private:
  Retargeter(std::shared_ptr<const ModelRig> model, const Skeleton& rig, RigRoles roles);
  GlobalPose RigWorld(const double* rig_frame);

  std::shared_ptr<const ModelRig> model_;
  Skeleton rig_;
  RigRoles roles_;
  double scale_ = 1;
  Quat up_turn_;  // Rig space -> model space, before scaling.
  AimPlan model_plan_, rig_plan_;
  Motion rig_one_, model_one_;  // One-frame scratch.
  std::vector<Vec3> model_euler_, rig_euler_;
};

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_RETARGET_H_
