// Wheel-encoder preintegration: straight lines and a constant-speed circle against their closed
// forms, the residual at the truth and under known perturbations with a non-trivial extrinsic,
// the templated residual against the double one (and its Jet derivatives), and the covariance
// against its closed form on a straight line and the exact effect of noisy readings on a circle;
// the mounting correction: zero gives the residual without it exactly, the truth of a turned wheel
// frame is found through it, and its Jet derivatives against central differences.
#include <gtest/gtest.h>

#include <array>
#include <sstream>
#include <string>
#include <type_traits>

#include <Eigen/Eigenvalues>

#include "livo/wheel_preintegration.hpp"

#ifdef LIVO_HAVE_CERES_JET
#include <ceres/jet.h>
#endif

using namespace livo;

namespace {

WheelRig testRig() {
  WheelRig rig;
  rig.rate_hz = 50.0;
  rig.track_width = 0.6;
  rig.speed_noise_std = 0.02;
  rig.T_I_B = se3::fromRotationTranslation(so3::Exp(Vec3(0.1, -0.2, 0.3)), Vec3(-0.4, 0.1, -0.3));
  return rig;
}

// Constant forward speed v and yaw rate w, readings at the rig's rate for `duration` seconds.
WheelPreintegration drive(const WheelRig& rig, double v, double w, double duration,
                          const WheelPreintegrationNoise& noise = {}) {
  WheelPreintegration pre(rig, noise);
  const int n = static_cast<int>(std::lround(duration * rig.rate_hz));
  const double dt = duration / n;
  const double left = v - 0.5 * rig.track_width * w, right = v + 0.5 * rig.track_width * w;
  for (int k = 0; k < n; ++k) pre.integrate(left, right, left, right, dt);
  return pre;
}

// Pose of O after t seconds of the arc (v, w) in O at its start.
Pose3 arc(double v, double w, double t) {
  const double th = w * t;
  const Vec3 p = std::abs(w) < 1e-12 ? Vec3(v * t, 0, 0) : Vec3(v / w * std::sin(th), v / w * (1 - std::cos(th)), 0);
  return se3::fromRotationTranslation(so3::Exp(Vec3(0, 0, th)), p);
}

// IMU poses W_T_I whose wheel frame starts at T_W_O0 and follows the arc.
Pose3 imuPose(const WheelRig& rig, const Pose3& T_W_O0, double v, double w, double t) {
  return T_W_O0 * arc(v, w, t) * rig.T_I_B.inverse();
}

const Pose3 kStart = se3::fromRotationTranslation(so3::Exp(Vec3(0.1, 0.2, 1.0)), Vec3(5.0, -3.0, 1.0));

}  // namespace

TEST(WheelPreintegration, StraightLineIsExact) {
  const WheelRig rig = testRig();
  const WheelPreintegration pre = drive(rig, 2.0, 0.0, 1.5);
  EXPECT_NEAR(pre.duration(), 1.5, 1e-14);
  EXPECT_NEAR((pre.deltaR() - Mat3::Identity()).norm(), 0.0, 1e-15);
  EXPECT_NEAR((pre.deltaP() - Vec3(3.0, 0, 0)).norm(), 0.0, 1e-13);

  // a speed ramp 1 -> 3 m/s: the midpoint rule integrates a linear speed exactly (2 m)
  WheelPreintegration ramp(rig, WheelPreintegrationNoise{});
  const int n = 50;
  for (int k = 0; k < n; ++k) {
    const double v0 = 1.0 + 2.0 * k / n, v1 = 1.0 + 2.0 * (k + 1) / n;
    ramp.integrate(v0, v0, v1, v1, 1.0 / n);
  }
  EXPECT_NEAR((ramp.deltaP() - Vec3(2.0, 0, 0)).norm(), 0.0, 1e-13);
}

