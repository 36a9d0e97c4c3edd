// Fitting a pose to target positions: turns joints so that the joints (and
// End Sites) that have targets land on them, keeping the skeleton's bone
// lengths. Retargeting (motion/retarget.h) drives it in both directions:
// another rig's joint positions onto a model's skeleton, and the model's
// output back onto the rig.
#ifndef STYLUS_MOTION_AIM_FIT_H_
#define STYLUS_MOTION_AIM_FIT_H_

#include <array>
#include <vector>

#include "motion/motion.h"
#include "motion/rig_roles.h"

namespace stylus::motion {

// Targets of one frame: slot j < J is joint j, slot J + j the first End Site
// of joint j.
struct AimTargets {
  std::vector<Vec3> position;
  std::vector<char> has;

  explicit AimTargets(int joints = 0) : position(2 * joints), has(2 * joints, 0) {}
  void Set(int slot, const Vec3& p) {
    position[slot] = p;
    has[slot] = 1;
  }
};

// What a skeleton's fit does, worked out once per skeleton and role map.
class AimPlan {
 public:
  // `targeted`: the slots that will have targets (see AimTargets).
  AimPlan(const Skeleton& skeleton, const RigRoles& roles, const std::vector<char>& targeted);

  // Fits `pose` (the start: joints without a target below them keep their
  // rotation) to `targets`, in place:
  //  * the pelvis's nearest ancestor-or-self with position channels moves
  //    so that the pelvis is at its target (joints above the pelvis keep
  //    their rotations); once the pelvis has turned, it moves again so that
  //    the midpoint of the hip joints is at their targets' midpoint (rigs
  //    whose hip joints sit elsewhere below the pelvis then reach the same
  //    foot positions with legs of the same length);
  //  * walking down from the pelvis, a joint with one aim (the first
  //    targeted joint below each child) turns by the smallest rotation that
  //    points it at its target; thighs and upper arms then turn about that
  //    line so that the knee or elbow bends towards the target of the joint
  //    after (when the limb is bent enough to tell); a joint with several
  //    aims (pelvis, chest) takes the least-squares rotation over them;
  //  * each foot is then placed on its target by two-bone IK (the knee's
  //    hinge kept), the foot keeping its world rotation.
  void Fit(const AimTargets& targets, LocalPose* pose) const;

  // Joints whose rotation Fit may change.
  const std::vector<bool>& fitted() const { return fitted_; }
  // The joint whose translation Fit changes (-1: none).
  int mover() const { return mover_; }

 private:
  void PlaceHips(const AimTargets& targets, int pelvis, const std::vector<Quat>& wr,
                 std::vector<Vec3>* wp, LocalPose* pose) const;
  // The current offset of slot `aim` from joint `j`, in j's frame.
  Vec3 OffsetFrom(int j, int aim, const LocalPose& pose) const;

  Skeleton skeleton_;
  int pelvis_ = -1;
  int mover_ = -1;  // The joint whose translation places the pelvis.
  std::vector<std::vector<int>> aims_;
  std::vector<bool> twist_, fitted_, above_pelvis_;
  std::vector<std::array<int, 3>> legs_;  // thigh, shin, foot.
  std::array<int, 2> hips_{{-1, -1}};     // Thighs whose midpoint places the pelvis.
};

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_AIM_FIT_H_
