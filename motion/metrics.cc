#include "motion/metrics.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "motion/contacts.h"
#include "motion/kinematics.h"
#include "motion/postprocess.h"
#include "motion/rig_roles.h"

namespace stylus::motion {
namespace {

double Length(const Vec3& v) { return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z); }

}  // namespace

namespace {

// contacts[f][k]: foot joint k of `reference` is in one of its contact spans.
std::vector<std::array<bool, 4>> Contacts(const std::vector<std::vector<Vec3>>& ref,
                                          const HumanoidRoles& roles, double fps) {
  std::vector<std::array<bool, 4>> out(ref.size(), {false, false, false, false});
  const auto spans = DetectContactSpans(ref, roles, fps);
  for (int k = 0; k < 4; ++k) {
    for (const ContactSpan& s : spans[k]) {
      for (int f = s.begin; f < s.end; ++f) out[f][k] = true;
    }
  }
  return out;
}

}  // namespace

double FootSkating(const Motion& clip, const Motion& reference, const HumanoidRoles& roles) {
  const auto pos = GlobalPositions(clip);
  const auto contacts = Contacts(GlobalPositions(reference), roles, reference.fps());
  const auto feet = FootJoints(roles);
  double sum = 0;
  int n = 0;
  for (size_t f = 1; f < pos.size() && f < contacts.size(); ++f) {
    for (int k = 0; k < 4; ++k) {
      if (!contacts[f][k] || !contacts[f - 1][k]) continue;
      const Vec3 d = pos[f][feet[k]] - pos[f - 1][feet[k]];
      sum += std::hypot(d.x, d.z) * clip.fps();
      ++n;
    }
  }
  return n ? sum / n : 0;
}

double FootSkatingOnSpans(const Motion& clip, const std::array<std::vector<ContactSpan>, 4>& spans,
                          const HumanoidRoles& roles) {
  const auto pos = GlobalPositions(clip);
  const auto feet = FootJoints(roles);
  const int n = static_cast<int>(pos.size());
  double sum = 0;
  int count = 0;
  for (int k = 0; k < 4; ++k) {
    for (const ContactSpan& s : spans[k]) {
      for (int f = std::max(1, s.begin + 1); f < std::min(n, s.end); ++f) {
        const Vec3 d = pos[f][feet[k]] - pos[f - 1][feet[k]];
        sum += std::hypot(d.x, d.z) * clip.fps();
        ++count;
      }
    }
  }
  return count ? sum / count : 0;
}

double FootHeightError(const Motion& clip, const Motion& reference, const HumanoidRoles& roles) {
  const auto ref = GlobalPositions(reference);
  const auto pos = GlobalPositions(clip);
  const auto contacts = Contacts(ref, roles, reference.fps());
  const auto feet = FootJoints(roles);
  double sum = 0;
  int n = 0;
  for (int k = 0; k < 4; ++k) {
    double floor = 1e300;
    for (const auto& p : ref) floor = std::min(floor, p[feet[k]].y);
    for (size_t f = 0; f < pos.size() && f < contacts.size(); ++f) {
      if (!contacts[f][k]) continue;
      sum += std::abs(pos[f][feet[k]].y - floor);
      ++n;
    }
  }
  return n ? sum / n : 0;
}

double BoneLengthError(const Motion& clip, const HumanoidRoles& roles) {
  const Skeleton& sk = clip.skeleton;
  const auto pos = GlobalPositions(clip);
  std::vector<bool> below(sk.num_joints(), false);
  double sum = 0;
  int n = 0;
  for (int j = 1; j < sk.num_joints(); ++j) {
    const int p = sk.joint(j).parent;
    below[j] = p == roles.pelvis || below[p];
    const double rest = Length(sk.joint(j).offset);
    if (!below[j] || rest < 1e-9) continue;
    for (const auto& frame : pos) {
      sum += std::abs(Length(frame[j] - frame[p]) - rest) / rest;
      ++n;
    }
  }
  return n ? sum / n : 0;
}

