#include "motion/retarget.h"

#include <algorithm>
#include <utility>

#include "absl/strings/str_cat.h"
#include "motion/features.h"
#include "motion/kinematics.h"

namespace stylus::motion {
namespace {

Vec3 Lerp(const Vec3& a, const Vec3& b, double t) { return a + t * (b - a); }

// Where `middle` sits between `from` and `to` in `pose`, as a fraction of
// the two distances.
double Fraction(const GlobalPose& pose, int from, int middle, int to) {
  const double a = Norm(pose.positions[middle] - pose.positions[from]);
  const double b = Norm(pose.positions[to] - pose.positions[middle]);
  return a + b > 1e-9 ? a / (a + b) : 0.5;
}

constexpr Role kToes[2] = {Role::kLeftToe, Role::kRightToe};
constexpr Role kFeet[2] = {Role::kLeftFoot, Role::kRightFoot};
constexpr Role kClavicles[2] = {Role::kLeftClavicle, Role::kRightClavicle};
constexpr Role kUpperArms[2] = {Role::kLeftUpperArm, Role::kRightUpperArm};

// The slots (motion/aim_fit.h) a rig's roles give targets to.
std::vector<char> RoleSlots(const Skeleton& sk, const RigRoles& r, bool with_toes) {
  std::vector<char> slots(2 * sk.num_joints(), 0);
  for (int i = 0; i < kRoleCount; ++i) {
    if (r.joint[i] >= 0) slots[r.joint[i]] = 1;
  }
  for (int s = 0; s < 2; ++s) {
    if (!with_toes) {
      if (r.has(kToes[s])) slots[r[kToes[s]]] = 0;
    } else if (r.toe_is_end_site[s]) {
      slots[sk.num_joints() + r[kFeet[s]]] = 1;
    }
  }
  return slots;
}

bool RigHasToes(const RigRoles& r) {
  return (r.has(Role::kLeftToe) || r.toe_is_end_site[0]) &&
         (r.has(Role::kRightToe) || r.toe_is_end_site[1]);
}

// The Euler triple of each joint in a frame row, in its channels' order.
void ReadEuler(const Skeleton& sk, const double* row, std::vector<Vec3>* euler) {
  euler->assign(sk.num_joints(), Vec3{});
  for (int j = 0; j < sk.num_joints(); ++j) {
    const Joint& joint = sk.joint(j);
    int k = 0;
    for (size_t c = 0; c < joint.channels.size(); ++c) {
      if (!IsPosition(joint.channels[c])) (*euler)[j][k++] = row[sk.channel_start(j) + c];
    }
  }
}

}  // namespace

std::vector<Quat> MeanFeatureRotations(const std::vector<float>& feature_mean,
                                       const Skeleton& skeleton, int pelvis) {
  const FeatureLayout layout(skeleton.num_joints());
  std::vector<Quat> out(skeleton.num_joints());
  if (static_cast<int>(feature_mean.size()) < layout.dim()) return out;
  std::vector<bool> above(skeleton.num_joints(), false);
  for (int p = pelvis >= 0 ? skeleton.joint(pelvis).parent : -1; p >= 0;
       p = skeleton.joint(p).parent) {
    above[p] = true;
  }
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    const float* q = feature_mean.data() + layout.rotation(j);
    if (!above[j]) out[j] = Normalized(Quat{q[0], q[1], q[2], q[3]});
  }
  return out;
}

