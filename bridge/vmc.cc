#include "bridge/vmc.h"

#include <utility>

#include "absl/container/flat_hash_map.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace stylus::bridge {
namespace {

using motion::Quat;
using motion::Vec3;

// Unity's HumanBodyBones (the body and fingers) with their humanoid parent,
// parents first.
const std::vector<std::pair<std::string, std::string>>& Bones() {
  static const auto* bones = [] {
    auto* b = new std::vector<std::pair<std::string, std::string>>{
        {"Hips", ""},           {"Spine", "Hips"},      {"Chest", "Spine"},
        {"UpperChest", "Chest"}, {"Neck", "UpperChest"}, {"Head", "Neck"},
        {"LeftEye", "Head"},    {"RightEye", "Head"},   {"Jaw", "Head"}};
    for (const char* side : {"Left", "Right"}) {
      const std::string s = side;
      b->push_back({s + "Shoulder", "UpperChest"});
      b->push_back({s + "UpperArm", s + "Shoulder"});
      b->push_back({s + "LowerArm", s + "UpperArm"});
      b->push_back({s + "Hand", s + "LowerArm"});
      for (const char* finger : {"Thumb", "Index", "Middle", "Ring", "Little"}) {
        const std::string f = s + finger;
        b->push_back({f + "Proximal", s + "Hand"});
        b->push_back({f + "Intermediate", f + "Proximal"});
        b->push_back({f + "Distal", f + "Intermediate"});
      }
      b->push_back({s + "UpperLeg", "Hips"});
      b->push_back({s + "LowerLeg", s + "UpperLeg"});
      b->push_back({s + "Foot", s + "LowerLeg"});
      b->push_back({s + "Toes", s + "Foot"});
    }
    return b;
  }();
  return *bones;
}

const absl::flat_hash_map<std::string, std::string>& Parents() {
  static const auto* parents = [] {
    auto* p = new absl::flat_hash_map<std::string, std::string>();
    for (const auto& [bone, parent] : Bones()) (*p)[bone] = parent;
    return p;
  }();
  return *parents;
}

}  // namespace

VmcTransform FromUnity(const float p[3], const float q[4]) {
  return {Vec3{-p[0], p[1], p[2]}, motion::Normalized(Quat{q[3], q[0], -q[1], -q[2]})};
}

void ToUnity(const VmcTransform& t, float p[3], float q[4]) {
  p[0] = static_cast<float>(-t.position.x);
  p[1] = static_cast<float>(t.position.y);
  p[2] = static_cast<float>(t.position.z);
  q[0] = static_cast<float>(t.rotation.x);
  q[1] = static_cast<float>(-t.rotation.y);
  q[2] = static_cast<float>(-t.rotation.z);
  q[3] = static_cast<float>(t.rotation.w);
}

std::string UnityParent(const std::string& bone) {
  auto it = Parents().find(bone);
  return it == Parents().end() ? "" : it->second;
}

bool IsUnityBone(const std::string& bone) { return Parents().contains(bone); }

absl::StatusOr<VmcSkeleton> VmcSkeleton::FromFrame(const VmcFrame& frame) {
  if (!frame.bones.count("Hips")) {
    return absl::InvalidArgumentError("the performer sent no Hips bone (/VMC/Ext/Bone/Pos \"Hips\")");
  }
  std::vector<std::string> missing;
  for (const char* need : {"LeftUpperLeg", "LeftLowerLeg", "LeftFoot", "RightUpperLeg", "RightLowerLeg",
                           "RightFoot", "LeftUpperArm", "LeftLowerArm", "LeftHand", "RightUpperArm",
                           "RightLowerArm", "RightHand"}) {
    if (!frame.bones.count(need)) missing.push_back(need);
  }
  if (!missing.empty()) {
    return absl::InvalidArgumentError(absl::StrCat("the performer sent no ", absl::StrJoin(missing, ", "),
                                                   ": Stylus needs a humanoid's legs and arms"));
  }
  // The bones sent, each under its nearest sent humanoid ancestor, then in
  // depth-first order from the Hips (children in the table's order).
  absl::flat_hash_map<std::string, std::vector<std::string>> children;
  for (const auto& [bone, declared] : Bones()) {
    if (bone == "Hips" || !frame.bones.count(bone)) continue;
    std::string parent = declared;
    while (!parent.empty() && !frame.bones.count(parent)) parent = UnityParent(parent);
    if (!parent.empty()) children[parent].push_back(bone);
  }
  std::vector<motion::Joint> joints;
  std::vector<std::pair<std::string, int>> stack = {{"Hips", -1}};
  while (!stack.empty()) {
    auto [bone, parent] = stack.back();
    stack.pop_back();
    motion::Joint j;
    j.name = bone;
    j.parent = parent;
    j.offset = bone == "Hips" ? Vec3{} : frame.bones.at(bone).position;
    using motion::Channel;
    if (bone == "Hips") j.channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition};
    j.channels.insert(j.channels.end(), {Channel::kZrotation, Channel::kXrotation, Channel::kYrotation});
    const int self = static_cast<int>(joints.size());
    joints.push_back(std::move(j));
    const std::vector<std::string>& kids = children[bone];
    for (auto it = kids.rbegin(); it != kids.rend(); ++it) stack.push_back({*it, self});
  }
  absl::StatusOr<motion::Skeleton> skeleton = motion::Skeleton::Create(std::move(joints));
  if (!skeleton.ok()) return skeleton.status();
  VmcSkeleton s;
  s.skeleton_ = *std::move(skeleton);
  return s;
}

std::vector<double> VmcSkeleton::Row(const VmcFrame& frame) const {
  motion::Motion one = motion::RestMotion(skeleton_, 1, 1.0 / 30);
  motion::LocalPose pose = motion::PoseAt(one, 0);
  for (int j = 0; j < skeleton_.num_joints(); ++j) {
    auto it = frame.bones.find(skeleton_.joint(j).name);
    if (it == frame.bones.end()) continue;
    if (j == 0) {
      // The Hips in the world: the avatar's root transform, then its own.
      pose.translations[0] = frame.root.position + motion::Rotate(frame.root.rotation, it->second.position);
      pose.rotations[0] = motion::Normalized(frame.root.rotation * it->second.rotation);
    } else {
      pose.rotations[j] = it->second.rotation;
    }
  }
  std::vector<motion::Vec3> euler(skeleton_.num_joints());
  motion::SetPose(&one, 0, pose, &euler);
  return one.values;
}

VmcFrame VmcSkeleton::FrameOf(const double* row, const VmcTransform& root) const {
  motion::Motion one = motion::RestMotion(skeleton_, 1, 1.0 / 30);
  std::copy(row, row + skeleton_.num_channels(), one.values.begin());
  const motion::LocalPose pose = motion::PoseAt(one, 0);
  VmcFrame out;
  out.root = root;
  const Quat back = motion::Conjugate(root.rotation);
  for (int j = 0; j < skeleton_.num_joints(); ++j) {
    VmcTransform t;
    if (j == 0) {
      t.position = motion::Rotate(back, pose.translations[0] - root.position);
      t.rotation = motion::Normalized(back * pose.rotations[0]);
    } else {
      t.position = skeleton_.joint(j).offset;
      t.rotation = pose.rotations[j];
    }
    out.bones[skeleton_.joint(j).name] = t;
  }
  return out;
}

}  // namespace stylus::bridge
