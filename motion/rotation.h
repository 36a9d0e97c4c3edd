// Rotation math for motion data: 3-vectors, unit quaternions, 3x3 matrices and
// Euler angles in degrees, in all six axis orders that BVH files use.
//
// Conventions (used throughout motion/):
//  * Right-handed coordinates; rotations act on column vectors: v' = R v.
//  * An Euler triple is stored in the order of its axes: for EulerOrder "ZXY" the
//    triple is (z, x, y) and the rotation is R = Rz(z) * Rx(x) * Ry(y), which is how
//    BVH composes a joint's rotation channels in the order they are listed.
//  * Quaternions are (w, x, y, z); functions that return one return it normalized.
// All functions are pure and thread-safe.
#ifndef STYLUS_MOTION_ROTATION_H_
#define STYLUS_MOTION_ROTATION_H_

#include <array>
#include <string>
#include <utility>
#include <vector>

#include "absl/status/statusor.h"
#include "absl/strings/string_view.h"

namespace stylus::motion {

struct Vec3 {
  double x = 0, y = 0, z = 0;

  double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
};

Vec3 operator+(const Vec3& a, const Vec3& b);
Vec3 operator-(const Vec3& a, const Vec3& b);
Vec3 operator*(const Vec3& a, double s);
Vec3 operator*(double s, const Vec3& a);
double Dot(const Vec3& a, const Vec3& b);
Vec3 Cross(const Vec3& a, const Vec3& b);
double Norm(const Vec3& a);
// Returns a / |a|, or `fallback` when |a| is (nearly) zero.
Vec3 Normalized(const Vec3& a, const Vec3& fallback = {1, 0, 0});

struct Quat {
  double w = 1, x = 0, y = 0, z = 0;
};

Quat operator*(const Quat& a, const Quat& b);
Quat Conjugate(const Quat& q);
Quat Normalized(const Quat& q);
double Dot(const Quat& a, const Quat& b);
Vec3 Rotate(const Quat& q, const Vec3& v);
// Rotation of `angle_rad` radians about `axis` (need not be unit length).
Quat AxisAngle(const Vec3& axis, double angle_rad);
// Rotation by `angle_rad` about the vertical (+Y) axis.
Quat YawRotation(double angle_rad);
// Shortest-arc spherical interpolation; t = 0 gives a, t = 1 gives b (up to sign).
Quat Slerp(const Quat& a, const Quat& b, double t);
// Returns q or -q, whichever lies in the hemisphere of `reference` (dot >= 0).
Quat SameHemisphere(const Quat& q, const Quat& reference);
// q or -q, whichever lies on the positive side of a fixed reference
// (w + 0.1x + 0.01y + 0.001z >= 0): unlike w >= 0, small noise cannot flip the
// sign of half turns (w ~ 0), which rigs use for mirrored limbs.
Quat CanonicalSign(const Quat& q);
// The rotation R that best turns each `first` of `pairs` onto the direction
// of its `second` (least squares, Horn's quaternion method): maximizes the sum
// of (R a) . b. The length of each `a` weighs its pair; give `b` unit length.
Quat BestRotation(const std::vector<std::pair<Vec3, Vec3>>& pairs);
// The smallest rotation that turns direction `from` onto direction `to`.
Quat RotationBetween(const Vec3& from, const Vec3& to);
// The angle between two rotations, in radians, in [0, pi].
double AngleBetween(const Quat& a, const Quat& b);

// Row-major 3x3 matrix: m[row][col].
struct Mat3 {
  std::array<std::array<double, 3>, 3> m{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}};
};

Mat3 operator*(const Mat3& a, const Mat3& b);
Vec3 operator*(const Mat3& a, const Vec3& v);
Mat3 QuatToMat(const Quat& q);
Quat MatToQuat(const Mat3& m);
// Elementary rotation about axis 0 (X), 1 (Y) or 2 (Z).
Mat3 AxisMat(int axis, double angle_rad);

// The order of three rotation axes, e.g. {2, 0, 1} for "ZXY". Only the six
// Tait-Bryan orders (all axes distinct) are valid.
struct EulerOrder {
  std::array<int, 3> axes{{2, 0, 1}};

  // Parses "XYZ", "zxy", ... ; anything else is INVALID_ARGUMENT.
  static absl::StatusOr<EulerOrder> Parse(absl::string_view name);
  std::string Name() const;
  bool operator==(const EulerOrder& o) const { return axes == o.axes; }
};

// The six orders, for tests and loops.
std::array<EulerOrder, 6> AllEulerOrders();

// Euler triple (degrees, in the order's axis order) to rotation.
Mat3 EulerToMat(const Vec3& degrees, const EulerOrder& order);
Quat EulerToQuat(const Vec3& degrees, const EulerOrder& order);

// Rotation to an Euler triple in degrees. The middle angle lies in [-90, 90];
// at gimbal lock the third angle is set to 0.
Vec3 MatToEuler(const Mat3& m, const EulerOrder& order);
Vec3 QuatToEuler(const Quat& q, const EulerOrder& order);
// Of all Euler triples for q (both solutions, each angle shifted by any multiple
// of 360 degrees), the one closest to `previous`: writing a sequence this way
// leaves no 360-degree jumps between frames.
Vec3 QuatToEulerNear(const Quat& q, const EulerOrder& order, const Vec3& previous);

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegToRad = kPi / 180.0;
constexpr double kRadToDeg = 180.0 / kPi;

}  // namespace stylus::motion

#endif  // STYLUS_MOTION_ROTATION_H_
