// The IMU's sensing-axis errors as states beside the filter (imu_intrinsics.hpp): the corrected
// reading's Jacobian and the propagation's Jacobians against numeric differentiation, the
// propagated covariance against the filter augmented with the twelve states, and a planted
// error recovered from pose measurements along a walk.
#include <gtest/gtest.h>

#include <random>

#include "livo/imu_axes.hpp"
#include "livo/lio/imu_propagator.hpp"
#include "synthetic_world.hpp"

using namespace livo;
using namespace livo::lio;

namespace {
ImuIntrinsics someIntrinsics() {
  ImuIntrinsics k;
  k.value << 0.012, -0.008, 0.005, 0.007, -0.004, 0.009, -0.006, 0.011, 0.003,  // gyro
      -0.006, 0.011, 0.003, -0.005, 0.008, 0.002, 0.004, -0.007, 0.006;         // accel
  return k;
}

using VecK = ImuIntrinsics::Vector;
using Vec12 = Eigen::Matrix<double, 12, 1>;

// δx_{i+1} as a function of (δx_i, w_i, δk) over the navigation states
Vec18 errorMap(const FilterState& xh, const ImuIntrinsics& kh, const Vec18& dx, const Vec12& w, const VecK& dk,
               const Vec3& gyro, const Vec3& accel, double dt) {
  StateVector d = StateVector::Zero();
  d.head<FilterState::kNavDim>() = dx;
  const FilterState x = xh.boxplus(d);
  ImuIntrinsics k = kh;
  k.value += dk;
  // the noise enters the readings: u = K w + b + n
  FilterState next = propagateState(x, gyro - w.segment<3>(0), accel - w.segment<3>(3), dt, k);
  next.gyro_bias += w.segment<3>(6) * dt;
  next.accel_bias += w.segment<3>(9) * dt;
  return next.boxminus(propagateState(xh, gyro, accel, dt, kh)).head<FilterState::kNavDim>();
}
}  // namespace