// On a circle each step is a chord of length v dt at the mean heading: the sum is the discrete
// closed form v dt sin(wT/2)/sin(w dt/2) at heading wT/2, the true arc's chord 2 v/w sin(wT/2)
// times (w dt/2)/sin(w dt/2) = 1 + (w dt)²/24 + ...
TEST(WheelPreintegration, CircleMatchesClosedForm) {
  const WheelRig rig = testRig();
  const double v = 2.0, w = 0.4, duration = 3.0, dt = 1.0 / rig.rate_hz;
  const WheelPreintegration pre = drive(rig, v, w, duration);
  const double half = 0.5 * w * duration;
  const Vec3 heading(std::cos(half), std::sin(half), 0.0);
  const Vec3 discrete = v * dt * std::sin(half) / std::sin(0.5 * w * dt) * heading;
  const Vec3 exact = arc(v, w, duration).translation();
  EXPECT_NEAR((pre.deltaR() - so3::Exp(Vec3(0, 0, w * duration))).norm(), 0.0, 1e-14);
  EXPECT_NEAR((pre.deltaP() - discrete).norm(), 0.0, 1e-13);
  const double gap = (pre.deltaP() - exact).norm() / exact.norm();
  EXPECT_NEAR(gap, (w * dt) * (w * dt) / 24.0, 1e-9);  // next term (w dt)^4 7/5760 ~ 5e-13
}

// At the true poses the residual is zero on a straight line and the discretisation's known chord
// excess on the circle, whatever the extrinsic and the start pose.
TEST(WheelPreintegration, ResidualAtTruth) {
  const WheelRig rig = testRig();
  const double duration = 2.0, dt = 1.0 / rig.rate_hz;
  for (double w : {0.0, 0.4}) {
    const double v = 2.0;
    const WheelPreintegration pre = drive(rig, v, w, duration);
    const Pose3 Ti = imuPose(rig, kStart, v, w, 0.0), Tj = imuPose(rig, kStart, v, w, duration);
    const Vec6 r = pre.residual(Ti.linear(), Ti.translation(), Tj.linear(), Tj.translation());
    EXPECT_NEAR(r.head<3>().norm(), 0.0, 1e-14) << w;
    const double excess = w == 0.0 ? 0.0 : 0.5 * w * dt / std::sin(0.5 * w * dt) - 1.0;
    EXPECT_NEAR((r.tail<3>() + excess * arc(v, w, duration).translation()).norm(), 0.0, 1e-13) << w;
  }
}

// Perturbations of the poses move the residual by their closed forms through the extrinsic, and
// the whitened cost of a translation error grows with its square.
TEST(WheelPreintegration, ResidualUnderPerturbation) {
  const WheelRig rig = testRig();
  const Mat3 R_IB = rig.T_I_B.linear();
  const Vec3 t_IB = rig.T_I_B.translation();
  const double v = 2.0, w = 0.4, duration = 2.0;
  const WheelPreintegration pre = drive(rig, v, w, duration);
  const Pose3 Ti = imuPose(rig, kStart, v, w, 0.0), Tj = imuPose(rig, kStart, v, w, duration);
  const Mat3 R_Oi = Ti.linear() * R_IB;
  const Vec6 r0 = pre.residual(Ti.linear(), Ti.translation(), Tj.linear(), Tj.translation());

  // rotation of the IMU at j by Exp(d): R_Oj -> R_Oj Exp(R_IB^T d), p_Oj -> p_Oj + R_j (Exp(d) - I) t_IB
  const Vec3 d(0.01, -0.02, 0.03);
  const Vec6 r1 = pre.residual(Ti.linear(), Ti.translation(), Tj.linear() * so3::Exp(d), Tj.translation());
  EXPECT_NEAR((r1.head<3>() - R_IB.transpose() * d).norm(), 0.0, 1e-14);  // r0's rotation is ~1e-16
  const Vec3 dp = R_Oi.transpose() * Tj.linear() * (so3::Exp(d) - Mat3::Identity()) * t_IB;
  EXPECT_NEAR((r1.tail<3>() - r0.tail<3>() - dp).norm(), 0.0, 1e-14);

  // translations at i and j
  const Vec3 e(0.05, -0.03, 0.02);
  const Vec6 rj = pre.residual(Ti.linear(), Ti.translation(), Tj.linear(), Tj.translation() + e);
  const Vec6 ri = pre.residual(Ti.linear(), Ti.translation() + e, Tj.linear(), Tj.translation());
  EXPECT_NEAR((rj.tail<3>() - r0.tail<3>() - R_Oi.transpose() * e).norm(), 0.0, 1e-14);
  EXPECT_NEAR((ri.tail<3>() - r0.tail<3>() + R_Oi.transpose() * e).norm(), 0.0, 1e-14);
  EXPECT_NEAR((rj.head<3>() - r0.head<3>()).norm(), 0.0, 1e-14);

  // whitened cost on a straight line (zero at the truth): exactly quadratic in the error
  const WheelPreintegration line = drive(rig, v, 0.0, duration);
  const Pose3 Lj = imuPose(rig, kStart, v, 0.0, duration);
  const Mat6 U = line.sqrtInformation();
  auto cost = [&](double s) {
    return (U * line.residual(Ti.linear(), Ti.translation(), Lj.linear(), Lj.translation() + s * e)).squaredNorm();
  };
  EXPECT_LT(cost(0.0), 1e-12);
  EXPECT_GT(cost(1.0), 1.0);  // a few cm against position sigmas of 0.3 (forward) to 5 cm over 4 m
  EXPECT_NEAR(cost(2.0) / cost(1.0), 4.0, 1e-9);
}

