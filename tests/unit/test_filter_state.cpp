// The ESIKF state's ⊞ / ⊟ and the Jacobian H of paper eq. (12) against numeric differentiation, over
// all 32 error states (the navigation state and the LiDAR's and camera's calibration, three rotation
// blocks), the covariance check the filter applies to every covariance it adopts, and the state's
// message (filter_state_t) round trip.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "livo/filter_state.hpp"
#include "livo/filter_state_message.hpp"

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
  x.lidar = SensorCalibration{so3::Exp(Vec3(-0.4, 0.2, 0.9) * s), Vec3(0.1, -0.05, 0.2) * s, 0.004 * s};
  x.camera = SensorCalibration{so3::Exp(Vec3(1.2, -0.3, 0.5) * s), Vec3(-0.03, 0.08, 0.01) * s, -0.012 * s};
  return x;
}

// A random SPD matrix over the states marked in `estimated`, zero rows and columns elsewhere.
StateCovariance randomCovariance(unsigned seed, const StateVector& estimated) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  StateCovariance A;
  for (int i = 0; i < FilterState::kDim; ++i)
    for (int j = 0; j < FilterState::kDim; ++j) A(i, j) = 0.1 * n01(rng);
  StateCovariance P = A * A.transpose() + StateCovariance::Identity() * 0.01;
  return estimated.asDiagonal() * P * estimated.asDiagonal();
}
}  // namespace

TEST(FilterState, BoxPlusMinusInverse) {
  const FilterState x = someState(1.0);
  StateVector d;
  for (int i = 0; i < FilterState::kDim; ++i) d[i] = 0.05 * std::sin(1.0 + i);
  const FilterState y = x.boxplus(d);
  EXPECT_NEAR((y.boxminus(x) - d).norm(), 0.0, 1e-12);
  EXPECT_NEAR(x.boxminus(x).norm(), 0.0, 1e-15);
  // x ⊞ (y ⊟ x) = y
  const FilterState z = x.boxplus(y.boxminus(x));
  EXPECT_NEAR(z.boxminus(y).norm(), 0.0, 1e-12);
  // every block lands in its own state: the calibrations moved by their own part of d only
  EXPECT_NEAR((y.lidar.rot - x.lidar.rot * so3::Exp(d.segment<3>(FilterState::kLidar + FilterState::kCalRot))).norm(),
              0.0, 1e-15);
  EXPECT_EQ(y.lidar.pos, x.lidar.pos + d.segment<3>(FilterState::kLidar + FilterState::kCalPos));
  EXPECT_EQ(y.lidar.dt, x.lidar.dt + d[FilterState::kLidar + FilterState::kCalDt]);
  EXPECT_NEAR(
      (y.camera.rot - x.camera.rot * so3::Exp(d.segment<3>(FilterState::kCamera + FilterState::kCalRot))).norm(), 0.0,
      1e-15);
  EXPECT_EQ(y.camera.pos, x.camera.pos + d.segment<3>(FilterState::kCamera + FilterState::kCalPos));
  EXPECT_EQ(y.camera.dt, x.camera.dt + d[FilterState::kCamera + FilterState::kCalDt]);
}

TEST(FilterState, BoxMinusJacobianNumeric) {
  const FilterState x = someState(1.0);
  const FilterState y = someState(0.6);
  const StateCovariance H = FilterState::boxminusJacobian(x, y);
  StateCovariance Hnum;
  const double h = 1e-6;
  for (int i = 0; i < FilterState::kDim; ++i) {
    StateVector d = StateVector::Zero();
    d[i] = h;
    Hnum.col(i) = (x.boxplus(d).boxminus(y) - x.boxplus(-d).boxminus(y)) / (2 * h);
  }
  EXPECT_NEAR((H - Hnum).norm(), 0.0, 1e-7);
  // the three rotation blocks are not the identity here (x and y differ in every rotation) ...
  for (const int b : FilterState::kRotationBlocks)
    EXPECT_GT((H.block<3, 3>(b, b) - Mat3::Identity()).norm(), 1e-2) << "block " << b;
  // ... and H is the identity everywhere else
  StateCovariance off = H;
  for (const int b : FilterState::kRotationBlocks) off.block<3, 3>(b, b) = Mat3::Identity();
  EXPECT_EQ(off, StateCovariance::Identity());
  // Identity when x == y.
  EXPECT_NEAR((FilterState::boxminusJacobian(x, x) - StateCovariance::Identity()).norm(), 0.0, 1e-12);
}

