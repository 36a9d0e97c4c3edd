#include "motion/aim_fit.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "motion/ik.h"

namespace stylus::motion {
namespace {

constexpr double kTiny = 1e-9;

// True when the differences' directions, both as they are and as wanted,
// span a plane (two of them at least ~6 degrees apart): then they fix a
// rotation, else its turn about their common line is left to rounding.
bool Spans(const std::vector<std::pair<Vec3, Vec3>>& diffs) {
  auto spans = [&](bool wanted) {
    for (size_t a = 0; a < diffs.size(); ++a) {
      for (size_t b = a + 1; b < diffs.size(); ++b) {
        const Vec3 x = wanted ? diffs[a].second : Normalized(diffs[a].first);
        const Vec3 y = wanted ? diffs[b].second : Normalized(diffs[b].first);
        if (Norm(Cross(x, y)) > 0.1) return true;
      }
    }
    return false;
  };
  return spans(false) && spans(true);
}

}  // namespace

AimPlan::AimPlan(const Skeleton& skeleton, const RigRoles& roles, const std::vector<char>& targeted)
    : skeleton_(skeleton), pelvis_(roles[Role::kPelvis]) {
  const int n = skeleton.num_joints();
  above_pelvis_.assign(n, false);
  for (int p = pelvis_ >= 0 ? skeleton.joint(pelvis_).parent : -1; p >= 0;
       p = skeleton.joint(p).parent) {
    above_pelvis_[p] = true;
  }
  for (int j = pelvis_; j >= 0 && mover_ < 0; j = skeleton.joint(j).parent) {
    if (HasPositionChannel(skeleton.joint(j))) mover_ = j;
  }
  // The nearest targeted joint at or below each joint (parents come first,
  // so a reverse pass sees children before their parent).
  std::vector<int> near(n, -1), depth(n, 0);
  for (int j = n - 1; j >= 0; --j) {
    if (targeted[j]) {
      near[j] = j;
      continue;
    }
    for (int c : skeleton.children(j)) {
      if (near[c] >= 0 && (near[j] < 0 || depth[c] + 1 < depth[j])) {
        near[j] = near[c];
        depth[j] = depth[c] + 1;
      }
    }
  }
  aims_.assign(n, {});
  fitted_.assign(n, false);
  twist_.assign(n, false);
  for (int j = 0; j < n; ++j) {
    if (above_pelvis_[j]) continue;
    for (int c : skeleton.children(j)) {
      if (near[c] >= 0) aims_[j].push_back(near[c]);
    }
    if (targeted[n + j] && !skeleton.joint(j).end_sites.empty()) aims_[j].push_back(n + j);
    fitted_[j] = skeleton.has_rotation(j) && !aims_[j].empty();
  }
  for (Role r : {Role::kLeftThigh, Role::kRightThigh, Role::kLeftUpperArm, Role::kRightUpperArm}) {
    if (roles.has(r)) twist_[roles[r]] = true;
  }
  const Role legs[2][3] = {{Role::kLeftThigh, Role::kLeftShin, Role::kLeftFoot},
                           {Role::kRightThigh, Role::kRightShin, Role::kRightFoot}};
  if (roles.has(Role::kLeftThigh) && roles.has(Role::kRightThigh) &&
      targeted[roles[Role::kLeftThigh]] && targeted[roles[Role::kRightThigh]] && mover_ >= 0) {
    hips_ = {roles[Role::kLeftThigh], roles[Role::kRightThigh]};
  }
  for (const auto& leg : legs) {
    if (!roles.has(leg[0]) || !roles.has(leg[1]) || !roles.has(leg[2])) continue;
    if (!targeted[roles[leg[2]]]) continue;
    legs_.push_back({roles[leg[0]], roles[leg[1]], roles[leg[2]]});
    for (Role r : leg) fitted_[roles[r]] = fitted_[roles[r]] || skeleton.has_rotation(roles[r]);
  }
}

Vec3 AimPlan::OffsetFrom(int j, int aim, const LocalPose& pose) const {
  const int n = skeleton_.num_joints();
  Vec3 v;
  int k;
  if (aim >= n) {
    k = aim - n;
    v = skeleton_.joint(k).end_sites[0];
  } else {
    v = pose.translations[aim];
    k = skeleton_.joint(aim).parent;
  }
  while (k != j && k >= 0) {
    v = pose.translations[k] + Rotate(pose.rotations[k], v);
    k = skeleton_.joint(k).parent;
  }
  return v;
}

void AimPlan::PlaceHips(const AimTargets& targets, int pelvis, const std::vector<Quat>& wr,
                        std::vector<Vec3>* wp, LocalPose* pose) const {
  Vec3 now, want;
  for (int hip : hips_) {
    now = now + 0.5 * ((*wp)[pelvis] + Rotate(wr[pelvis], OffsetFrom(pelvis, hip, *pose)));
    want = want + 0.5 * targets.position[hip];
  }
  const Vec3 delta = want - now;
  const int p = skeleton_.joint(mover_).parent;
  pose->translations[mover_] =
      pose->translations[mover_] + (p < 0 ? delta : Rotate(Conjugate(wr[p]), delta));
  (*wp)[pelvis] = (*wp)[pelvis] + delta;
}

void AimPlan::Fit(const AimTargets& targets, LocalPose* pose) const {
  const int n = skeleton_.num_joints();
  std::vector<Quat> wr(n);
  std::vector<Vec3> wp(n);
  auto forward = [&](int j) {
    const int p = skeleton_.joint(j).parent;
    wr[j] = p < 0 ? pose->rotations[j] : wr[p] * pose->rotations[j];
    wp[j] = p < 0 ? pose->translations[j] : wp[p] + Rotate(wr[p], pose->translations[j]);
  };
  if (pelvis_ >= 0 && mover_ >= 0 && targets.has[pelvis_]) {
    for (int j = 0; j <= pelvis_; ++j) forward(j);
    const int p = skeleton_.joint(mover_).parent;
    const Vec3 delta = targets.position[pelvis_] - wp[pelvis_];
    pose->translations[mover_] =
        pose->translations[mover_] + (p < 0 ? delta : Rotate(Conjugate(wr[p]), delta));
  }
  std::vector<Vec3> shift(n);  // Target minus position of the nearest targeted joint.
  for (int j = 0; j < n; ++j) {
    forward(j);
    const int parent = skeleton_.joint(j).parent;
    shift[j] = targets.has[j] ? targets.position[j] - wp[j] : (parent < 0 ? Vec3{} : shift[parent]);
    if (!fitted_[j] || aims_[j].empty()) continue;
    // Directions run from the joint's own target when it has one (the
    // rig's bone directions, whatever the lengths), else from where it is
    // relative to the nearest targeted joint above it.
    const Vec3 origin = wp[j] + shift[j];
    std::vector<std::pair<Vec3, Vec3>> pairs;
    std::vector<int> used;
    for (int a : aims_[j]) {
      const Vec3 v = Rotate(wr[j], OffsetFrom(j, a, *pose));
      const Vec3 w = targets.position[a] - origin;
      if (Norm(v) < kTiny || Norm(w) < kTiny) continue;
      pairs.push_back({v, Normalized(w)});
      used.push_back(a);
    }
    if (pairs.empty()) continue;
    Quat q;
    if (pairs.size() == 1) {
      q = RotationBetween(pairs[0].first, pairs[0].second);
      const int a = used[0];
      if (twist_[j] && a < n) {
        // Turn about the limb so the next joint's target is in its plane.
        const Vec3 axis = pairs[0].second;
        for (int b : aims_[a]) {
          const Vec3 u = Rotate(q * wr[j], OffsetFrom(j, b, *pose));
          const Vec3 t = targets.position[b] - origin;
          const Vec3 u_perp = u - Dot(u, axis) * axis, t_perp = t - Dot(t, axis) * axis;
          const double bend = std::min(Norm(u_perp) / std::max(Norm(u), kTiny),
                                       Norm(t_perp) / std::max(Norm(t), kTiny));
          const double weight = std::clamp((bend - 0.05) / 0.15, 0.0, 1.0);
          if (weight <= 0) continue;
          const double angle = std::atan2(Dot(Cross(u_perp, t_perp), axis), Dot(u_perp, t_perp));
          q = AxisAngle(axis, angle * weight) * q;
          break;
        }
      }
    } else {
      // Several aims (pelvis: spine and hips; chest: neck and clavicles):
      // the differences between them, which do not depend on where the
      // joint itself sits among them (rigs place hip joints lower or wider
      // below the pelvis; the line between them still runs left-right).
      auto differences = [&](const std::vector<int>& aims) {
        std::vector<std::pair<Vec3, Vec3>> diffs;
        for (size_t a = 0; a < aims.size(); ++a) {
          for (size_t b = a + 1; b < aims.size(); ++b) {
            const Vec3 v =
                Rotate(wr[j], OffsetFrom(j, aims[a], *pose) - OffsetFrom(j, aims[b], *pose));
            const Vec3 w = targets.position[aims[a]] - targets.position[aims[b]];
            if (Norm(v) > kTiny && Norm(w) > kTiny) diffs.push_back({v, Normalized(w)});
          }
        }
        return diffs;
      };
      std::vector<std::pair<Vec3, Vec3>> diffs = differences(used);
      if (!Spans(diffs)) {
        // The aims sit on one line (a rig whose two clavicles share one
        // place): the turn about it is left to rounding. The targeted
        // joints one step further (the upper arms beyond the clavicles)
        // say it.
        std::vector<int> further = used;
        for (int a : used) {
          if (a >= n) continue;
          for (int b : aims_[a]) {
            if (b < n && targets.has[b]) further.push_back(b);
          }
        }
        diffs = differences(further);
      }
      q = BestRotation(diffs.size() >= 2 ? diffs : pairs);
    }
    wr[j] = Normalized(q * wr[j]);
    const int p = skeleton_.joint(j).parent;
    pose->rotations[j] = p < 0 ? wr[j] : Normalized(Conjugate(wr[p]) * wr[j]);
    if (j == pelvis_ && mover_ >= 0 && hips_[0] >= 0) {
      PlaceHips(targets, j, wr, &wp, pose);
      if (targets.has[j]) shift[j] = targets.position[j] - wp[j];
    }
  }
  for (const auto& [thigh, shin, foot] : legs_) {
    const TwoBoneResult ik = SolveTwoBone(wp[thigh], wp[shin], wp[foot], targets.position[foot]);
    const int pt = skeleton_.joint(thigh).parent, ps = skeleton_.joint(shin).parent,
              pf = skeleton_.joint(foot).parent;
    const Quat parent_thigh = pt < 0 ? Quat{} : wr[pt];
    pose->rotations[thigh] = Normalized(Conjugate(parent_thigh) * ik.hip_delta * wr[thigh]);
    pose->rotations[shin] = Normalized(Conjugate(ik.hip_delta * wr[ps]) * ik.knee_delta * wr[shin]);
    pose->rotations[foot] = Normalized(Conjugate(ik.knee_delta * wr[pf]) * wr[foot]);
  }
}

}  // namespace stylus::motion