TEST(WheelPreintegration, TemplatedResidualEqualsDouble) {
  const WheelRig rig = testRig();
  const WheelPreintegration pre = drive(rig, 2.0, 0.4, 2.0);
  const Pose3 Ti = imuPose(rig, kStart, 2.0, 0.4, 0.0), Tj = imuPose(rig, kStart, 2.0, 0.4, 2.0);
  const Mat3 R_i = Ti.linear() * so3::Exp(Vec3(0.02, -0.01, 0.03)),
             R_j = Tj.linear() * so3::Exp(Vec3(-0.02, 0.01, 0.02));
  const Vec3 p_i = Ti.translation() + Vec3(0.1, -0.05, 0.02), p_j = Tj.translation() + Vec3(-0.03, 0.2, 0.1);
  const Vec6 expected = pre.residual(R_i, p_i, R_j, p_j);
  const Eigen::Vector4d q_i = Quat(R_i).coeffs(), q_j = Quat(R_j).coeffs();
  Vec6 r;
  pre.residual(q_i.data(), p_i.data(), q_j.data(), p_j.data(), r.data());
  EXPECT_GT(expected.norm(), 0.05);
  EXPECT_NEAR((r - expected).norm(), 0.0, 1e-13);  // |terms| < 10: rounding only
}

