#include "motion/ik.h"

#include <algorithm>
#include <cmath>

namespace stylus::motion {

TwoBoneResult SolveTwoBone(const Vec3& hip, const Vec3& knee, const Vec3& ankle,
                           const Vec3& target, const Vec3& pole_hint) {
  const double l1 = Norm(knee - hip), l2 = Norm(ankle - knee);
  TwoBoneResult r;
  const Vec3 to_target = target - hip;
  const double wanted = Norm(to_target);
  const Vec3 u = Normalized(to_target, Normalized(ankle - hip, {0, -1, 0}));
  // Reach: [|l1 - l2|, l1 + l2].
  const double d = std::clamp(wanted, std::abs(l1 - l2), l1 + l2);
  r.reached = std::abs(d - wanted) <= 1e-6 * std::max(1.0, l1 + l2);
  // The bend direction: the current knee's offset from the hip-target line.
  Vec3 v = (knee - hip) - u * Dot(knee - hip, u);
  if (Norm(v) < 1e-9 * std::max(1.0, l1)) v = pole_hint - u * Dot(pole_hint, u);
  if (Norm(v) < 1e-12) v = Cross(u, Normalized(Cross(u, {1, 0, 0}), {0, 0, 1}));
  v = Normalized(v, {0, 0, 1});
  // Angle at the hip between the thigh and the hip-ankle line (law of cosines).
  double cos_a = d > 1e-12 ? (l1 * l1 + d * d - l2 * l2) / (2 * l1 * d) : 1.0;
  cos_a = std::clamp(cos_a, -1.0, 1.0);
  const double sin_a = std::sqrt(std::max(0.0, 1 - cos_a * cos_a));
  r.knee = hip + (u * cos_a + v * sin_a) * l1;
  r.ankle = hip + u * d;
  r.hip_delta = RotationBetween(knee - hip, r.knee - hip);
  const Vec3 shin_after_hip = Rotate(r.hip_delta, ankle - knee);
  r.knee_delta = RotationBetween(shin_after_hip, r.ankle - r.knee) * r.hip_delta;
  return r;
}

}  // namespace stylus::motion
