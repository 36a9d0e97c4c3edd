#include "motion/position_fit.h"

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

// The eigenvector of the largest eigenvalue of a symmetric 4x4 matrix
// (cyclic Jacobi rotations).
std::array<double, 4> TopEigenvector(std::array<std::array<double, 4>, 4> a) {
  std::array<std::array<double, 4>, 4> v{};
  for (int i = 0; i < 4; ++i) v[i][i] = 1;
  for (int sweep = 0; sweep < 30; ++sweep) {
    double off = 0;
    for (int p = 0; p < 4; ++p)
      for (int q = p + 1; q < 4; ++q) off += a[p][q] * a[p][q];
    if (off < 1e-24) break;
    for (int p = 0; p < 4; ++p)
      for (int q = p + 1; q < 4; ++q) {
        if (std::fabs(a[p][q]) < 1e-30) continue;
        const double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        const double t = (theta >= 0 ? 1 : -1) / (std::fabs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 4; ++k) {  // a = J^T a J, columns then rows.
          const double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 4; ++k) {
          const double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
        for (int k = 0; k < 4; ++k) {
          const double vkp = v[k][p], vkq = v[k][q];
          v[k][p] = c * vkp - s * vkq;
          v[k][q] = s * vkp + c * vkq;
        }
      }
  }
  int best = 0;
  for (int i = 1; i < 4; ++i)
    if (a[i][i] > a[best][best]) best = i;
  return {v[0][best], v[1][best], v[2][best], v[3][best]};
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
  double s[3][3] = {};
  for (const auto& [a, b] : pairs) {
    const double av[3] = {a.x, a.y, a.z}, bv[3] = {b.x, b.y, b.z};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s[i][j] += av[i] * bv[j];
  }
  const double xx = s[0][0], xy = s[0][1], xz = s[0][2], yx = s[1][0], yy = s[1][1],
               yz = s[1][2], zx = s[2][0], zy = s[2][1], zz = s[2][2];
  const std::array<std::array<double, 4>, 4> n = {{
      {xx + yy + zz, yz - zy, zx - xz, xy - yx},
      {yz - zy, xx - yy - zz, xy + yx, zx + xz},
      {zx - xz, xy + yx, -xx + yy - zz, yz + zy},
      {xy - yx, zx + xz, yz + zy, -xx - yy + zz},
  }};
  const std::array<double, 4> e = TopEigenvector(n);
  return SameHemisphere(Normalized(Quat{e[0], e[1], e[2], e[3]}), global);
}

}  // namespace

void FitRotationsToPositions(const Skeleton& skeleton, const HumanoidRoles& roles,
                             FeatureClip* features) {
  const int joints = skeleton.num_joints();
  const FeatureLayout layout(joints);
  // Joints at or below the pelvis, parents first (file order is depth-first).
  std::vector<bool> below(joints, false);
  below[roles.pelvis] = true;
  for (int j = roles.pelvis + 1; j < joints; ++j) {
    const int p = skeleton.joint(j).parent;
    below[j] = p >= 0 && below[p];
  }
  std::vector<Quat> global(joints), previous(joints);
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
        global[j] = global[p] * local;
      }
      if (!skeleton.children(j).empty()) {
        global[j] = AlignChildren(global[j], position[j], skeleton.children(j), skeleton, row,
                                  layout);
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
