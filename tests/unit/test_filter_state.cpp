// The ESIKF state's ⊞ / ⊟ and the Jacobian H of paper eq. (12) against numeric differentiation.
#include <gtest/gtest.h>

#include "livo/filter_state.hpp"

using namespace livo;

namespace {
FilterState someState(double s) {
  FilterState x;
  x.rot = so3::Exp(Vec3(0.3, -0.7, 1.1) * s);
  x.pos = Vec3(1, 2, 3) * s;
  x.vel = Vec3(-0.5, 0.2, 0.1) * s;
  x.gyro_bias = Vec3(0.01, -0.02, 0.005) * s;
  x.accel_bias = Vec3(0.1, 0.05, -0.2) * s;
  x.gravity = Vec3(0.1 * s, -0.2 * s, -9.81);
  return x;
}
}  // namespace

TEST(FilterState, BoxPlusMinusInverse) {
  const FilterState x = someState(1.0);
  Vec18 d;
  for (int i = 0; i < 18; ++i) d[i] = 0.05 * std::sin(1.0 + i);
  const FilterState y = x.boxplus(d);
  EXPECT_NEAR((y.boxminus(x) - d).norm(), 0.0, 1e-12);
  EXPECT_NEAR(x.boxminus(x).norm(), 0.0, 1e-15);
  // x ⊞ (y ⊟ x) = y
  const FilterState z = x.boxplus(y.boxminus(x));
  EXPECT_NEAR(z.boxminus(y).norm(), 0.0, 1e-12);
}

TEST(FilterState, BoxMinusJacobianNumeric) {
  const FilterState x = someState(1.0);
  const FilterState y = someState(0.6);
  const Mat18 H = FilterState::boxminusJacobian(x, y);
  Mat18 Hnum;
  const double h = 1e-6;
  for (int i = 0; i < 18; ++i) {
    Vec18 d = Vec18::Zero();
    d[i] = h;
    Hnum.col(i) = (x.boxplus(d).boxminus(y) - x.boxplus(-d).boxminus(y)) / (2 * h);
  }
  EXPECT_NEAR((H - Hnum).norm(), 0.0, 1e-7);
  // Identity when x == y.
  EXPECT_NEAR((FilterState::boxminusJacobian(x, x) - Mat18::Identity()).norm(), 0.0, 1e-12);
}