// On a straight line at speed v the discrete covariance has a closed form (N steps of dt = T/N,
// per-interval variances sigma² / (rate dt)): with q_yaw = 2 s² / (b² rate) and q_rp = rp² / rate,
//   var(yaw) = q_yaw T, var(y) = q_yaw v² (T³/3 - T dt²/12) + lat² T / rate, cov(yaw, y) = q_yaw v T²/2,
//   var(pitch) = q_rp T, var(z) = q_rp v² (T³/3 - T dt²/12) + vert² T / rate, cov(pitch, z) = -q_rp v T²/2,
//   var(roll) = q_rp T, var(x) = s² T / (2 rate);
// it is positive definite and grows with the distance.
TEST(WheelPreintegration, CovarianceClosedFormOnAStraightLine) {
  const WheelRig rig = testRig();
  const WheelPreintegrationNoise noise = WheelPreintegrationNoise::fromRig(rig);
  EXPECT_EQ(noise.speed_std, rig.speed_noise_std);
  const double v = 2.0, dt = 1.0 / rig.rate_hz, rate = rig.rate_hz, b = rig.track_width;
  Mat6 previous = Mat6::Zero();
  for (double T : {0.5, 1.0, 2.0, 4.0}) {
    const WheelPreintegration pre = drive(rig, v, 0.0, T, noise);
    const double q_yaw = 2.0 * noise.speed_std * noise.speed_std / (b * b * rate);
    const double q_rp = noise.roll_pitch_rate_std * noise.roll_pitch_rate_std / rate;
    const double cubic = T * T * T / 3.0 - T * dt * dt / 12.0;
    Mat6 expected = Mat6::Zero();
    expected(0, 0) = q_rp * T;
    expected(1, 1) = q_rp * T;
    expected(2, 2) = q_yaw * T;
    expected(3, 3) = noise.speed_std * noise.speed_std * T / (2.0 * rate);
    expected(4, 4) = q_yaw * v * v * cubic + noise.lateral_speed_std * noise.lateral_speed_std * T / rate;
    expected(5, 5) = q_rp * v * v * cubic + noise.vertical_speed_std * noise.vertical_speed_std * T / rate;
    expected(2, 4) = expected(4, 2) = q_yaw * v * T * T / 2.0;
    expected(1, 5) = expected(5, 1) = -q_rp * v * T * T / 2.0;
    EXPECT_NEAR((pre.covariance() - expected).norm(), 0.0, 1e-12 * expected.norm()) << T;
    const Eigen::SelfAdjointEigenSolver<Mat6> eig(pre.covariance());
    EXPECT_GT(eig.eigenvalues().minCoeff(), 0.0) << T;
    const Eigen::SelfAdjointEigenSolver<Mat6> growth(pre.covariance() - previous);
    EXPECT_GT(growth.eigenvalues().minCoeff(), 0.0) << T;  // every direction more uncertain
    previous = pre.covariance();
  }
}

// The covariance of the measured directions (yaw, forward and lateral position) on a circle
// against the exact first-order effect of white noise of speed_std on every reading: the
// sensitivity G_m of the end error to each reading, by central differences of the integration,
// gives Cov = speed_std² sum_m G_m G_m^T. The model counts each interval's mean as one independent
// reading, while the trapezoid sums of the readings have O(1/N) less variance (1/(2N) for the yaw,
// about 3/(4N) for the lateral position): whitened by the model, the exact covariance has
// eigenvalues in [1 - 2/N, 1]. The unmeasured directions get nothing when their sigmas are 0.
TEST(WheelPreintegration, CovarianceMatchesReadingNoise) {
  const WheelRig rig = testRig();
  WheelPreintegrationNoise noise = WheelPreintegrationNoise::fromRig(rig);
  noise.lateral_speed_std = noise.vertical_speed_std = noise.roll_pitch_rate_std = 0.0;
  const double v = 2.0, w = 0.4, duration = 2.0;
  const int n = static_cast<int>(std::lround(duration * rig.rate_hz));
  const double dt = duration / n;
  const double left = v - 0.5 * rig.track_width * w, right = v + 0.5 * rig.track_width * w;
  // readings' noise: [left_0 .. left_n, right_0 .. right_n]
  auto integrateWith = [&](const Eigen::VectorXd& e) {
    WheelPreintegration pre(rig, noise);
    for (int k = 0; k < n; ++k)
      pre.integrate(left + e[k], right + e[n + 1 + k], left + e[k + 1], right + e[n + 2 + k], dt);
    return pre;
  };
  const WheelPreintegration ref = integrateWith(Eigen::VectorXd::Zero(2 * (n + 1)));
  auto endError = [&](const WheelPreintegration& pre) {
    Vec6 e;
    e << so3::Log(Mat3(ref.deltaR().transpose() * pre.deltaR())), pre.deltaP() - ref.deltaP();
    return e;
  };
  const double h = 1e-6;  // the error is smooth in the noise: truncation ~ h² * O(1), rounding ~ 1e-16 / h
  Mat6 exact = Mat6::Zero();
  for (int m = 0; m < 2 * (n + 1); ++m) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(2 * (n + 1));
    e[m] = h;
    const Vec6 plus = endError(integrateWith(e));
    e[m] = -h;
    const Vec6 G = (plus - endError(integrateWith(e))) / (2 * h);
    exact += rig.speed_noise_std * rig.speed_noise_std * G * G.transpose();
  }
  const std::array<int, 3> measured{{2, 3, 4}}, unmeasured{{0, 1, 5}};
  Mat3 model_block, exact_block;
  for (int a = 0; a < 3; ++a) {
    for (int c = 0; c < 3; ++c) {
      model_block(a, c) = ref.covariance()(measured[a], measured[c]);
      exact_block(a, c) = exact(measured[a], measured[c]);
    }
    EXPECT_EQ(ref.covariance().row(unmeasured[a]).norm(), 0.0);
  }
  const Mat3 Linv = Mat3(model_block.llt().matrixL()).inverse();
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(Linv * exact_block * Linv.transpose());
  EXPECT_GT(eig.eigenvalues().minCoeff(), 1.0 - 2.0 / n);
  EXPECT_LT(eig.eigenvalues().maxCoeff(), 1.0 + 1e-6);
}

