#include "motion/ik.h"

#include <algorithm>
#include <cmath>

namespace stylus::motion {
namespace {

// The hinge of the current pose: perpendicular to the plane of hip, knee and
// ankle, oriented so that a positive turn of the shin bends the knee.
Vec3 PoseHinge(const Vec3& hip, const Vec3& knee, const Vec3& ankle, const Vec3& pole_hint) {
  const Vec3 u = Normalized(ankle - hip, {0, -1, 0});
  Vec3 v = (knee - hip) - u * Dot(knee - hip, u);
  if (Norm(v) < 1e-9 * std::max(1.0, Norm(knee - hip))) v = pole_hint - u * Dot(pole_hint, u);
  if (Norm(v) < 1e-12) v = Cross(u, Normalized(Cross(u, {1, 0, 0}), {0, 0, 1}));
  // Thigh = a u + b v and shin = c u - e v (a, b, c, e > 0 for a bent knee),
  // so Cross(thigh, shin) points along Cross(v, u).
  return Normalized(Cross(v, u), {1, 0, 0});
}

// Eases distances past `start` towards `start + soft` (identity below it).
double Soften(double d, double start, double soft) {
  if (soft <= 0 || d <= start) return d;
  return start + soft * (1 - std::exp(-(d - start) / soft));
}

}  // namespace

TwoBoneResult SolveTwoBone(const Vec3& hip, const Vec3& knee, const Vec3& ankle, const Vec3& target,
                           const TwoBoneParams& params) {
  TwoBoneResult r;
  const double l1 = Norm(knee - hip), l2 = Norm(ankle - knee);
  const Vec3 n = params.hinge ? Normalized(*params.hinge, {1, 0, 0})
                              : PoseHinge(hip, knee, ankle, params.pole_hint);
  // Thigh t and shin s (unit), split along the hinge and across it: turning
  // the shin about the hinge changes only the angle phi between the across
  // parts, and t.s = along + across * cos(phi).
  const Vec3 t = Normalized(knee - hip, {0, -1, 0}), s = Normalized(ankle - knee, {0, -1, 0});
  const Vec3 t_across = t - n * Dot(t, n), s_across = s - n * Dot(s, n);
  const double along = Dot(t, n) * Dot(s, n), across = Norm(t_across) * Norm(s_across);
  const double phi = std::atan2(Dot(Cross(t_across, s_across), n), Dot(t_across, s_across));
  // The knee angle phi (>= 0) at which the hip-ankle distance is d.
  auto bend_for = [&](double d) {
    if (across < 1e-12 || l1 < 1e-12 || l2 < 1e-12) return 0.0;
    const double cos_phi = ((d * d - l1 * l1 - l2 * l2) / (2 * l1 * l2) - along) / across;
    return std::acos(std::clamp(cos_phi, -1.0, 1.0));
  };
  const double reach = std::sqrt(std::max(0.0, l1 * l1 + l2 * l2 + 2 * l1 * l2 * (along + across)));
  const double soft_start = reach - params.soft;
  const double wanted = Norm(target - hip), now = Norm(ankle - hip);
  const double d = Soften(wanted, soft_start, params.soft),
               d_now = Soften(now, soft_start, params.soft);
  // The knee turns by the change of bend that the change of (softened)
  // distance needs: nothing for the ankle's own position, soft reach or not;
  // without a soft reach it is exactly the bend for the target's distance.
  // A forward-bent knee is not pushed past straight; a hyperextended one
  // (phi < 0) changes by the same amount, continuous through the straight leg.
  double new_phi = phi + bend_for(d) - bend_for(d_now);
  if (phi >= 0) new_phi = std::max(0.0, new_phi);
  const Quat bend = AxisAngle(n, new_phi - phi);
  const Vec3 bent_ankle = knee + Rotate(bend, ankle - knee);
  const Vec3 to_target = target - hip;
  const Quat swing =
      Norm(to_target) > 1e-12 ? RotationBetween(bent_ankle - hip, to_target) : Quat{};
  r.knee = hip + Rotate(swing, knee - hip);
  r.ankle = hip + Rotate(swing, bent_ankle - hip);
  r.hip_delta = swing;
  r.knee_delta = swing * bend;
  r.reached = Norm(r.ankle - target) <= 1e-6 * std::max(1.0, l1 + l2);
  return r;
}

}  // namespace stylus::motion