TEST(FilterState, UsableCovarianceAcceptsAFixedCalibrationBlock) {
  // everything estimated
  EXPECT_TRUE(isUsableCovariance(randomCovariance(3, StateVector::Ones())));
  // the camera's calibration held fixed: zero rows and columns, the rest positive definite
  StateVector estimated = StateVector::Ones();
  estimated.segment<FilterState::kCalibrationDim>(FilterState::kCamera).setZero();
  const StateCovariance P = randomCovariance(4, estimated);
  ASSERT_EQ(P.row(FilterState::kCamera + FilterState::kCalDt).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_TRUE(isUsableCovariance(P));
  // setCalibrationPrior with a zero sigma builds such a block, with a positive one a diagonal prior
  StateCovariance Q = randomCovariance(5, StateVector::Ones());
  setCalibrationPrior(FilterState::kLidar, CalibrationStd{}, &Q);
  EXPECT_EQ(Q.middleRows<FilterState::kCalibrationDim>(FilterState::kLidar).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(Q.middleCols<FilterState::kCalibrationDim>(FilterState::kLidar).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_TRUE(isUsableCovariance(Q));
  setCalibrationPrior(FilterState::kLidar, CalibrationStd{0.01, 0.02, 0.005}, &Q);
  EXPECT_DOUBLE_EQ(Q(FilterState::kLidar + FilterState::kCalRot + 1, FilterState::kLidar + FilterState::kCalRot + 1),
                   1e-4);
  EXPECT_DOUBLE_EQ(Q(FilterState::kLidar + FilterState::kCalPos + 2, FilterState::kLidar + FilterState::kCalPos + 2),
                   4e-4);
  EXPECT_DOUBLE_EQ(Q(FilterState::kLidar + FilterState::kCalDt, FilterState::kLidar + FilterState::kCalDt), 2.5e-5);
  EXPECT_TRUE(isUsableCovariance(Q));
}

TEST(FilterState, UsableCovarianceRejectsBrokenMatrices) {
  StateVector estimated = StateVector::Ones();
  estimated.segment<FilterState::kCalibrationDim>(FilterState::kCamera).setZero();
  const StateCovariance good = randomCovariance(6, estimated);
  ASSERT_TRUE(isUsableCovariance(good));
  const int fixed = FilterState::kCamera + FilterState::kCalPos + 1;  // a state held fixed
  // a negative variance (its row otherwise zero)
  {
    StateCovariance P = good;
    P(fixed, fixed) = -1e-6;
    EXPECT_FALSE(isUsableCovariance(P));
  }
  // a zero-variance state whose row and column are not zero
  {
    StateCovariance P = good;
    P(fixed, FilterState::kPos) = P(FilterState::kPos, fixed) = 1e-9;
    EXPECT_FALSE(isUsableCovariance(P));
  }
  // indefinite: a correlation above 1 between two estimated states
  {
    StateCovariance P = good;
    const int a = FilterState::kVel, b = FilterState::kLidar + FilterState::kCalDt;
    P(a, b) = P(b, a) = 1.5 * std::sqrt(P(a, a) * P(b, b));
    EXPECT_FALSE(isUsableCovariance(P));
  }
  // a non-finite entry
  {
    StateCovariance P = good;
    P(2, 20) = P(20, 2) = std::numeric_limits<double>::quiet_NaN();
    EXPECT_FALSE(isUsableCovariance(P));
    P(2, 20) = P(20, 2) = std::numeric_limits<double>::infinity();
    EXPECT_FALSE(isUsableCovariance(P));
  }
  // not symmetric
  {
    StateCovariance P = good;
    P(1, 4) += 1e-3;
    EXPECT_FALSE(isUsableCovariance(P));
  }
}

TEST(FilterState, MessageRoundTripKeepsTheCalibrationAndTheWholeCovariance) {
  const FilterState x = someState(0.8);
  const StateCovariance P = randomCovariance(7, StateVector::Ones());
  const Vec3 rate(0.1, -0.2, 0.3);
  const filter_state_t m = toFilterState(123, x, P, 9, "test", rate);
  EXPECT_EQ(m.angular_velocity[2], 0.3);
  FilterState y;
  StateCovariance Q;
  ASSERT_TRUE(fromFilterState(m, &y, &Q));
  EXPECT_LT(x.boxminus(y).norm(), 1e-12);  // all 32 states, the calibrations' rotations included
  EXPECT_EQ(y.lidar.dt, x.lidar.dt);
  EXPECT_EQ(y.camera.dt, x.camera.dt);
  EXPECT_EQ(Q, P);
  // a broken calibration quaternion or a non-finite time shift is refused
  filter_state_t bad = m;
  for (double& q : bad.camera_orientation) q = 0.0;
  EXPECT_FALSE(fromFilterState(bad, &y, &Q));
  // a NaN in any of the hand-off's calibration fields or in the body rate is refused, whatever
  // the field (the VIO would otherwise render its references through it)
  const double nan = std::numeric_limits<double>::quiet_NaN();
  constexpr int kCameraDt = FilterState::kDim - 1, kCameraDtRow = kCameraDt * FilterState::kDim;
  const std::vector<std::pair<const char*, std::function<void(filter_state_t&)>>> poison = {
      {"angular_velocity", [&](filter_state_t& b) { b.angular_velocity[1] = nan; }},
      {"lidar_orientation", [&](filter_state_t& b) { b.lidar_orientation[2] = nan; }},
      {"lidar_position", [&](filter_state_t& b) { b.lidar_position[0] = nan; }},
      {"lidar_time_shift", [&](filter_state_t& b) { b.lidar_time_shift = nan; }},
      {"camera_orientation", [&](filter_state_t& b) { b.camera_orientation[3] = nan; }},
      {"camera_position", [&](filter_state_t& b) { b.camera_position[2] = nan; }},
      {"camera_time_shift", [&](filter_state_t& b) { b.camera_time_shift = nan; }},
      {"covariance (a calibration entry)",
       [&](filter_state_t& b) { b.covariance[kCameraDtRow + kCameraDt - 1] = nan; }},
  };
  for (const auto& [field, spoil] : poison) {
    bad = m;
    spoil(bad);
    EXPECT_FALSE(fromFilterState(bad, &y, &Q)) << field;
  }
  ASSERT_TRUE(fromFilterState(m, &y, &Q));  // and the message they were spoiled from still reads
}