// Readings whose speeds vary (a slalom): the scale Jacobians against re-integrating with scaled speeds.
WheelPreintegration slalom(const WheelRig& rig, double s_left, double s_right) {
  WheelPreintegration pre(rig, WheelPreintegrationNoise{});
  const double dt = 1.0 / rig.rate_hz;
  auto left = [](double t) { return 2.0 + 0.5 * std::sin(1.3 * t); };
  auto right = [](double t) { return 2.0 + 0.8 * std::cos(0.9 * t); };
  for (int k = 0; k < 150; ++k) {
    const double t0 = k * dt, t1 = (k + 1) * dt;
    pre.integrate(s_left * left(t0), s_right * right(t0), s_left * left(t1), s_right * right(t1), dt);
  }
  return pre;
}

TEST(WheelPreintegration, ScaleJacobiansMatchCentralDifferences) {
  const WheelRig rig = testRig();
  const WheelPreintegration pre = slalom(rig, 1.0, 1.0);
  const double h = 1e-6;
  for (int i = 0; i < 2; ++i) {
    const double d[2] = {i == 0 ? h : 0.0, i == 1 ? h : 0.0};
    const WheelPreintegration plus = slalom(rig, 1.0 + d[0], 1.0 + d[1]);
    const WheelPreintegration minus = slalom(rig, 1.0 - d[0], 1.0 - d[1]);
    const Vec3 dtheta = so3::Log(Mat3(minus.deltaR().transpose() * plus.deltaR())) / (2 * h);
    const Vec3 dp = (plus.deltaP() - minus.deltaP()) / (2 * h);
    EXPECT_LT((dtheta - pre.rotationScaleJacobian().col(i)).norm(), 1e-6) << "scale " << i;
    EXPECT_LT((dp - pre.positionScaleJacobian().col(i)).norm(), 1e-5)
        << "scale " << i << ": " << dp.transpose() << " vs " << pre.positionScaleJacobian().col(i).transpose();
  }
  // the yaw depends on the scales, the position too (3 s at about 2 m/s)
  EXPECT_GT(pre.rotationScaleJacobian().row(2).norm(), 1.0);
  EXPECT_GT(pre.positionScaleJacobian().norm(), 3.0);
}

