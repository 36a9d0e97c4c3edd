#include "motion/gait.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/str_cat.h"
#include "motion/features.h"
#include "motion/kinematics.h"

namespace stylus::motion {

namespace {

// The value below which `share` of `v` lies (nearest rank).
double Percentile(std::vector<double> v, double share) {
  std::sort(v.begin(), v.end());
  const size_t i = static_cast<size_t>(std::lround(share * (v.size() - 1)));
  return v[std::min(i, v.size() - 1)];
}

double Spread(const std::vector<double>& v) { return Percentile(v, 0.95) - Percentile(v, 0.05); }

// How many joints hang below joint `j`.
double Ahead(const Vec3& p, const Vec3& pelvis, const Vec3& facing) {
  return (p.x - pelvis.x) * facing.x + (p.z - pelvis.z) * facing.z;
}

}  // namespace

absl::StatusOr<Gait> MeasureGait(const Motion& clip, const HumanoidRoles& roles) {
  if (clip.num_frames <= 0) return absl::InvalidArgumentError("the clip has no frames");
  if (roles.leg_length <= 0) return absl::InvalidArgumentError("the rig's legs have no length");
  const Skeleton& sk = clip.skeleton;
  int hand = roles.left_shoulder;
  for (int step = 0; step < 2; ++step) {
    if (sk.children(hand).empty()) {
      return absl::InvalidArgumentError(absl::StrCat(
          "the left arm ends at '", sk.joint(hand).name, "': no hand two joints below '",
          sk.joint(roles.left_shoulder).name, "'"));
    }
    hand = MainChild(sk, hand);  // Not a twist bone or a prop.
  }
  const std::vector<std::vector<Vec3>> p = GlobalPositionsYUp(clip, roles.up_axis);
  const double unit = 1.0 / roles.leg_length;
  Gait g;
  GaitCurves& c = g.curves;
  c.frame_time = clip.frame_time;
  double lowest_foot = p[0][roles.left_ankle].y, mean_pelvis = 0, path = 0;
  for (size_t f = 0; f < p.size(); ++f) {
    lowest_foot = std::min(lowest_foot, p[f][roles.left_ankle].y);
    mean_pelvis += p[f][roles.pelvis].y / p.size();
    if (f > 0) {
      const Vec3 d = p[f][roles.pelvis] - p[f - 1][roles.pelvis];
      path += std::hypot(d.x, d.z);
    }
  }
  for (const std::vector<Vec3>& frame : p) {
    const Vec3& pelvis = frame[roles.pelvis];
    const double yaw = FacingYaw(frame, roles);
    const Vec3 facing{std::sin(yaw), 0, std::cos(yaw)};
    c.foot_forward.push_back(unit * Ahead(frame[roles.left_ankle], pelvis, facing));
    c.foot_height.push_back(unit * (frame[roles.left_ankle].y - lowest_foot));
    c.hand_forward.push_back(unit * Ahead(frame[hand], pelvis, facing));
    c.pelvis_height.push_back(unit * (pelvis.y - mean_pelvis));
  }
  GaitSummary& s = g.summary;
  s.stride = Spread(c.foot_forward);
  s.foot_lift = Spread(c.foot_height);
  s.arm_swing = Spread(c.hand_forward);
  s.bob = Spread(c.pelvis_height);
  const double duration = (clip.num_frames - 1) * clip.frame_time;
  s.speed = duration > 0 ? unit * path / duration : 0;
  absl::StatusOr<Cadence> cadence = FindCadence(p, clip.frame_time, roles);
  if (cadence.ok()) {
    s.cadence = *cadence;
  } else if (!absl::IsNotFound(cadence.status())) {
    return cadence.status();
  }
  return g;
}

}  // namespace stylus::motion
