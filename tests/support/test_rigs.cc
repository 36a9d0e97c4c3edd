#include "tests/support/test_rigs.h"

#include <map>
#include <random>

#include "absl/strings/match.h"
#include "absl/strings/str_cat.h"
#include "absl/strings/str_format.h"
#include "motion/kinematics.h"
#include "motion/resample.h"

namespace stylus::testing {
namespace {

using motion::Channel;
using motion::GlobalPose;
using motion::Joint;
using motion::LocalPose;
using motion::Motion;
using motion::Quat;
using motion::Vec3;

enum class Kind { kFollow, kBetween, kExtra, kFloor };

struct Spec {
  std::string name, parent;  // parent "" for the root.
  Kind kind = Kind::kFollow;
  std::string source;          // Bandai joint followed (kFollow, kBetween, kFloor).
  double t = 0;                // kBetween: fraction from the source's parent to it.
  double along = 0, side = 0;  // kExtra: offset along the parent's bone, and up.
  bool positions = false;      // Position channels (besides the root's).
};

struct RigPlan {
  std::vector<Spec> joints;
  double units = 1;
  bool z_up = false;
  std::string euler = "ZXY";
  double fps = 30;
  bool random_frames = false;
};

Spec F(const std::string& name, const std::string& parent, const std::string& src) {
  Spec s;
  s.name = name;
  s.parent = parent;
  s.source = src;
  return s;
}
Spec B(const std::string& name, const std::string& parent, const std::string& src, double t) {
  Spec s = F(name, parent, src);
  s.kind = Kind::kBetween;
  s.t = t;
  return s;
}
Spec X(const std::string& name, const std::string& parent, double along, double side = 0) {
  Spec s = F(name, parent, "");
  s.kind = Kind::kExtra;
  s.along = along;
  s.side = side;
  return s;
}

RigPlan Plan(TestRig rig) {
  RigPlan p;
  std::vector<Spec>& j = p.joints;
  switch (rig) {
    case TestRig::kCmu: {
      p.units = 1 / 2.54;
      p.euler = "ZYX";
      p.fps = 120;
      j.push_back(F("Hips", "", "Hips"));
      for (const char* s : {"Left", "Right"}) {
        const std::string b = std::string(s) == "Left" ? "_L" : "_R", c = std::string(1, s[0]);
        j.push_back(B(c + "HipJoint", "Hips", "UpperLeg" + b, 0));
        j.push_back(F(std::string(s) + "UpLeg", c + "HipJoint", "UpperLeg" + b));
        j.push_back(F(std::string(s) + "Leg", std::string(s) + "UpLeg", "LowerLeg" + b));
        j.push_back(F(std::string(s) + "Foot", std::string(s) + "Leg", "Foot" + b));
        j.push_back(F(std::string(s) + "ToeBase", std::string(s) + "Foot", "Toes" + b));
      }
      j.push_back(B("LowerBack", "Hips", "Spine", 0));
      j.push_back(F("Spine", "LowerBack", "Spine"));
      j.push_back(F("Spine1", "Spine", "Chest"));
      j.push_back(F("Neck", "Spine1", "Neck"));
      j.push_back(B("Neck1", "Neck", "Head", 0.5));
      j.push_back(F("Head", "Neck1", "Head"));
      for (const char* s : {"Left", "Right"}) {
        const std::string n = s, b = n == "Left" ? "_L" : "_R", c = std::string(1, s[0]);
        j.push_back(F(n + "Shoulder", "Spine1", "Shoulder" + b));
        j.push_back(F(n + "Arm", n + "Shoulder", "UpperArm" + b));
        j.push_back(F(n + "ForeArm", n + "Arm", "LowerArm" + b));
        j.push_back(F(n + "Hand", n + "ForeArm", "Hand" + b));
        j.push_back(X(n + "FingerBase", n + "Hand", 6));
        j.push_back(X(n + "HandIndex1", n + "FingerBase", 4));
        j.push_back(X(c + "Thumb", n + "Hand", 3, 2));
      }
      break;
    }
    case TestRig::kMixamo:
    case TestRig::kMixamoMetres: {
      if (rig == TestRig::kMixamoMetres) p.units = 0.01;
      p.euler = "ZYX";
      const std::string m = "mixamorig:";
      j.push_back(F(m + "Hips", "", "Hips"));
      j.push_back(B(m + "Spine", m + "Hips", "Spine", 0.5));
      j.push_back(F(m + "Spine1", m + "Spine", "Spine"));
      j.push_back(F(m + "Spine2", m + "Spine1", "Chest"));
      j.push_back(F(m + "Neck", m + "Spine2", "Neck"));
      j.push_back(F(m + "Head", m + "Neck", "Head"));
      j.push_back(X(m + "HeadTop_End", m + "Head", 15));
      for (const char* s : {"Left", "Right"}) {
        const std::string n = m + s, b = std::string(s) == "Left" ? "_L" : "_R";
        j.push_back(F(n + "Shoulder", m + "Spine2", "Shoulder" + b));
        j.push_back(F(n + "Arm", n + "Shoulder", "UpperArm" + b));
        j.push_back(F(n + "ForeArm", n + "Arm", "LowerArm" + b));
        j.push_back(F(n + "Hand", n + "ForeArm", "Hand" + b));
        j.push_back(X(n + "HandIndex1", n + "Hand", 5));
        j.push_back(X(n + "HandIndex2", n + "HandIndex1", 3));
        j.push_back(X(n + "HandThumb1", n + "Hand", 2, 2));
      }
      for (const char* s : {"Right", "Left"}) {
        const std::string n = m + s, b = std::string(s) == "Left" ? "_L" : "_R";
        j.push_back(F(n + "UpLeg", m + "Hips", "UpperLeg" + b));
        j.push_back(F(n + "Leg", n + "UpLeg", "LowerLeg" + b));
        j.push_back(F(n + "Foot", n + "Leg", "Foot" + b));
        j.push_back(F(n + "ToeBase", n + "Foot", "Toes" + b));
        j.push_back(X(n + "Toe_End", n + "ToeBase", 5));
      }
      break;
    }
    case TestRig::kRigify: {
      p.units = 0.01;
      p.z_up = true;
      p.euler = "XYZ";
      j.push_back(F("spine", "", "Hips"));
      j.push_back(F("spine.001", "spine", "Spine"));
      j.push_back(B("spine.002", "spine.001", "Chest", 0.5));
      j.push_back(F("spine.003", "spine.002", "Chest"));
      j.push_back(F("spine.004", "spine.003", "Neck"));
      j.push_back(B("spine.005", "spine.004", "Head", 0.5));
      j.push_back(F("spine.006", "spine.005", "Head"));
      for (bool arms : {true, false}) {
        for (const char* s : {"L", "R"}) {
          const std::string x = absl::StrCat(".", s), b = absl::StrCat("_", s);
          if (arms) {
            j.push_back(F("shoulder" + x, "spine.003", "Shoulder" + b));
            j.push_back(F("upper_arm" + x, "shoulder" + x, "UpperArm" + b));
            j.push_back(F("forearm" + x, "upper_arm" + x, "LowerArm" + b));
            j.push_back(F("hand" + x, "forearm" + x, "Hand" + b));
          } else {
            j.push_back(F("thigh" + x, "spine", "UpperLeg" + b));
            j.push_back(F("shin" + x, "thigh" + x, "LowerLeg" + b));
            j.push_back(F("foot" + x, "shin" + x, "Foot" + b));
            j.push_back(F("toe" + x, "foot" + x, "Toes" + b));
          }
        }
      }
      break;
    }
    case TestRig::kUnreal: {
      p.z_up = true;
      p.euler = "YZX";
      Spec root = F("root", "", "Hips");
      root.kind = Kind::kFloor;
      j.push_back(root);
      Spec pelvis = F("pelvis", "root", "Hips");
      pelvis.positions = true;
      j.push_back(pelvis);
      for (const char* s : {"l", "r"}) {
        const std::string x = absl::StrCat("_", s), b = s[0] == 'l' ? "_L" : "_R";
        j.push_back(F("thigh" + x, "pelvis", "UpperLeg" + b));
        j.push_back(X("thigh_twist_01" + x, "thigh" + x, 10));
        j.push_back(F("calf" + x, "thigh" + x, "LowerLeg" + b));
        j.push_back(F("foot" + x, "calf" + x, "Foot" + b));
        j.push_back(F("ball" + x, "foot" + x, "Toes" + b));
      }
      j.push_back(B("spine_01", "pelvis", "Spine", 0.5));
      j.push_back(F("spine_02", "spine_01", "Spine"));
      j.push_back(F("spine_03", "spine_02", "Chest"));
      for (const char* s : {"l", "r"}) {
        const std::string x = absl::StrCat("_", s), b = s[0] == 'l' ? "_L" : "_R";
        j.push_back(F("clavicle" + x, "spine_03", "Shoulder" + b));
        j.push_back(F("upperarm" + x, "clavicle" + x, "UpperArm" + b));
        j.push_back(X("upperarm_twist_01" + x, "upperarm" + x, 8));
        j.push_back(F("lowerarm" + x, "upperarm" + x, "LowerArm" + b));
        j.push_back(F("hand" + x, "lowerarm" + x, "Hand" + b));
        j.push_back(X("index_01" + x, "hand" + x, 6));
      }
      j.push_back(X("weapon_r", "hand_r", 10, 3));
      j.push_back(F("neck_01", "spine_03", "Neck"));
      j.push_back(F("head", "neck_01", "Head"));
      break;
    }
    case TestRig::kAnonymous:
    case TestRig::kReoriented:
      break;  // Built from the Bandai skeleton itself (below).
  }
  return p;
}

// The Bandai skeleton's own joints as a plan: anonymous names or turned frames.
RigPlan PlanFromBandai(const motion::Skeleton& sk, TestRig rig) {
  RigPlan p;
  for (int i = 0; i < sk.num_joints(); ++i) {
    const Joint& joint = sk.joint(i);
    auto name = [&](int k) {
      return rig == TestRig::kAnonymous ? absl::StrFormat("j%02d", k) : sk.joint(k).name;
    };
    Spec s = F(name(i), joint.parent < 0 ? "" : name(joint.parent), joint.name);
    s.positions = motion::HasPositionChannel(joint);  // Bandai's Hips carry the motion.
    p.joints.push_back(s);
  }
  p.random_frames = rig == TestRig::kReoriented;
  p.euler = rig == TestRig::kReoriented ? "XZY" : "ZXY";
  return p;
}

}  // namespace

std::string TestRigName(TestRig rig) {
  switch (rig) {
    case TestRig::kCmu:
      return "cmu";
    case TestRig::kMixamo:
      return "mixamo";
    case TestRig::kMixamoMetres:
      return "mixamo_metres";
    case TestRig::kRigify:
      return "rigify";
    case TestRig::kUnreal:
      return "unreal";
    case TestRig::kAnonymous:
      return "anonymous";
    case TestRig::kReoriented:
      return "reoriented";
  }
  return "?";
}

std::vector<TestRig> AllTestRigs() {
  return {TestRig::kCmu,    TestRig::kMixamo,    TestRig::kMixamoMetres, TestRig::kRigify,
          TestRig::kUnreal, TestRig::kAnonymous, TestRig::kReoriented};
}

std::string TestRigJoint(TestRig rig, const std::string& bandai_name) {
  motion::Skeleton none;
  RigPlan p = Plan(rig);
  if (rig == TestRig::kAnonymous || rig == TestRig::kReoriented) return "";
  for (const Spec& s : p.joints) {
    if (s.kind == Kind::kFollow && s.source == bandai_name) return s.name;
  }
  return "";
}

Motion WithoutLegs(const Motion& bandai) {
  const motion::Skeleton& sk = bandai.skeleton;
  std::vector<Joint> joints;
  std::vector<int> index(sk.num_joints(), -1), kept;
  for (int j = 0; j < sk.num_joints(); ++j) {
    const std::string& n = sk.joint(j).name;
    if (absl::StrContains(n, "Leg") || absl::StrContains(n, "Foot") ||
        absl::StrContains(n, "Toes")) {
      continue;
    }
    Joint copy = sk.joint(j);
    copy.parent = copy.parent < 0 ? -1 : index[copy.parent];
    index[j] = static_cast<int>(joints.size());
    joints.push_back(copy);
    kept.push_back(j);
  }
  Motion out =
      motion::RestMotion(*motion::Skeleton::Create(joints), bandai.num_frames, bandai.frame_time);
  for (int f = 0; f < bandai.num_frames; ++f) {
    int at = 0;
    for (int j : kept) {
      const int n = static_cast<int>(sk.joint(j).channels.size());
      for (int c = 0; c < n; ++c) out.frame(f)[at + c] = bandai.frame(f)[sk.channel_start(j) + c];
      at += n;
    }
  }
  return out;
}

absl::StatusOr<Motion> BuildTestRig(const Motion& bandai_clip, TestRig rig) {
  RigPlan plan = (rig == TestRig::kAnonymous || rig == TestRig::kReoriented)
                     ? PlanFromBandai(bandai_clip.skeleton, rig)
                     : Plan(rig);
  const Motion clip =
      plan.fps != bandai_clip.fps() ? motion::Resample(bandai_clip, 1.0 / plan.fps) : bandai_clip;
  const motion::Skeleton& src = clip.skeleton;
  const int n = static_cast<int>(plan.joints.size());
  std::map<std::string, int> index;
  std::vector<int> parent(n, -1), source(n, -1);
  for (int i = 0; i < n; ++i) {
    const Spec& s = plan.joints[i];
    index[s.name] = i;
    if (!s.parent.empty()) parent[i] = index.at(s.parent);
    if (!s.source.empty()) source[i] = *src.Find(s.source);
  }
  // World transforms of every new joint in every frame.
  const Quat g = plan.z_up ? motion::AxisAngle({1, 0, 0}, M_PI / 2) : Quat{};
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  std::vector<Quat> frame0(n);  // Wanted world rotation at frame 0.
  for (int i = 0; i < n; ++i) {
    frame0[i] = plan.random_frames
                    ? motion::Normalized(Quat{normal(rng), normal(rng), normal(rng), normal(rng)})
                    : Quat{};
  }
  std::vector<std::vector<Vec3>> P(clip.num_frames, std::vector<Vec3>(n));
  std::vector<std::vector<Quat>> R(clip.num_frames, std::vector<Quat>(n));
  std::vector<Quat> attach(n);  // Rotation from the followed frame to the new one.
  std::vector<Vec3> extra_local(n);
  for (int f = 0; f < clip.num_frames; ++f) {
    const GlobalPose w = motion::ForwardKinematics(src, motion::PoseAt(clip, f));
    for (int i = 0; i < n; ++i) {
      const Spec& s = plan.joints[i];
      Vec3 pos;
      Quat base;
      switch (s.kind) {
        case Kind::kFollow:
          pos = w.positions[source[i]];
          base = w.rotations[source[i]];
          break;
        case Kind::kBetween: {
          const int sp = src.joint(source[i]).parent;
          pos = w.positions[sp] + s.t * (w.positions[source[i]] - w.positions[sp]);
          base = w.rotations[sp];
          break;
        }
        case Kind::kFloor:
          pos = w.positions[source[i]];
          pos.y = 0;
          break;
        case Kind::kExtra: {
          const int p = parent[i];
          if (f == 0) {
            // Along the parent's bone (from its parent), lifted by `side`.
            const int pp = parent[p];
            const Vec3 dir =
                motion::Normalized(P[0][p] - (pp >= 0 ? P[0][pp] : P[0][p] - Vec3{0, 1, 0}));
            Vec3 up = motion::Normalized(motion::Cross(dir, {0, 0, 1}), {0, 1, 0});
            const Vec3 world = s.along * dir + s.side * up;
            extra_local[i] = motion::Rotate(motion::Conjugate(R[0][p]), world);
          }
          pos = P[f][p] + motion::Rotate(R[f][p], extra_local[i]);
          base = R[f][p];
          break;
        }
      }
      if (f == 0) attach[i] = motion::Conjugate(base) * frame0[i];
      P[f][i] = pos;
      R[f][i] = motion::Normalized(base * attach[i]);
    }
  }
  // Into the rig's space: up axis and units.
  for (int f = 0; f < clip.num_frames; ++f) {
    for (int i = 0; i < n; ++i) {
      P[f][i] = plan.units * motion::Rotate(g, P[f][i]);
      R[f][i] = g * R[f][i];
    }
  }
  absl::StatusOr<motion::EulerOrder> order = motion::EulerOrder::Parse(plan.euler);
  if (!order.ok()) return order.status();
  std::vector<Joint> joints(n);
  for (int i = 0; i < n; ++i) {
    Joint& j = joints[i];
    j.name = plan.joints[i].name;
    j.parent = parent[i];
    const int p = parent[i];
    j.offset = p < 0 ? P[0][i] : motion::Rotate(motion::Conjugate(R[0][p]), P[0][i] - P[0][p]);
    if (p < 0 || plan.joints[i].positions) {
      j.channels = {Channel::kXposition, Channel::kYposition, Channel::kZposition};
    }
    for (int k = 0; k < 3; ++k) {
      j.channels.push_back(static_cast<Channel>(3 + order->axes[k]));
    }
  }
  for (int i = 0; i < n; ++i) {
    bool leaf = true;
    for (int k = 0; k < n; ++k) leaf &= parent[k] != i;
    if (!leaf) continue;
    const int p = parent[i];
    const double len = p < 0 ? 1 : std::max(2 * plan.units, 0.25 * motion::Norm(joints[i].offset));
    const Vec3 dir = p < 0 ? Vec3{0, 1, 0} : P[0][i] - P[0][p];
    joints[i].end_sites.push_back(
        motion::Rotate(motion::Conjugate(R[0][i]), len * motion::Normalized(dir)));
  }
  absl::StatusOr<motion::Skeleton> skeleton = motion::Skeleton::Create(std::move(joints));
  if (!skeleton.ok()) return skeleton.status();
  Motion out = motion::RestMotion(*skeleton, clip.num_frames, clip.frame_time);
  std::vector<Vec3> euler(n);
  for (int f = 0; f < clip.num_frames; ++f) {
    LocalPose pose = motion::PoseAt(out, f);
    for (int i = 0; i < n; ++i) {
      const int p = parent[i];
      pose.rotations[i] = p < 0 ? R[f][i] : motion::Conjugate(R[f][p]) * R[f][i];
      if (p < 0) {
        pose.translations[i] = P[f][i];
      } else if (plan.joints[i].positions) {
        pose.translations[i] = motion::Rotate(motion::Conjugate(R[f][p]), P[f][i] - P[f][p]);
      }
    }
    motion::SetPose(&out, f, pose, &euler);
  }
  return out;
}

}  // namespace stylus::testing