TEST(WheelPreintegration, ScaleCorrectionIsSecondOrder) {
  // Tyres about 1 % off (left large, right small): the poses the true speeds give leave a residual
  // on the nominal preintegration; the scale-corrected residual is second order in the scale error
  // (halving the error quarters it) where the uncorrected one is first order (halves).
  const WheelRig rig = testRig();
  const WheelPreintegration nominal = slalom(rig, 1.0, 1.0);
  double corrected_norm[2], uncorrected_norm[2];
  for (int k = 0; k < 2; ++k) {
    const double e = k == 0 ? 1.0 : 0.5;
    const double sl = 1.0 + 0.012 * e, sr = 1.0 - 0.006 * e;
    const WheelPreintegration truth = slalom(rig, sl, sr);
    const Pose3 Ti = kStart * rig.T_I_B.inverse();
    const Pose3 Tj = kStart * se3::fromRotationTranslation(truth.deltaR(), truth.deltaP()) * rig.T_I_B.inverse();
    const Quat qi(Ti.linear()), qj(Tj.linear());
    const Vec3 pi = Ti.translation(), pj = Tj.translation();
    Vec6 uncorrected, corrected, at_truth;
    const double unit[2] = {1.0, 1.0}, scale[2] = {sl, sr};
    nominal.residual(qi.coeffs().data(), pi.data(), qj.coeffs().data(), pj.data(), unit, uncorrected.data());
    nominal.residual(qi.coeffs().data(), pi.data(), qj.coeffs().data(), pj.data(), scale, corrected.data());
    truth.residual(qi.coeffs().data(), pi.data(), qj.coeffs().data(), pj.data(), at_truth.data());
    EXPECT_LT(at_truth.norm(), 1e-9);
    corrected_norm[k] = corrected.norm();
    uncorrected_norm[k] = uncorrected.norm();
    EXPECT_LT(corrected_norm[k], 0.1 * uncorrected_norm[k])
        << corrected.transpose() << " vs " << uncorrected.transpose();
  }
  EXPECT_NEAR(uncorrected_norm[0] / uncorrected_norm[1], 2.0, 0.2);
  EXPECT_NEAR(corrected_norm[0] / corrected_norm[1], 4.0, 0.4);
}

// A mounting correction of zero is the residual without one, to the last bit (the graphs' outputs
// without a stated wheel calibration must not move), with and without the scales.
TEST(WheelPreintegration, ZeroMountingIsTheResidualWithoutIt) {
  const WheelRig rig = testRig();
  const WheelPreintegration pre = slalom(rig, 1.0, 1.0);
  const Pose3 Ti = kStart * rig.T_I_B.inverse();
  const Pose3 Tj = Ti * se3::fromRotationTranslation(so3::Exp(Vec3(0.02, -0.03, 0.5)), Vec3(5.0, 0.4, -0.2));
  const Quat qi(Ti.linear()), qj(Tj.linear());
  const Vec3 pi = Ti.translation(), pj = Tj.translation();
  const double unit[2] = {1.0, 1.0}, scale[2] = {1.012, 0.994}, zero[3] = {0.0, 0.0, 0.0};
  Vec6 plain, with_unit, scaled, mounted_unit, mounted_scaled;
  pre.residual(qi.coeffs().data(), pi.data(), qj.coeffs().data(), pj.data(), plain.data());
  pre.residual(qi.coeffs().data(), pi.data(), qj.coeffs().data(), pj.data(), unit, with_unit.data());
  pre.residual(qi.coeffs().data(), pi.data(), qj.coeffs().data(), pj.data(), scale, scaled.data());
  pre.residual(qi.coeffs().data(), pi.data(), qj.coeffs().data(), pj.data(), unit, zero, mounted_unit.data());
  pre.residual(qi.coeffs().data(), pi.data(), qj.coeffs().data(), pj.data(), scale, zero, mounted_scaled.data());
  EXPECT_GT(plain.norm(), 0.1);
  EXPECT_TRUE(mounted_unit == plain) << (mounted_unit - plain).transpose();
  EXPECT_TRUE(mounted_unit == with_unit);
  EXPECT_TRUE(mounted_scaled == scaled) << (mounted_scaled - scaled).transpose();
}

