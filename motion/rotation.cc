#include "motion/rotation.h"

#include <algorithm>
#include <cmath>

#include "absl/strings/ascii.h"
#include "absl/strings/str_cat.h"

namespace stylus::motion {

Vec3 operator+(const Vec3& a, const Vec3& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec3 operator-(const Vec3& a, const Vec3& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec3 operator*(const Vec3& a, double s) { return {a.x * s, a.y * s, a.z * s}; }
Vec3 operator*(double s, const Vec3& a) { return a * s; }
double Dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 Cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
double Norm(const Vec3& a) { return std::sqrt(Dot(a, a)); }
Vec3 Normalized(const Vec3& a, const Vec3& fallback) {
  const double n = Norm(a);
  return n < 1e-12 ? fallback : a * (1.0 / n);
}

Quat operator*(const Quat& a, const Quat& b) {
  return {
      a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
      a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}
Quat Conjugate(const Quat& q) { return {q.w, -q.x, -q.y, -q.z}; }
double Dot(const Quat& a, const Quat& b) { return a.w * b.w + a.x * b.x + a.y * b.y + a.z * b.z; }
Quat Normalized(const Quat& q) {
  const double n = std::sqrt(Dot(q, q));
  if (n < 1e-12 || !std::isfinite(n)) return Quat{};
  return {q.w / n, q.x / n, q.y / n, q.z / n};
}

Vec3 Rotate(const Quat& q, const Vec3& v) {
  // v' = v + 2 u x (u x v + w v), u = vector part.
  const Vec3 u{q.x, q.y, q.z};
  const Vec3 t = Cross(u, v) * 2.0;
  return v + t * q.w + Cross(u, t);
}

Quat AxisAngle(const Vec3& axis, double angle_rad) {
  const Vec3 a = Normalized(axis);
  const double s = std::sin(angle_rad / 2);
  return {std::cos(angle_rad / 2), a.x * s, a.y * s, a.z * s};
}

Quat YawRotation(double angle_rad) {
  return {std::cos(angle_rad / 2), 0, std::sin(angle_rad / 2), 0};
}

Quat SameHemisphere(const Quat& q, const Quat& reference) {
  return Dot(q, reference) < 0 ? Quat{-q.w, -q.x, -q.y, -q.z} : q;
}

Quat CanonicalSign(const Quat& q) {
  // Sign of the dot product with a fixed reference that no "round" rotation
  // (half turns, 120-degree turns about diagonals, ...) is orthogonal to.
  const double d = q.w + 0.1 * q.x + 0.01 * q.y + 0.001 * q.z;
  return d < 0 ? Quat{-q.w, -q.x, -q.y, -q.z} : q;
}

Quat Slerp(const Quat& a, const Quat& b_in, double t) {
  const Quat b = SameHemisphere(b_in, a);
  const double d = std::clamp(Dot(a, b), -1.0, 1.0);
  if (d > 0.9995) {  // Nearly parallel: linear blend avoids dividing by sin(~0).
    return Normalized(Quat{a.w + t * (b.w - a.w), a.x + t * (b.x - a.x), a.y + t * (b.y - a.y),
                           a.z + t * (b.z - a.z)});
  }
  const double theta = std::acos(d);
  const double sa = std::sin((1 - t) * theta) / std::sin(theta);
  const double sb = std::sin(t * theta) / std::sin(theta);
  return Normalized(
      Quat{sa * a.w + sb * b.w, sa * a.x + sb * b.x, sa * a.y + sb * b.y, sa * a.z + sb * b.z});
}

Quat RotationBetween(const Vec3& from, const Vec3& to) {
  const Vec3 f = Normalized(from), t = Normalized(to);
  const double d = Dot(f, t);
  if (d < -0.999999) {  // Opposite: any axis orthogonal to `from` works.
    Vec3 axis = Cross({1, 0, 0}, f);
    if (Norm(axis) < 1e-6) axis = Cross({0, 1, 0}, f);
    return AxisAngle(axis, kPi);
  }
  const Vec3 c = Cross(f, t);
  return Normalized(Quat{1 + d, c.x, c.y, c.z});
}

double AngleBetween(const Quat& a, const Quat& b) {
  const double d = std::min(1.0, std::fabs(Dot(Normalized(a), Normalized(b))));
  return 2 * std::acos(d);
}

Mat3 operator*(const Mat3& a, const Mat3& b) {
  Mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      r.m[i][j] = a.m[i][0] * b.m[0][j] + a.m[i][1] * b.m[1][j] + a.m[i][2] * b.m[2][j];
  return r;
}

Vec3 operator*(const Mat3& a, const Vec3& v) {
  return {a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z,
          a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
          a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z};
}

Mat3 QuatToMat(const Quat& qin) {
  const Quat q = Normalized(qin);
  const double w = q.w, x = q.x, y = q.y, z = q.z;
  Mat3 r;
  r.m = {{{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}}};
  return r;
}

Quat MatToQuat(const Mat3& a) {
  const auto& m = a.m;
  const double trace = m[0][0] + m[1][1] + m[2][2];
  Quat q;
  if (trace > 0) {
    const double s = 2 * std::sqrt(trace + 1.0);
    q = {0.25 * s, (m[2][1] - m[1][2]) / s, (m[0][2] - m[2][0]) / s, (m[1][0] - m[0][1]) / s};
  } else if (m[0][0] > m[1][1] && m[0][0] > m[2][2]) {
    const double s = 2 * std::sqrt(1.0 + m[0][0] - m[1][1] - m[2][2]);
    q = {(m[2][1] - m[1][2]) / s, 0.25 * s, (m[0][1] + m[1][0]) / s, (m[0][2] + m[2][0]) / s};
  } else if (m[1][1] > m[2][2]) {
    const double s = 2 * std::sqrt(1.0 + m[1][1] - m[0][0] - m[2][2]);
    q = {(m[0][2] - m[2][0]) / s, (m[0][1] + m[1][0]) / s, 0.25 * s, (m[1][2] + m[2][1]) / s};
  } else {
    const double s = 2 * std::sqrt(1.0 + m[2][2] - m[0][0] - m[1][1]);
    q = {(m[1][0] - m[0][1]) / s, (m[0][2] + m[2][0]) / s, (m[1][2] + m[2][1]) / s, 0.25 * s};
  }
  return Normalized(q);
}

Mat3 AxisMat(int axis, double a) {
  const double c = std::cos(a), s = std::sin(a);
  Mat3 r;
  switch (axis) {
    case 0:
      r.m = {{{1, 0, 0}, {0, c, -s}, {0, s, c}}};
      break;
    case 1:
      r.m = {{{c, 0, s}, {0, 1, 0}, {-s, 0, c}}};
      break;
    default:
      r.m = {{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}};
      break;
  }
  return r;
}

absl::StatusOr<EulerOrder> EulerOrder::Parse(absl::string_view name) {
  const std::string up = absl::AsciiStrToUpper(name);
  if (up.size() != 3)
    return absl::InvalidArgumentError(absl::StrCat("bad Euler order '", name, "'"));
  EulerOrder o;
  for (int i = 0; i < 3; ++i) {
    if (up[i] < 'X' || up[i] > 'Z') {
      return absl::InvalidArgumentError(absl::StrCat("bad Euler order '", name, "'"));
    }
    o.axes[i] = up[i] - 'X';
  }
  if (o.axes[0] == o.axes[1] || o.axes[1] == o.axes[2] || o.axes[0] == o.axes[2]) {
    return absl::InvalidArgumentError(absl::StrCat(
        "Euler order '", name, "' repeats an axis; only Tait-Bryan orders are supported"));
  }
  return o;
}

std::string EulerOrder::Name() const {
  std::string s;
  for (int a : axes) s.push_back(static_cast<char>('X' + a));
  return s;
}

std::array<EulerOrder, 6> AllEulerOrders() {
  std::array<EulerOrder, 6> all;
  const char* names[] = {"XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"};
  for (int i = 0; i < 6; ++i) all[i] = *EulerOrder::Parse(names[i]);
  return all;
}

Mat3 EulerToMat(const Vec3& deg, const EulerOrder& order) {
  return AxisMat(order.axes[0], deg[0] * kDegToRad) * AxisMat(order.axes[1], deg[1] * kDegToRad) *
         AxisMat(order.axes[2], deg[2] * kDegToRad);
}

Quat EulerToQuat(const Vec3& deg, const EulerOrder& order) {
  Quat q;
  for (int k = 0; k < 3; ++k) {
    Vec3 axis;
    axis[order.axes[k]] = 1;
    q = q * AxisAngle(axis, deg[k] * kDegToRad);
  }
  return Normalized(q);
}

// For R = Ri(a) Rj(b) Rk(c): R[i][k] = s sin(b) with s = +1 for the cyclic orders
// (XYZ, YZX, ZXY) and -1 for the others; a and c follow from the rest of row i and
// column k. See docs/motion.md for the derivation.
Vec3 MatToEuler(const Mat3& r, const EulerOrder& order) {
  const int i = order.axes[0], j = order.axes[1], k = order.axes[2];
  const double s = ((j - i + 3) % 3 == 1) ? 1.0 : -1.0;
  const auto& m = r.m;
  // cos(b) from the two other entries of row i: accurate even near b = +-90,
  // where asin(R[i][k]) loses half the digits.
  const double cb = std::hypot(m[i][i], m[i][j]);
  const double b = std::atan2(s * m[i][k], cb);
  double a, c;
  if (cb > 1e-12) {
    a = std::atan2(-s * m[j][k], m[k][k]);
    c = std::atan2(-s * m[i][j], m[i][i]);
  } else {  // Gimbal lock: only a +/- c is defined; put it all in a.
    a = std::atan2(s * m[k][j], m[j][j]);
    c = 0;
  }
  return {a * kRadToDeg, b * kRadToDeg, c * kRadToDeg};
}

Vec3 QuatToEuler(const Quat& q, const EulerOrder& order) { return MatToEuler(QuatToMat(q), order); }

namespace {
double Wrap360Near(double angle, double target) {
  return angle + 360.0 * std::round((target - angle) / 360.0);
}
}  // namespace

Vec3 QuatToEulerNear(const Quat& q, const EulerOrder& order, const Vec3& previous) {
  const Vec3 e1 = QuatToEuler(q, order);
  // The other solution of a Tait-Bryan decomposition: (a+180, 180-b, c+180).
  const Vec3 e2{e1[0] + 180.0, 180.0 - e1[1], e1[2] + 180.0};
  Vec3 best;
  double best_d = 1e300;
  for (const Vec3& e : {e1, e2}) {
    Vec3 w{Wrap360Near(e[0], previous[0]), Wrap360Near(e[1], previous[1]),
           Wrap360Near(e[2], previous[2])};
    const double d = Norm(w - previous);
    if (d < best_d) {
      best_d = d;
      best = w;
    }
  }
  return best;
}

namespace {

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

}  // namespace

Quat BestRotation(const std::vector<std::pair<Vec3, Vec3>>& pairs) {
  double s[3][3] = {};
  for (const auto& [a, b] : pairs) {
    const double av[3] = {a.x, a.y, a.z}, bv[3] = {b.x, b.y, b.z};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) s[i][j] += av[i] * bv[j];
  }
  const double xx = s[0][0], xy = s[0][1], xz = s[0][2], yx = s[1][0], yy = s[1][1], yz = s[1][2],
               zx = s[2][0], zy = s[2][1], zz = s[2][2];
  const std::array<std::array<double, 4>, 4> n = {{
      {xx + yy + zz, yz - zy, zx - xz, xy - yx},
      {yz - zy, xx - yy - zz, xy + yx, zx + xz},
      {zx - xz, xy + yx, -xx + yy - zz, yz + zy},
      {xy - yx, zx + xz, yz + zy, -xx - yy + zz},
  }};
  const std::array<double, 4> e = TopEigenvector(n);
  return Normalized(Quat{e[0], e[1], e[2], e[3]});
}

}  // namespace stylus::motion
