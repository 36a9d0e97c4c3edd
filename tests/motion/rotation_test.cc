#include "motion/rotation.h"

#include <cmath>
#include <random>

#include "gtest/gtest.h"

namespace stylus::motion {
namespace {

void ExpectMatNear(const Mat3& a, const Mat3& b, double tol) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(a.m[i][j], b.m[i][j], tol) << "element " << i << "," << j;
}

// Textbook elementary matrices, written out independently of AxisMat.
Mat3 Textbook(char axis, double deg) {
  const double c = std::cos(deg * kDegToRad), s = std::sin(deg * kDegToRad);
  Mat3 r;
  if (axis == 'X') r.m = {{{1, 0, 0}, {0, c, -s}, {0, s, c}}};
  if (axis == 'Y') r.m = {{{c, 0, s}, {0, 1, 0}, {-s, 0, c}}};
  if (axis == 'Z') r.m = {{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}};
  return r;
}

TEST(RotationTest, EulerOrdersMatchTextbookMatrixProducts) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> angle(-180, 180);
  for (const EulerOrder& order : AllEulerOrders()) {
    const std::string name = order.Name();
    for (int trial = 0; trial < 50; ++trial) {
      const Vec3 e{angle(rng), angle(rng) / 2, angle(rng)};
      const Mat3 expected =
          Textbook(name[0], e[0]) * Textbook(name[1], e[1]) * Textbook(name[2], e[2]);
      ExpectMatNear(EulerToMat(e, order), expected, 1e-12);
      ExpectMatNear(QuatToMat(EulerToQuat(e, order)), expected, 1e-12);
    }
  }
}

TEST(RotationTest, KnownRotations) {
  const Quat z90 = EulerToQuat({90, 0, 0}, *EulerOrder::Parse("ZXY"));
  const Vec3 v = Rotate(z90, {1, 0, 0});
  EXPECT_NEAR(v.x, 0, 1e-12);
  EXPECT_NEAR(v.y, 1, 1e-12);
  const Vec3 w = Rotate(YawRotation(kPi / 2), {0, 0, 1});  // Facing +Z turns to +X.
  EXPECT_NEAR(w.x, 1, 1e-12);
  EXPECT_NEAR(w.z, 0, 1e-12);
}

TEST(RotationTest, MatrixToEulerRoundTripsInAllOrdersIncludingGimbalLock) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> angle(-180, 180);
  for (const EulerOrder& order : AllEulerOrders()) {
    for (int trial = 0; trial < 200; ++trial) {
      Vec3 e{angle(rng), angle(rng) / 2, angle(rng)};
      if (trial % 10 == 0) e[1] = trial % 20 == 0 ? 90 : -90;  // Gimbal lock.
      const Mat3 m = EulerToMat(e, order);
      const Vec3 back = MatToEuler(m, order);
      EXPECT_LE(std::fabs(back[1]), 90 + 1e-9);
      ExpectMatNear(EulerToMat(back, order), m, 1e-6);
      ExpectMatNear(QuatToMat(MatToQuat(m)), m, 1e-9);
    }
  }
}

TEST(RotationTest, EulerStaysContinuousOverA720DegreeSpin) {
  for (const EulerOrder& order : AllEulerOrders()) {
    for (int axis = 0; axis < 3; ++axis) {
      Vec3 spin_axis{0.2, 0.3, 0.1};
      spin_axis[axis] = 1;
      Vec3 prev;
      for (int step = 0; step <= 720; step += 3) {
        const Quat q = AxisAngle(spin_axis, step * kDegToRad);
        const Vec3 e = QuatToEulerNear(q, order, prev);
        ExpectMatNear(EulerToMat(e, order), QuatToMat(q), 1e-6);
        if (step > 0) {
          for (int k = 0; k < 3; ++k) {
            EXPECT_LT(std::fabs(e[k] - prev[k]), 30) << order.Name() << " step " << step;
          }
        }
        prev = e;
      }
    }
  }
}

TEST(RotationTest, SlerpEndpointsAndMidpoint) {
  const Quat a = AxisAngle({0, 1, 0}, 0.2), b = AxisAngle({0, 1, 0}, 1.4);
  EXPECT_NEAR(AngleBetween(Slerp(a, b, 0), a), 0, 1e-9);
  EXPECT_NEAR(AngleBetween(Slerp(a, b, 1), b), 0, 1e-6);
  EXPECT_NEAR(AngleBetween(Slerp(a, b, 0.5), AxisAngle({0, 1, 0}, 0.8)), 0, 1e-9);
  // Takes the short way even when b is given in the other hemisphere.
  const Quat neg_b{-b.w, -b.x, -b.y, -b.z};
  EXPECT_NEAR(AngleBetween(Slerp(a, neg_b, 0.5), AxisAngle({0, 1, 0}, 0.8)), 0, 1e-9);
}

TEST(RotationTest, HemisphereAndRotationBetween) {
  const Quat q{0.5, 0.5, 0.5, 0.5};
  const Quat flipped = SameHemisphere(Quat{-0.5, -0.5, -0.5, -0.5}, q);
  EXPECT_GT(Dot(flipped, q), 0);
  for (const Vec3& to : {Vec3{0, 1, 0}, Vec3{-1, 0, 0}, Vec3{0.3, -0.2, 0.9}}) {
    const Vec3 r = Rotate(RotationBetween({1, 0, 0}, to), {1, 0, 0});
    const Vec3 t = Normalized(to);
    EXPECT_NEAR(r.x, t.x, 1e-9);
    EXPECT_NEAR(r.y, t.y, 1e-9);
    EXPECT_NEAR(r.z, t.z, 1e-9);
  }
}

TEST(RotationTest, EulerOrderParsing) {
  EXPECT_EQ(EulerOrder::Parse("zxy")->Name(), "ZXY");
  EXPECT_FALSE(EulerOrder::Parse("XXY").ok());
  EXPECT_FALSE(EulerOrder::Parse("XY").ok());
  EXPECT_FALSE(EulerOrder::Parse("ABC").ok());
}

}  // namespace
}  // namespace stylus::motion
