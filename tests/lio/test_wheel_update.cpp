// Wheel velocity update: the measurement Jacobian against numeric differentiation, and the update
// pulling a wrong velocity towards the wheel speed with the non-holonomic constraints.
#include <gtest/gtest.h>

#include "livo/lio/wheel_update.hpp"

using namespace livo;
using namespace livo::lio;

namespace {
FilterState movingState() {
  FilterState x;
  x.rot = so3::Exp(Vec3(0.02, -0.01, 0.7));
  x.pos = Vec3(3.0, 1.0, 0.0);
  x.vel = x.rot * Vec3(1.2, 0.0, 0.0);  // forward in the body
  x.gyro_bias = Vec3(0.001, -0.002, 0.003);
  return x;
}
const Pose3 kTIB = se3::fromRotationTranslation(so3::Exp(Vec3(0.0, 0.0, 0.05)), Vec3(-0.3, 0.1, -0.4));
}  // namespace

TEST(WheelUpdate, JacobianMatchesNumericDifferentiation) {
  const FilterState x = movingState();
  const Vec3 gyro(0.05, -0.02, 0.4);
  const Mat3xState H = wheelVelocityJacobian(x, gyro, kTIB);
  const double h = 1e-6;
  for (int i = 0; i < FilterState::kDim; ++i) {
    StateVector d = StateVector::Zero();
    d[i] = h;
    const Vec3 num =
        (wheelFrameVelocity(x.boxplus(d), gyro, kTIB) - wheelFrameVelocity(x.boxplus(-d), gyro, kTIB)) / (2 * h);
    EXPECT_LT((H.col(i) - num).norm(), 1e-8) << "state " << i;
  }
}

TEST(WheelUpdate, CorrectsVelocityAndGatesSlip) {
  // a vehicle that obeys the constraints: B moves along its x axis at 1.2 m/s while turning
  FilterState truth = movingState();
  const Vec3 omega(0.0, 0.0, 0.4);
  const Vec3 gyro = omega + truth.gyro_bias;
  truth.vel = truth.rot * (kTIB.linear() * Vec3(1.2, 0.0, 0.0) - omega.cross(kTIB.translation()));
  const double speed = 1.2;
  ASSERT_LT((wheelFrameVelocity(truth, gyro, kTIB) - Vec3(speed, 0, 0)).norm(), 1e-12);
  FilterState x = truth;
  x.vel += truth.rot * Vec3(0.3, 0.2, -0.1);  // wrong forward, lateral and vertical velocity
  StateCovariance P = StateCovariance::Identity() * 1e-4;
  P.block<3, 3>(FilterState::kVel, FilterState::kVel) = Mat3::Identity() * 0.25;
  WheelOptions o;
  o.enabled = true;
  o.T_I_B = kTIB;
  const WheelUpdateResult r = wheelVelocityUpdate(&x, &P, gyro, speed, o);
  ASSERT_TRUE(r.applied);
  EXPECT_LT((x.vel - truth.vel).norm(), 0.06);
  EXPECT_LT(P(FilterState::kVel, FilterState::kVel), 0.25);
  // velocity in the wheel frame is now nearly forward only
  const Vec3 vb = wheelFrameVelocity(x, gyro, kTIB);
  EXPECT_NEAR(vb.x(), speed, 0.03);
  EXPECT_LT(std::abs(vb.y()), 0.06);

  // a 3 m/s discrepancy with a confident filter is slip: rejected, state untouched
  FilterState y = truth;
  StateCovariance Py = StateCovariance::Identity() * 1e-4;
  const WheelUpdateResult slip = wheelVelocityUpdate(&y, &Py, gyro, speed + 3.0, o);
  EXPECT_FALSE(slip.applied);
  EXPECT_GT(slip.chi2, o.gate_chi2);
  EXPECT_EQ(y.vel, truth.vel);
}