TEST(ImuIntrinsics, ReadingJacobianMatchesNumericDifferentiation) {
  const ImuIntrinsics k = someIntrinsics();
  const Vec3 u(0.4, -0.9, 9.7);
  const Vec3 w = k.gyroAxes().inverse() * u;
  const Eigen::Matrix<double, 3, 9> J = ImuIntrinsics::readingJacobian(k.gyroAxes(), w);
  const double h = 1e-7;
  for (int i = 0; i < 9; ++i) {
    ImuIntrinsics a = k, b = k;
    a.value[ImuIntrinsics::kGyroScale + i] += h;
    b.value[ImuIntrinsics::kGyroScale + i] -= h;
    const Vec3 num = (a.gyroAxes().inverse() * u - b.gyroAxes().inverse() * u) / (2 * h);
    EXPECT_LT((J.col(i) - num).norm(), 1e-7)
        << "column " << i << ": " << J.col(i).transpose() << " vs " << num.transpose();
  }
  // the simulator's sensing axes are the lower-triangular case of the filter's K
  const Vec3 scale(0.01, -0.02, 0.005), mis(0.003, -0.004, 0.006);
  ImuIntrinsics s;
  const Mat3 L = imuSensingAxes(scale, mis);
  s.value.segment<6>(ImuIntrinsics::kGyroCross) << L(0, 1), L(0, 2), L(1, 0), L(1, 2), L(2, 0), L(2, 1);
  s.value.segment<3>(ImuIntrinsics::kGyroScale) = L.diagonal() - Vec3::Ones();
  EXPECT_LT((s.gyroAxes() - L).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(ImuIntrinsics, PropagationJacobiansMatchNumericDifferentiation) {
  const FilterState x = synth::someState();
  const ImuIntrinsics k = someIntrinsics();
  const Vec3 gyro(0.4, -0.9, 1.7), accel(0.5, 2.0, 9.4);
  const double dt = 0.05, h = 1e-6;
  Mat18 Fx;
  Mat18x12 Fw;
  IntrinsicsJacobian Fm;
  propagationJacobians(x, gyro, accel, dt, &Fx, &Fw, k, &Fm);
  Mat18 Fx_num;
  Mat18x12 Fw_num;
  IntrinsicsJacobian Fm_num;
  const Vec12 z = Vec12::Zero();
  const VecK zk = VecK::Zero();
  for (int i = 0; i < 18; ++i) {
    Vec18 d = Vec18::Zero();
    d[i] = h;
    Fx_num.col(i) = (errorMap(x, k, d, z, zk, gyro, accel, dt) - errorMap(x, k, -d, z, zk, gyro, accel, dt)) / (2 * h);
  }
  for (int i = 0; i < 12; ++i) {
    Vec12 e = z;
    e[i] = h;
    Fw_num.col(i) = (errorMap(x, k, Vec18::Zero(), e, zk, gyro, accel, dt) -
                     errorMap(x, k, Vec18::Zero(), -e, zk, gyro, accel, dt)) /
                    (2 * h);
  }
  for (int i = 0; i < ImuIntrinsics::kDim; ++i) {
    VecK e = zk;
    e[i] = h;
    Fm_num.col(i) =
        (errorMap(x, k, Vec18::Zero(), z, e, gyro, accel, dt) - errorMap(x, k, Vec18::Zero(), z, -e, gyro, accel, dt)) /
        (2 * h);
  }
  EXPECT_LT((Fx - Fx_num).cwiseAbs().maxCoeff(), 1e-8) << Fx - Fx_num;
  EXPECT_LT((Fw - Fw_num).cwiseAbs().maxCoeff(), 1e-8) << Fw - Fw_num;
  EXPECT_LT((Fm - Fm_num).cwiseAbs().maxCoeff(), 1e-8) << Fm - Fm_num;
  EXPECT_GT(Fm.cwiseAbs().maxCoeff(), 1e-3);  // the test sees them
}

// The propagator's covariance, the intrinsics' cross-covariance and the clone's, against the
// 32 + 18 + 6 state filter propagated in full; then a pose update, conditioned beside the filter,
// against the Kalman update of that augmented filter.
TEST(ImuIntrinsics, CarriedBesideTheFilterEqualsTheAugmentedFilter) {
  constexpr int N = FilterState::kDim, K = ImuIntrinsics::kDim, A = N + K + 6;
  using MatA = Eigen::Matrix<double, A, A>;
  const ImuNoise noise{0.01, 0.1, 0.001, 0.01};
  const double dt = 0.005;
  const FilterState x0 = synth::someState();
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  StateCovariance L;
  for (int i = 0; i < L.size(); ++i) L.data()[i] = 0.02 * n01(rng);
  const StateCovariance P0 = L * L.transpose() + 1e-4 * StateCovariance::Identity();
  const ImuIntrinsics::Covariance Pk = intrinsicsPrior(0.01, 0.007, 0.01, 0.007);
  const Vec3 gyro(0.3, -0.4, 0.8), accel(0.3, 0.5, 9.9);
  ImuPropagator prop(noise);
  const ImuSample s0{0, gyro, accel};
  prop.setIntrinsics(someIntrinsics(), Pk, true);
  prop.reset(x0, P0, s0);
  MatA Pa = MatA::Zero();
  Pa.topLeftCorner<N, N>() = P0;
  Pa.block<K, K>(N, N) = Pk;
  FilterState x = x0;
  auto step = [&](int from, int to) {
    for (int i = from; i <= to; ++i) {
      ImuSample s = s0;
      s.utime = i * 5000;
      ASSERT_TRUE(prop.addSample(s));
      Mat18 Fx;
      Mat18x12 Fw;
      IntrinsicsJacobian Fm;
      propagationJacobians(x, gyro, accel, dt, &Fx, &Fw, prop.intrinsics(), &Fm);
      MatA F = MatA::Identity();
      F.topLeftCorner<18, 18>() = Fx;
      F.block<18, K>(0, N) = Fm;
      Eigen::Matrix<double, A, 12> G = Eigen::Matrix<double, A, 12>::Zero();
      G.topRows<18>() = Fw;
      Pa = F * Pa * F.transpose() + G * discreteNoiseCovariance(noise, dt) * G.transpose();
      x = propagateState(x, gyro, accel, dt, prop.intrinsics());
    }
  };
  step(1, 10);
  // clone the pose: the augmented filter's last six states become a copy of the pose
  prop.clonePose();
  Eigen::Matrix<double, A, A> Cl = MatA::Identity();
  Cl.block<6, 6>(N + K, N + K).setZero();
  Cl.block<6, 6>(N + K, 0).setIdentity();
  Pa = Cl * Pa * Cl.transpose();
  const Mat6 clone_cov = Pa.block<6, 6>(N + K, N + K);
  step(11, 30);
  auto compare = [&](const char* when) {
    const double scale = Pa.cwiseAbs().maxCoeff();
    EXPECT_LT((prop.covariance() - Pa.topLeftCorner<N, N>()).cwiseAbs().maxCoeff(), 1e-10 * scale) << when;
    EXPECT_LT((prop.intrinsicsCovariance() - Pa.block<K, K>(N, N)).cwiseAbs().maxCoeff(), 1e-10 * scale) << when;
    EXPECT_LT((prop.cloneCross() - Pa.block<N, 6>(0, N + K)).cwiseAbs().maxCoeff(), 1e-10 * scale) << when;
  };
  compare("after propagation");

  // a pose measurement of the current state: H = [I6 0], noise 1 mrad / 1 mm
  Eigen::Matrix<double, 6, A> H = Eigen::Matrix<double, 6, A>::Zero();
  H.leftCols<6>().setIdentity();
  Mat6 R = Mat6::Zero();
  R.diagonal() << Vec3::Constant(1e-6), Vec3::Constant(1e-6);
  Vec6 r;
  r << 0.002, -0.001, 0.003, 0.004, -0.002, 0.001;
  const Eigen::Matrix<double, A, 6> Kg = Pa * H.transpose() * (H * Pa * H.transpose() + R).inverse();
  const Eigen::Matrix<double, A, 1> da = Kg * r;
  MatA Pa_post = (MatA::Identity() - Kg * H) * Pa;
  Pa_post = 0.5 * (Pa_post + Pa_post.transpose());
  // the filter's own update (what the LiDAR stage does), then the conditioning beside it
  const FilterState x_post = prop.state().boxplus(da.head<N>());
  const VecK k_before = prop.intrinsics().value;
  prop.applyUpdate(x_post, Pa_post.topLeftCorner<N, N>());
  EXPECT_LT((prop.intrinsics().value - k_before - da.segment<K>(N)).cwiseAbs().maxCoeff(), 1e-9);
  // the clone is considered, not estimated: its block keeps its covariance
  Pa_post.block<6, 6>(N + K, N + K) = clone_cov;
  Pa = Pa_post;
  compare("after the update");
  EXPECT_LT((prop.intrinsicsCovariance() - Pk).diagonal().maxCoeff(), 0.0);  // it learnt something
}

// A walk with a gyro and an accelerometer whose axes are off by a per cent and milliradians, the
// body pose measured at 10 Hz (as registered sweeps measure it): the filter, starting from the
// nominal sensor, finds the planted errors within its own 3-sigma, and the gyro's scales, which
// the turns excite, to a fraction of their prior.
TEST(ImuIntrinsics, APlantedErrorIsRecoveredFromPoseMeasurements) {
  const auto traj = synth::roomTrajectory(0.0);
  const double rate = 200.0, duration = 60.0;
  std::mt19937 rng(3);
  std::normal_distribution<double> n01;
  ImuNoise noise{1.7e-4, 2.0e-3, 1.9e-5, 3.0e-3};
  noise.gyro_scale_std = 0.01;
  noise.gyro_misalignment_std = 0.007;
  noise.accel_scale_std = 0.01;
  noise.accel_misalignment_std = 0.007;
  std::vector<ImuSample> imu = synth::simulateImu(traj, 0.0, duration, rate, 0, synth::ImuErrorModel::exact(), &rng);
  const ImuIntrinsics truth = someIntrinsics();
  const double sg = noise.gyro_noise_density * std::sqrt(rate), sa = noise.accel_noise_density * std::sqrt(rate);
  for (ImuSample& s : imu) {
    s.gyro = truth.gyroAxes() * s.gyro;
    s.accel = truth.accelAxes() * s.accel;
    for (int a = 0; a < 3; ++a) {
      s.gyro[a] += sg * n01(rng);
      s.accel[a] += sa * n01(rng);
    }
  }
  ImuPropagator prop(noise);
  prop.setIntrinsics({}, intrinsicsPrior(noise), true);
  StateCovariance P0 = StateCovariance::Zero();
  P0.diagonal().head<18>() << Vec3::Constant(1e-6), Vec3::Constant(1e-6), Vec3::Constant(1e-4), Vec3::Constant(1e-6),
      Vec3::Constant(1e-4), Vec3::Constant(1e-6);
  prop.reset(traj.state(0.0), P0, imu.front());
  const double sr = 1e-3, sp = 2e-3;  // a registered sweep: about 0.06 deg and 2 mm
  size_t i = 1;
  for (int k = 1; k <= static_cast<int>(duration * 10) - 1; ++k) {
    const int64_t t_meas = static_cast<int64_t>(k) * 100000;
    while (i < imu.size() && imu[i].utime <= t_meas) prop.addSample(imu[i++]);
    const Pose3 T = traj.pose(static_cast<double>(t_meas) * 1e-6);
    const FilterState& x = prop.state();
    const StateCovariance& P = prop.covariance();
    Vec6 r;
    r.head<3>() = so3::Log(Mat3(x.rot.transpose() * T.linear())) + sr * Vec3(n01(rng), n01(rng), n01(rng));
    r.tail<3>() = T.translation() - x.pos + sp * Vec3(n01(rng), n01(rng), n01(rng));
    Mat6 S = P.topLeftCorner<6, 6>();
    S.diagonal() += (Vec6() << Vec3::Constant(sr * sr), Vec3::Constant(sp * sp)).finished();
    const Eigen::Matrix<double, FilterState::kDim, 6> Kg = P.leftCols<6>() * S.inverse();
    StateCovariance Pp = P - Kg * P.topRows<6>();
    prop.applyUpdate(x.boxplus(Kg * r), 0.5 * (Pp + Pp.transpose()));
  }
  const VecK err = prop.intrinsics().value - truth.value;
  const VecK sigma = prop.intrinsicsCovariance().diagonal().cwiseSqrt();
  for (int j = 0; j < ImuIntrinsics::kDim; ++j)
    EXPECT_LT(std::abs(err[j]), 3.0 * sigma[j]) << "state " << j << ": " << err.transpose();
  // the gyro's scales, excited by the turns, to a third of their prior or better
  for (int j = 0; j < 3; ++j) EXPECT_LT(sigma[ImuIntrinsics::kGyroScale + j], 0.01 / 3.0) << sigma.transpose();
}