// The wheels of a rig whose wheel frame is truly R_IB Exp(δ) (turned 0.7 deg in pitch, 1 deg in
// yaw, 0.3 deg in roll): the IMU poses of that truth leave a residual on the nominal frame that
// grows with the distance (the speed seen sideways and upwards), and none through the correction δ.
TEST(WheelPreintegration, MountingCorrectionFindsATurnedWheelFrame) {
  const WheelRig rig = testRig();
  const Vec3 delta = Vec3(0.3, 0.7, 1.0) * (M_PI / 180.0);
  const Pose3 T_I_O = rig.T_I_B * se3::fromRotationTranslation(so3::Exp(delta), Vec3::Zero());
  const double v = 2.0, duration = 2.0, unit[2] = {1.0, 1.0}, zero[3] = {0.0, 0.0, 0.0};
  const WheelPreintegration pre = drive(rig, v, 0.0, duration);  // a straight line: exact at the truth
  const Pose3 Ti = kStart * T_I_O.inverse(), Tj = kStart * arc(v, 0.0, duration) * T_I_O.inverse();
  const Quat qi(Ti.linear()), qj(Tj.linear());
  const Vec3 pi = Ti.translation(), pj = Tj.translation();
  Vec6 nominal, corrected;
  pre.residual(qi.coeffs().data(), pi.data(), qj.coeffs().data(), pj.data(), unit, zero, nominal.data());
  pre.residual(qi.coeffs().data(), pi.data(), qj.coeffs().data(), pj.data(), unit, delta.data(), corrected.data());
  EXPECT_LT(corrected.norm(), 1e-12) << corrected.transpose();
  // nominal: the 4 m driven appear in the turned frame, about 4 m x (yaw, -pitch) to first order
  const Vec3 seen = so3::Exp(delta) * Vec3(v * duration, 0.0, 0.0);
  EXPECT_NEAR((nominal.tail<3>() - (seen - Vec3(v * duration, 0.0, 0.0))).norm(), 0.0, 1e-12) << nominal.transpose();
  EXPECT_NEAR(nominal(4), v * duration * delta.z(), 1e-3);
  EXPECT_NEAR(nominal(5), -v * duration * delta.y(), 1e-3);
}

TEST(WheelPreintegration, ZeroAndNegativeIntervals) {
  const WheelRig rig = testRig();
  WheelPreintegration pre = drive(rig, 1.0, 0.2, 0.5);
  const Vec3 p = pre.deltaP();
  const Mat6 c = pre.covariance();
  pre.integrate(1, 2, 3, 4, 0.0);
  EXPECT_TRUE(pre.deltaP() == p);
  EXPECT_TRUE(pre.covariance() == c);
  EXPECT_THROW(pre.integrate(1, 1, 1, 1, -0.01), std::invalid_argument);
}

#ifdef LIVO_HAVE_CERES_JET
namespace {
/// The 6 residuals of `residual` (callable on double and on Jet parameters) at `x` as Jets, in
/// `rj`, their derivatives checked against central differences: each finite (fatal otherwise) and
/// within 1e-7; `what` names the case in a failure. The step h = 1e-6: truncation ~ h² |f'''| / 6
/// < 1e-10, rounding ~ 1e-16 * 10 / h = 1e-9, both below 1e-8 at |terms| ~ 10.
template <int kParams, class Residual>
void expectJetMatchesCentralDifferences(const Residual& residual, const Eigen::Matrix<double, kParams, 1>& x,
                                        const std::string& what,
                                        Eigen::Matrix<ceres::Jet<double, kParams>, 6, 1>* rj_out) {
  using J = ceres::Jet<double, kParams>;
  std::array<J, kParams> xj;
  for (int i = 0; i < kParams; ++i) xj[i] = J(x[i], i);
  Eigen::Matrix<J, 6, 1>& rj = *rj_out;
  rj = residual(xj.data());
  const double h = 1e-6;
  for (int i = 0; i < kParams; ++i) {
    Eigen::Matrix<double, kParams, 1> xp = x, xm = x;
    xp[i] += h;
    xm[i] -= h;
    const Vec6 numeric = (residual(xp.data()) - residual(xm.data())) / (2 * h);
    for (int k = 0; k < 6; ++k) {
      ASSERT_TRUE(std::isfinite(rj[k].v[i]));
      EXPECT_NEAR(rj[k].v[i], numeric[k], 1e-7) << what << " residual " << k << " parameter " << i;
    }
  }
}
}  // namespace