absl::StatusOr<std::shared_ptr<const ModelRig>> MakeModelRig(
    const Skeleton& skeleton, const std::vector<Quat>& reference_rotations) {
  if (static_cast<int>(reference_rotations.size()) != skeleton.num_joints()) {
    return absl::InvalidArgumentError(absl::StrCat("reference pose has ",
                                                   reference_rotations.size(), " rotations for ",
                                                   skeleton.num_joints(), " joints"));
  }
  auto rig = std::make_shared<ModelRig>();
  rig->skeleton = skeleton;
  rig->reference = PoseAt(RestMotion(skeleton, 1, 1.0 / 30), 0);
  for (int j = 0; j < skeleton.num_joints(); ++j) {
    rig->reference.rotations[j] = Normalized(reference_rotations[j]);
  }
  absl::StatusOr<RigRoles> roles =
      FindRigRoles(skeleton, ForwardKinematics(skeleton, rig->reference));
  if (!roles.ok()) {
    return absl::InvalidArgumentError(
        absl::StrCat("the model's own skeleton: ", roles.status().message()));
  }
  for (Role r : {Role::kSpine, Role::kNeck, Role::kLeftClavicle, Role::kRightClavicle,
                 Role::kLeftToe, Role::kRightToe}) {
    if (!roles->has(r)) {
      return absl::InvalidArgumentError(absl::StrCat("the model's own skeleton has no ",
                                                     RoleName(r), " joint; retargeting needs one"));
    }
  }
  rig->roles = *roles;
  rig->leg_length = LegLength(skeleton, rig->roles);
  const GlobalPose ref = ForwardKinematics(skeleton, rig->reference);
  const RigRoles& m = rig->roles;
  rig->spine_at = Fraction(ref, m[Role::kPelvis], m[Role::kSpine], m[Role::kChest]);
  rig->neck_at = Fraction(ref, m[Role::kChest], m[Role::kNeck], m[Role::kHead]);
  for (int s = 0; s < 2; ++s) {
    rig->clavicle_at[s] = Fraction(ref, m[Role::kChest], m[kClavicles[s]], m[kUpperArms[s]]);
  }
  return std::shared_ptr<const ModelRig>(std::move(rig));
}

Retargeter::Retargeter(std::shared_ptr<const ModelRig> model, const Skeleton& rig, RigRoles roles)
    : model_(std::move(model)),
      rig_(rig),
      roles_(std::move(roles)),
      model_plan_(model_->skeleton, model_->roles,
                  RoleSlots(model_->skeleton, model_->roles, RigHasToes(roles_))),
      rig_plan_(rig_, roles_, RoleSlots(rig_, roles_, true)),
      rig_one_(RestMotion(rig_, 1, 1.0 / 30)),
      model_one_(RestMotion(model_->skeleton, 1, 1.0 / 30)) {
  scale_ = model_->leg_length / std::max(LegLength(rig_, roles_), 1e-9);
  up_turn_ = RotationBetween(roles_.up, model_->roles.up);
  Reset();
}

absl::StatusOr<std::unique_ptr<Retargeter>> Retargeter::Create(
    std::shared_ptr<const ModelRig> model, const Skeleton& rig, const double* first_frame,
    const JointMap& joint_map) {
  Motion one = RestMotion(rig, 1, 1.0 / 30);
  std::copy(first_frame, first_frame + rig.num_channels(), one.values.begin());
  absl::StatusOr<RigRoles> roles =
      FindRigRoles(rig, ForwardKinematics(rig, PoseAt(one, 0)), joint_map);
  if (!roles.ok()) return roles.status();
  if (LegLength(rig, *roles) <= 0) {
    return absl::InvalidArgumentError("the rig's legs have zero length (all offsets zero)");
  }
  return std::unique_ptr<Retargeter>(new Retargeter(std::move(model), rig, *std::move(roles)));
}

void Retargeter::Reset() { model_euler_.assign(model_->skeleton.num_joints(), Vec3{}); }

GlobalPose Retargeter::RigWorld(const double* rig_frame) {
  std::copy(rig_frame, rig_frame + rig_.num_channels(), rig_one_.values.begin());
  return ForwardKinematics(rig_, PoseAt(rig_one_, 0));
}