double Jitter(const Motion& clip) {
  const auto pos = GlobalPositions(clip);
  const double fps3 = clip.fps() * clip.fps() * clip.fps();
  double sum = 0;
  int n = 0;
  for (size_t f = 3; f < pos.size(); ++f) {
    for (size_t j = 0; j < pos[f].size(); ++j) {
      const Vec3 jerk = pos[f][j] - pos[f - 1][j] * 3.0 + pos[f - 2][j] * 3.0 - pos[f - 3][j];
      sum += Length(jerk) * fps3;
      ++n;
    }
  }
  return n ? sum / n : 0;
}

double TrajectoryError(const Motion& clip, const Motion& reference, const HumanoidRoles& roles) {
  const auto a = GlobalPositions(clip);
  const auto b = GlobalPositions(reference);
  const size_t n = std::min(a.size(), b.size());
  double sum = 0;
  for (size_t f = 0; f < n; ++f) {
    const Vec3 d = a[f][roles.pelvis] - b[f][roles.pelvis];
    sum += std::hypot(d.x, d.z);
  }
  return n ? sum / n : 0;
}

double MaxEulerStep(const Motion& clip) {
  const Skeleton& sk = clip.skeleton;
  double worst = 0;
  for (int f = 1; f < clip.num_frames; ++f) {
    for (int j = 0; j < sk.num_joints(); ++j) {
      const Joint& joint = sk.joint(j);
      for (size_t c = 0; c < joint.channels.size(); ++c) {
        if (IsPosition(joint.channels[c])) continue;
        const int i = sk.channel_start(j) + static_cast<int>(c);
        worst = std::max(worst, std::abs(clip.frame(f)[i] - clip.frame(f - 1)[i]));
      }
    }
  }
  return worst;
}

int EulerDiscontinuities(const Motion& clip) {
  const Skeleton& sk = clip.skeleton;
  int count = 0;
  LocalPose prev = clip.num_frames > 0 ? PoseAt(clip, 0) : LocalPose{};
  for (int f = 1; f < clip.num_frames; ++f) {
    LocalPose pose = PoseAt(clip, f);
    for (int j = 0; j < sk.num_joints(); ++j) {
      const Joint& joint = sk.joint(j);
      double step = 0;
      for (size_t c = 0; c < joint.channels.size(); ++c) {
        if (IsPosition(joint.channels[c])) continue;
        const int i = sk.channel_start(j) + static_cast<int>(c);
        step = std::max(step, std::abs(clip.frame(f)[i] - clip.frame(f - 1)[i]));
      }
      if (step > 90 && AngleBetween(pose.rotations[j], prev.rotations[j]) < M_PI / 4) ++count;
    }
    prev = std::move(pose);
  }
  return count;
}

absl::StatusOr<std::map<std::string, double>> ComputeMetrics(const Motion& clip,
                                                             const Motion* reference) {
  if (clip.num_frames <= 0) return absl::InvalidArgumentError("the clip has no frames");
  absl::StatusOr<HumanoidRoles> roles = HumanoidRolesOf(clip);
  if (!roles.ok()) return roles.status();
  if (reference != nullptr) {
    if (!reference->skeleton.SameTopology(clip.skeleton)) {
      return absl::InvalidArgumentError(
          absl::StrCat("the reference clip is on another skeleton: ",
                       clip.skeleton.DescribeMismatch(reference->skeleton)));
    }
    if (reference->num_frames <= 0) {
      return absl::InvalidArgumentError("the reference clip has no frames");
    }
  }
  const Motion& ref = reference ? *reference : clip;
  std::map<std::string, double> m;
  m["foot_skating"] = FootSkating(clip, ref, *roles);
  m["foot_height_error"] = FootHeightError(clip, ref, *roles);
  m["bone_length_error"] = BoneLengthError(clip, *roles);
  m["jitter"] = Jitter(clip);
  m["max_euler_step_deg"] = MaxEulerStep(clip);
  m["euler_discontinuities"] = EulerDiscontinuities(clip);
  if (reference) m["trajectory_error"] = TrajectoryError(clip, ref, *roles);
  return m;
}

}  // namespace stylus::motion