// The derivatives Ceres' AutoDiff would take against central differences of the double residual,
// at a perturbed state and at the truth of a straight line (zero rotation residual).
TEST(WheelPreintegrationJet, DerivativesMatchCentralDifferences) {
  constexpr int kParams = 14;  // q_i p_i q_j p_j
  using J = ceres::Jet<double, kParams>;
  const WheelRig rig = testRig();
  for (double w : {0.4, 0.0}) {
    const WheelPreintegration pre = drive(rig, 2.0, w, 2.0);
    const Pose3 Ti = imuPose(rig, kStart, 2.0, w, 0.0), Tj = imuPose(rig, kStart, 2.0, w, 2.0);
    const Mat3 R_j = w == 0.0 ? Mat3(Tj.linear()) : Mat3(Tj.linear() * so3::Exp(Vec3(-0.02, 0.01, 0.02)));
    Eigen::Matrix<double, kParams, 1> x;
    x << Quat(Ti.linear()).coeffs(), Ti.translation(), Quat(R_j).coeffs(), Tj.translation();
    auto residual = [&](const auto* p) {
      using T = std::decay_t<decltype(*p)>;
      Eigen::Matrix<T, 6, 1> r;
      pre.residual(p, p + 4, p + 7, p + 11, r.data());
      return r;
    };
    std::ostringstream what;
    what << "w " << w;
    Eigen::Matrix<J, 6, 1> rj;
    ASSERT_NO_FATAL_FAILURE(expectJetMatchesCentralDifferences<kParams>(residual, x, what.str(), &rj));
  }
}

// The derivatives with respect to the mounting correction δ (and the poses and scales with it)
// that Ceres' AutoDiff takes, against central differences of the residual, at δ = 0 (the start of
// every run) and at a turned frame, on an arc and with scales off one.
TEST(WheelPreintegrationJet, MountingDerivativesMatchCentralDifferences) {
  constexpr int kParams = 19;  // q_i p_i q_j p_j s δ
  using J = ceres::Jet<double, kParams>;
  const WheelRig rig = testRig();
  const WheelPreintegration pre = slalom(rig, 1.0, 1.0);
  const Pose3 Ti = kStart * rig.T_I_B.inverse();
  const Pose3 Tj = Ti * se3::fromRotationTranslation(so3::Exp(Vec3(0.02, -0.03, 0.5)), Vec3(5.0, 0.4, -0.2));
  for (const Vec3& delta : {Vec3::Zero().eval(), Vec3(0.012, -0.009, 0.017)}) {
    Eigen::Matrix<double, kParams, 1> x;
    x << Quat(Ti.linear()).coeffs(), Ti.translation(), Quat(Tj.linear()).coeffs(), Tj.translation(), 1.01, 0.995, delta;
    auto residual = [&](const auto* p) {
      using T = std::decay_t<decltype(*p)>;
      Eigen::Matrix<T, 6, 1> r;
      pre.residual(p, p + 4, p + 7, p + 11, p + 14, p + 16, r.data());
      return r;
    };
    std::ostringstream what;
    what << "delta " << delta.transpose();
    Eigen::Matrix<J, 6, 1> rj;
    ASSERT_NO_FATAL_FAILURE(expectJetMatchesCentralDifferences<kParams>(residual, x, what.str(), &rj));
    // the mounting moves the translation residual by about the distance driven (5 m) per radian
    double mounting_gain = 0.0;
    for (int i = 16; i < kParams; ++i)
      for (int k = 3; k < 6; ++k) mounting_gain = std::max(mounting_gain, std::abs(rj[k].v[i]));
    EXPECT_GT(mounting_gain, 4.0);
  }
}
#endif  // LIVO_HAVE_CERES_JET
