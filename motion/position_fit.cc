#include "motion/position_fit.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

namespace stylus::motion {
namespace {

constexpr double kTiny = 1e-9;

Vec3 Get3(const float* p) { return {p[0], p[1], p[2]}; }
void Set3(float* p, const Vec3& v) {
  p[0] = static_cast<float>(v.x);
  p[1] = static_cast<float>(v.y);
  p[2] = static_cast<float>(v.z);
}
Quat Get4(const float* p) { return Normalized(Quat{p[0], p[1], p[2], p[3]}); }
void Set4(float* p, const Quat& q) {
  p[0] = static_cast<float>(q.w);
  p[1] = static_cast<float>(q.x);
  p[2] = static_cast<float>(q.y);
  p[3] = static_cast<float>(q.z);
}

// The rotation `global` of a joint at `origin` that points its children's
// offsets at their targets: for one child the smallest turn from the current
// rotation (its twist is kept); for several, the least-squares rotation over
// all of them, weighted by bone length (Horn's quaternion method).
Quat AlignChildren(const Quat& global, const Vec3& origin, const std::vector<int>& children,
                   const Skeleton& skeleton, const float* row, const FeatureLayout& layout) {
  std::vector<std::pair<Vec3, Vec3>> pairs;  // (weighted offset, unit target)
  for (int c : children) {
    const Vec3& offset = skeleton.joint(c).offset;
    const Vec3 target = Get3(row + layout.position(c)) - origin;
    if (Norm(offset) < kTiny || Norm(target) < kTiny) continue;
    pairs.push_back({offset, Normalized(target)});
  }
  if (pairs.empty()) return global;
  if (pairs.size() == 1) {
    return Normalized(RotationBetween(Rotate(global, pairs[0].first), pairs[0].second) * global);
  }
  return SameHemisphere(BestRotation(pairs), global);
}

// A joint that turns about one axis of its parent's frame through the clip
// (a knee): its local rotations' vector parts all lie along `axis` (within
// kHingeSlack) and it bends somewhere (so the axis is known).
struct Hinge {
  bool is = false;
  Vec3 axis;
};
constexpr double kHingeSlack = 0.02;  // Off-axis part of the quaternion: ~2.3 degrees.

Hinge FindHinge(const FeatureClip& features, const FeatureLayout& layout, int joint) {
  Vec3 sum;
  for (int f = 0; f < features.frames; ++f) {
    const Quat q = Get4(features.row(f) + layout.rotation(joint));
    const double sign = q.w < 0 ? -1 : 1;
    sum = sum + Vec3{q.x, q.y, q.z} * sign;
  }
  Hinge h;
  if (Norm(sum) < 1e-3 * features.frames) return h;  // Never bends: no axis to trust.
  h.axis = Normalized(sum);
  for (int f = 0; f < features.frames; ++f) {
    const Quat q = Get4(features.row(f) + layout.rotation(joint));
    const Vec3 v{q.x, q.y, q.z};
    if (Norm(v - h.axis * Dot(v, h.axis)) > kHingeSlack) return h;
  }
  h.is = true;
  return h;
}

// The hinge angle (about unit `axis`) that puts a child at `child_offset`
// (in the hinge joint's frame) `distance` away from the parent joint, whose
// hinge joint sits at `offset` (in the parent's frame); of the two, the one
// nearest `current`. Out of reach: the nearest reachable angle.
double HingeAngle(const Vec3& offset, const Vec3& child_offset, const Vec3& axis, double distance,
                  double current) {
  // |offset + R(axis, t) child|^2 = |o|^2 + |c|^2 + 2 (A cos t + B sin t + C).
  const double uo = Dot(axis, offset), uc = Dot(axis, child_offset);
  const double a = Dot(offset, child_offset) - uo * uc;
  const double b = Dot(offset, Cross(axis, child_offset));
  const double c = uo * uc;
  const double r = std::sqrt(a * a + b * b);
  if (r < kTiny) return current;
  const double d =
      (distance * distance - Dot(offset, offset) - Dot(child_offset, child_offset)) / 2 - c;
  const double phi = std::atan2(b, a), spread = std::acos(std::clamp(d / r, -1.0, 1.0));
  const auto wrap = [](double t) { return std::remainder(t, 2 * M_PI); };
  const double t1 = wrap(phi + spread), t2 = wrap(phi - spread);
  return std::fabs(wrap(t1 - current)) <= std::fabs(wrap(t2 - current)) ? t1 : t2;
}

}  // namespace

void FitRotationsToPositions(const Skeleton& skeleton, const HumanoidRoles& roles,
                             FeatureClip* features, const FeatureClip* hinge_reference) {
  const int joints = skeleton.num_joints();
  const FeatureLayout layout(joints);
  // Joints at or below the pelvis, parents first (file order is depth-first).
  std::vector<bool> below(joints, false);
  below[roles.pelvis] = true;
  for (int j = roles.pelvis + 1; j < joints; ++j) {
    const int p = skeleton.joint(j).parent;
    below[j] = p >= 0 && below[p];
  }
  // Hinges (knees): a joint with one child, alone under its parent (itself
  // no hinge), that turns about one axis in the rotations the features start
  // with. Its parent is then fitted as a two-bone chain and the hinge keeps
  // its axis, so a generated pose never twists a knee sideways.
  std::vector<Hinge> hinge(joints);
  for (int j = roles.pelvis + 1; j < joints; ++j) {
    const int p = skeleton.joint(j).parent;
    // A hinge's own child is never one: its parent (the hinge) is placed by
    // the chain above it.
    if (!below[j] || p <= roles.pelvis || skeleton.children(j).size() != 1 ||
        skeleton.children(p).size() != 1 || hinge[p].is)
      continue;
    hinge[j] = FindHinge(hinge_reference != nullptr ? *hinge_reference : *features, layout, j);
  }
  std::vector<Quat> global(joints), previous(joints), hinge_local(joints);
  std::vector<Vec3> position(joints);
  for (int f = 0; f < features->frames; ++f) {
    float* row = features->row(f);
    for (int j = roles.pelvis; j < joints; ++j) {
      if (!below[j]) continue;
      const int p = skeleton.joint(j).parent;
      const Quat local = Get4(row + layout.rotation(j));
      if (j == roles.pelvis) {
        position[j] = Get3(row + layout.position(j));
        global[j] = local;  // Relative to the facing frame, as the features store it.
      } else {
        position[j] = position[p] + Rotate(global[p], skeleton.joint(j).offset);
        global[j] = hinge[j].is ? global[p] * hinge_local[j] : global[p] * local;
      }
      const std::vector<int>& children = skeleton.children(j);
      if (children.size() == 1 && hinge[children[0]].is) {
        // Two-bone chain j -> hinge k -> end e: the hinge angle that gives
        // the end's distance, then the rotation of j that points the chain
        // at the end's target with the hinge joint nearest its own.
        const int k = children[0], e = skeleton.children(k)[0];
        const Vec3& axis = hinge[k].axis;
        const Quat k_local = Get4(row + layout.rotation(k));
        const double current =
            2 * std::atan2(Dot(Vec3{k_local.x, k_local.y, k_local.z}, axis), k_local.w);
        const Vec3 to_k = Get3(row + layout.position(k)) - position[j];
        const Vec3 to_e = Get3(row + layout.position(e)) - position[j];
        const Vec3& o_k = skeleton.joint(k).offset;
        const Vec3& o_e = skeleton.joint(e).offset;
        const double angle = HingeAngle(o_k, o_e, axis, Norm(to_e), current);
        hinge_local[k] = AxisAngle(axis, angle);
        const Vec3 chain = o_k + Rotate(hinge_local[k], o_e);  // j -> e in j's frame.
        if (Norm(to_e) > kTiny && Norm(chain) > kTiny) {
          // The end first (it points at its target), then a turn about the
          // j -> end line that brings the hinge joint nearest its own target.
          const Vec3 line = Normalized(to_e);
          global[j] = Normalized(RotationBetween(Rotate(global[j], chain), line) * global[j]);
          const Vec3 now = Rotate(global[j], o_k), want = to_k;
          const Vec3 a = now - line * Dot(now, line), b = want - line * Dot(want, line);
          if (Norm(a) > 1e-6 * Norm(o_k) && Norm(b) > 1e-6 * Norm(o_k)) {
            const double turn = std::atan2(Dot(Cross(a, b), line), Dot(a, b));
            global[j] = Normalized(AxisAngle(line, turn) * global[j]);
          }
        } else {
          global[j] = AlignChildren(global[j], position[j], children, skeleton, row, layout);
        }
      } else if (!children.empty() && !hinge[j].is) {
        global[j] = AlignChildren(global[j], position[j], children, skeleton, row, layout);
      }
      Quat fitted = j == roles.pelvis ? global[j] : Normalized(Conjugate(global[p]) * global[j]);
      if (f > 0) fitted = SameHemisphere(fitted, previous[j]);
      previous[j] = fitted;
      Set4(row + layout.rotation(j), fitted);
      Set3(row + layout.position(j), position[j]);
    }
  }
}

}  // namespace stylus::motion