void Retargeter::ToModel(const double* rig_frame, double* model_frame) {
  const GlobalPose world = RigWorld(rig_frame);
  std::array<Vec3, kRoleCount> at;
  std::array<bool, kRoleCount> has{};
  for (int i = 0; i < kRoleCount; ++i) {
    const int j = roles_.joint[i];
    if (j < 0) continue;
    at[i] = world.positions[j];
    has[i] = true;
  }
  for (int s = 0; s < 2; ++s) {
    if (!roles_.toe_is_end_site[s]) continue;
    const int foot = roles_[kFeet[s]];
    at[static_cast<int>(kToes[s])] =
        world.positions[foot] + Rotate(world.rotations[foot], rig_.joint(foot).end_sites[0]);
    has[static_cast<int>(kToes[s])] = true;
  }
  for (int i = 0; i < kRoleCount; ++i) {
    if (has[i]) at[i] = scale_ * Rotate(up_turn_, at[i]);
  }
  auto fill = [&](Role r, Role from, Role to, double t) {
    const int i = static_cast<int>(r);
    if (has[i]) return;
    at[i] = Lerp(at[static_cast<int>(from)], at[static_cast<int>(to)], t);
    has[i] = true;
  };
  fill(Role::kSpine, Role::kPelvis, Role::kChest, model_->spine_at);
  fill(Role::kNeck, Role::kChest, Role::kHead, model_->neck_at);
  for (int s = 0; s < 2; ++s) {
    fill(kClavicles[s], Role::kChest, kUpperArms[s], model_->clavicle_at[s]);
  }

  const Skeleton& msk = model_->skeleton;
  AimTargets targets(msk.num_joints());
  for (int i = 0; i < kRoleCount; ++i) {
    if (has[i]) targets.Set(model_->roles.joint[i], at[i]);
  }
  LocalPose pose = model_->reference;
  model_plan_.Fit(targets, &pose);
  SetPose(&model_one_, 0, pose, &model_euler_);
  std::copy(model_one_.values.begin(), model_one_.values.end(), model_frame);
}

void Retargeter::FromModel(const double* model_frame, const double* rig_frame, double* out_frame) {
  const Skeleton& msk = model_->skeleton;
  std::copy(model_frame, model_frame + msk.num_channels(), model_one_.values.begin());
  const GlobalPose model_world = ForwardKinematics(msk, PoseAt(model_one_, 0));
  const Quat back = Conjugate(up_turn_);
  auto to_rig = [&](const Vec3& p) { return Rotate(back, (1.0 / scale_) * p); };
  AimTargets targets(rig_.num_joints());
  for (int i = 0; i < kRoleCount; ++i) {
    if (roles_.joint[i] >= 0) {
      targets.Set(roles_.joint[i], to_rig(model_world.positions[model_->roles.joint[i]]));
    }
  }
  for (int s = 0; s < 2; ++s) {
    if (roles_.toe_is_end_site[s]) {
      targets.Set(rig_.num_joints() + roles_[kFeet[s]],
                  to_rig(model_world.positions[model_->roles[kToes[s]]]));
    }
  }
  std::copy(rig_frame, rig_frame + rig_.num_channels(), rig_one_.values.begin());
  LocalPose pose = PoseAt(rig_one_, 0);
  rig_plan_.Fit(targets, &pose);
  ReadEuler(rig_, rig_frame, &rig_euler_);
  SetPose(&rig_one_, 0, pose, &rig_euler_);
  std::copy(rig_one_.values.begin(), rig_one_.values.end(), out_frame);
  // What the fit left alone keeps its input values exactly.
  for (int j = 0; j < rig_.num_joints(); ++j) {
    const Joint& joint = rig_.joint(j);
    for (size_t c = 0; c < joint.channels.size(); ++c) {
      const bool keep =
          IsPosition(joint.channels[c]) ? j != rig_plan_.mover() : !rig_plan_.fitted()[j];
      const int at = rig_.channel_start(j) + static_cast<int>(c);
      if (keep) out_frame[at] = rig_frame[at];
    }
  }
}

Motion Retargeter::ToModel(const Motion& clip) {
  Reset();
  Motion out = RestMotion(model_->skeleton, clip.num_frames, clip.frame_time);
  for (int f = 0; f < clip.num_frames; ++f) ToModel(clip.frame(f), out.frame(f));
  return out;
}

absl::StatusOr<Motion> Retargeter::FromModel(const Motion& model_clip, const Motion& rig_clip) {
  if (model_clip.num_frames != rig_clip.num_frames) {
    return absl::InvalidArgumentError(absl::StrCat("retargeting back: ", model_clip.num_frames,
                                                   " model frames for ", rig_clip.num_frames,
                                                   " frames of the rig's clip"));
  }
  Motion out = rig_clip;
  for (int f = 0; f < rig_clip.num_frames; ++f) {
    FromModel(model_clip.frame(f), rig_clip.frame(f), out.frame(f));
  }
  return out;
}

}  // namespace stylus::motion
