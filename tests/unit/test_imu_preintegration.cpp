// IMU preintegration against an analytic trajectory: the prediction against the exact end state
// at two rates (second order), the residual at the truth, the bias Jacobians and corrections
// against re-integration, the covariance against a Monte-Carlo of noisy integrations, and the
// templated residual against the double one (and its Jet derivatives against central differences).
#include <gtest/gtest.h>

#include <array>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>

#include "livo/imu_preintegration.hpp"

#ifdef LIVO_HAVE_CERES_JET
#include <ceres/jet.h>
#endif

using namespace livo;

namespace {

const Vec3 kGravity(0.0, 0.0, -9.81);
const Vec3 kGyroBias(0.012, -0.021, 0.015);
const Vec3 kAccelBias(0.11, -0.05, 0.08);

// Smooth 3D motion: each position axis and each Euler angle (roll, pitch, yaw; R = Rz Ry Rx) is
// amp sin(freq t + phase) (+ drift t), so positions, rates and specific forces are exact.
struct Motion {
  Vec3 amp{1.5, 1.0, 0.4}, freq{0.9, 1.3, 1.7}, phase{0.0, 1.2, 0.3};
  Vec3 e_amp{0.3, 0.25, 0.6}, e_freq{1.1, 0.8, 0.7}, e_phase{0.0, 0.5, 0.2}, e_drift{0.0, 0.0, 0.5};

  // d^n/dt^n of amp sin(freq t + phase), per axis
  static Vec3 sinusoid(const Vec3& a, const Vec3& f, const Vec3& ph, double t, int n) {
    Vec3 r;
    for (int i = 0; i < 3; ++i) r[i] = a[i] * std::pow(f[i], n) * std::sin(f[i] * t + ph[i] + n * M_PI / 2);
    return r;
  }
  Vec3 position(double t) const { return sinusoid(amp, freq, phase, t, 0); }
  Vec3 velocity(double t) const { return sinusoid(amp, freq, phase, t, 1); }
  Vec3 acceleration(double t) const { return sinusoid(amp, freq, phase, t, 2); }
  Vec3 euler(double t) const { return sinusoid(e_amp, e_freq, e_phase, t, 0) + e_drift * t; }
  Vec3 eulerRate(double t) const { return sinusoid(e_amp, e_freq, e_phase, t, 1) + e_drift; }

  Mat3 rotation(double t) const {
    const Vec3 e = euler(t);
    return (Eigen::AngleAxisd(e.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(e.y(), Vec3::UnitY()) *
            Eigen::AngleAxisd(e.x(), Vec3::UnitX()))
        .toRotationMatrix();
  }
  // R^T dR/dt = hat(w): w = roll' x + Rx^T (pitch' y + Ry^T yaw' z)
  Vec3 bodyRate(double t) const {
    const Vec3 e = euler(t), de = eulerRate(t);
    const Mat3 Rx = Eigen::AngleAxisd(e.x(), Vec3::UnitX()).toRotationMatrix();
    const Mat3 Ry = Eigen::AngleAxisd(e.y(), Vec3::UnitY()).toRotationMatrix();
    return de.x() * Vec3::UnitX() +
           Rx.transpose() * (de.y() * Vec3::UnitY() + Ry.transpose() * (de.z() * Vec3::UnitZ()));
  }
  Vec3 specificForce(double t) const { return rotation(t).transpose() * (acceleration(t) - kGravity); }
};

// Preintegrates [t0, t0 + duration] from samples at `rate` Hz (biases added), each interval with the
// mean of its two samples, plus white noise of the discrete covariance density² / dt if rng is set.
ImuPreintegration preintegrate(const Motion& m, double t0, double duration, double rate, const Vec3& lin_bg,
                               const Vec3& lin_ba, const ImuPreintegrationNoise& noise = {},
                               std::mt19937* rng = nullptr) {
  ImuPreintegration pre(lin_bg, lin_ba, noise);
  const int n = static_cast<int>(std::lround(duration * rate));
  const double dt = duration / n;
  std::normal_distribution<double> normal;
  for (int k = 0; k < n; ++k) {
    const double ta = t0 + k * dt, tb = t0 + (k + 1) * dt;
    Vec3 w = 0.5 * (m.bodyRate(ta) + m.bodyRate(tb)) + kGyroBias;
    Vec3 a = 0.5 * (m.specificForce(ta) + m.specificForce(tb)) + kAccelBias;
    if (rng) {
      for (int i = 0; i < 3; ++i) {
        w[i] += noise.gyro_noise_density / std::sqrt(dt) * normal(*rng);
        a[i] += noise.accel_noise_density / std::sqrt(dt) * normal(*rng);
      }
    }
    pre.integrate(w, a, dt);
  }
  return pre;
}

struct EndError {
  double rot, vel, pos;
};

EndError predictionError(const Motion& m, double t0, double duration, double rate) {
  const ImuPreintegration pre = preintegrate(m, t0, duration, rate, kGyroBias, kAccelBias);
  Mat3 R;
  Vec3 p, v;
  pre.predict(m.rotation(t0), m.position(t0), m.velocity(t0), kGyroBias, kAccelBias, kGravity, &R, &p, &v);
  const double t1 = t0 + duration;
  return {so3::Log(Mat3(R.transpose() * m.rotation(t1))).norm(), (v - m.velocity(t1)).norm(),
          (p - m.position(t1)).norm()};
}

}  // namespace

// The trajectory's rates are those of its rotation: R^T dR/dt = hat(w) by central differences.
TEST(ImuPreintegrationMotion, BodyRateIsTheRotationsDerivative) {
  const Motion m;
  const double h = 1e-5;
  for (double t : {0.0, 0.37, 1.9}) {
    const Mat3 dR = (m.rotation(t + h) - m.rotation(t - h)) / (2 * h);
    // central difference error ~ h² |d³R/dt³| / 6 < 1e-10; rounding ~ 1e-16 / h = 1e-11
    EXPECT_NEAR((so3::vee(m.rotation(t).transpose() * dR) - m.bodyRate(t)).norm(), 0.0, 1e-9);
  }
}

// The prediction from the true state at i against the true state at j. The scheme is second order
// (header): from 200 to 1000 Hz every error falls by 25 (the next term changes that by ~(dt f)²,
// f < 2 rad/s: 1e-4 relative, so 2 % would catch a first (5) or third (125) order). And the
// discretisation at 200 Hz is negligible against the noise the covariance assigns over the same
// interval (rig-default densities): below a tenth of each block's sigma.
TEST(ImuPreintegration, PredictMatchesTrueEndStateAtSecondOrder) {
  const Motion m;
  for (double duration : {0.1, 1.0}) {
    const EndError e200 = predictionError(m, 0.3, duration, 200.0);
    const EndError e1000 = predictionError(m, 0.3, duration, 1000.0);
    EXPECT_NEAR(e200.rot / e1000.rot, 25.0, 0.5) << duration;
    EXPECT_NEAR(e200.vel / e1000.vel, 25.0, 0.5) << duration;
    EXPECT_NEAR(e200.pos / e1000.pos, 25.0, 0.5) << duration;
    const Mat9 cov = preintegrate(m, 0.3, duration, 200.0, kGyroBias, kAccelBias).covariance();
    EXPECT_LT(e200.rot, 0.1 * std::sqrt(cov.block<3, 3>(0, 0).trace())) << duration;
    EXPECT_LT(e200.vel, 0.1 * std::sqrt(cov.block<3, 3>(3, 3).trace())) << duration;
    EXPECT_LT(e200.pos, 0.1 * std::sqrt(cov.block<3, 3>(6, 6).trace())) << duration;
  }
}

// At the true end state the residual is the prediction error, expressed in frame i; at the
// predicted one it vanishes.
TEST(ImuPreintegration, ResidualAtTruthIsThePredictionError) {
  const Motion m;
  const double t0 = 0.3, t1 = 1.3;
  const ImuPreintegration pre = preintegrate(m, t0, t1 - t0, 200.0, kGyroBias, kAccelBias);
  const Mat3 R_i = m.rotation(t0), R_j = m.rotation(t1);
  const Vec3 p_i = m.position(t0), v_i = m.velocity(t0), p_j = m.position(t1), v_j = m.velocity(t1);
  Mat3 R_pred;
  Vec3 p_pred, v_pred;
  pre.predict(R_i, p_i, v_i, kGyroBias, kAccelBias, kGravity, &R_pred, &p_pred, &v_pred);

  const Vec9 at_pred = pre.residual(R_i, p_i, v_i, R_pred, p_pred, v_pred, kGyroBias, kAccelBias, kGravity);
  // rounding of sums of terms up to |g| dt² / 2 ~ 5 m: ~1e-15 * 5 per operation
  EXPECT_LT(at_pred.norm(), 1e-13);

  const Vec9 at_truth = pre.residual(R_i, p_i, v_i, R_j, p_j, v_j, kGyroBias, kAccelBias, kGravity);
  Vec9 expected;
  expected << so3::Log(Mat3(R_pred.transpose() * R_j)), R_i.transpose() * (v_j - v_pred),
      R_i.transpose() * (p_j - p_pred);
  EXPECT_GT(expected.norm(), 1e-7);                // the integration error is well above rounding ...
  EXPECT_LT((at_truth - expected).norm(), 1e-13);  // ... and the residual is it, to rounding
}

// ∂(increments)/∂(linearisation biases) against central differences of re-integrating the same
// samples with perturbed biases.
TEST(ImuPreintegration, BiasJacobiansMatchCentralDifferences) {
  const Motion m;
  const double t0 = 0.3, duration = 1.0, rate = 200.0;
  const ImuPreintegration pre = preintegrate(m, t0, duration, rate, kGyroBias, kAccelBias);
  // Central differences err by h² |f'''| / 6; the third derivatives of the increments in the
  // biases are at most ~ duration^5 |a| < 20 here, so 1e-8 * 20 / 6 ~ 3e-8; rounding ~ 1e-16 / h.
  const double h = 1e-4;
  Mat3 R_g, V_g, P_g, V_a, P_a;
  for (int i = 0; i < 3; ++i) {
    const Vec3 d = Vec3::Unit(i) * h;
    const ImuPreintegration gp = preintegrate(m, t0, duration, rate, kGyroBias + d, kAccelBias);
    const ImuPreintegration gm = preintegrate(m, t0, duration, rate, kGyroBias - d, kAccelBias);
    R_g.col(i) = (so3::Log(Mat3(pre.deltaR().transpose() * gp.deltaR())) -
                  so3::Log(Mat3(pre.deltaR().transpose() * gm.deltaR()))) /
                 (2 * h);
    V_g.col(i) = (gp.deltaV() - gm.deltaV()) / (2 * h);
    P_g.col(i) = (gp.deltaP() - gm.deltaP()) / (2 * h);
    const ImuPreintegration ap = preintegrate(m, t0, duration, rate, kGyroBias, kAccelBias + d);
    const ImuPreintegration am = preintegrate(m, t0, duration, rate, kGyroBias, kAccelBias - d);
    V_a.col(i) = (ap.deltaV() - am.deltaV()) / (2 * h);
    P_a.col(i) = (ap.deltaP() - am.deltaP()) / (2 * h);
    EXPECT_TRUE(ap.deltaR() == pre.deltaR());  // the accelerometer bias does not rotate
  }
  EXPECT_GT(pre.dR_dbg().norm(), 1.0);  // non-trivial: ~ duration per axis
  EXPECT_NEAR((pre.dR_dbg() - R_g).norm(), 0.0, 1e-6);
  EXPECT_NEAR((pre.dV_dbg() - V_g).norm(), 0.0, 1e-6);
  EXPECT_NEAR((pre.dP_dbg() - P_g).norm(), 0.0, 1e-6);
  EXPECT_NEAR((pre.dV_dba() - V_a).norm(), 0.0, 1e-6);
  EXPECT_NEAR((pre.dP_dba() - P_a).norm(), 0.0, 1e-6);
}

// The first-order correction for a bias change against re-integration at the new biases: its
// error is second order (a quarter for half the change; the cubic term changes that ratio by
// ~|δb|-relative amounts, under 1e-2 here) and a small part of the change itself (0.2 % here for a
// change of 3e-3 rad/s and 0.03 m/s², 1 % asserted).
TEST(ImuPreintegration, CorrectedDeltasMatchReintegration) {
  const Motion m;
  const double t0 = 0.3, duration = 1.0, rate = 200.0;
  const ImuPreintegration pre = preintegrate(m, t0, duration, rate, kGyroBias, kAccelBias);
  const Vec3 dbg(2e-3, -1e-3, 3e-3), dba(0.02, 0.03, -0.01);
  double error[2];
  for (int half = 0; half < 2; ++half) {
    const double s = half ? 0.5 : 1.0;
    const Vec3 bg = kGyroBias + s * dbg, ba = kAccelBias + s * dba;
    const ImuPreintegration again = preintegrate(m, t0, duration, rate, bg, ba);
    Vec9 change, err;
    change << so3::Log(Mat3(pre.deltaR().transpose() * again.deltaR())), again.deltaV() - pre.deltaV(),
        again.deltaP() - pre.deltaP();
    err << so3::Log(Mat3(pre.correctedDeltaR(bg).transpose() * again.deltaR())),
        again.deltaV() - pre.correctedDeltaV(bg, ba), again.deltaP() - pre.correctedDeltaP(bg, ba);
    EXPECT_LT(err.norm(), 1e-2 * change.norm());
    error[half] = err.norm();
  }
  EXPECT_NEAR(error[0] / error[1], 4.0, 0.1);
}

TEST(ImuPreintegration, TemplatedResidualEqualsDouble) {
  const Motion m;
  const double t0 = 0.3, t1 = 1.3;
  const ImuPreintegration pre = preintegrate(m, t0, t1 - t0, 200.0, kGyroBias, kAccelBias);
  // States near the truth and biases away from the linearisation point: every term is non-zero.
  const Mat3 R_i = m.rotation(t0) * so3::Exp(Vec3(0.02, -0.01, 0.03));
  const Mat3 R_j = m.rotation(t1) * so3::Exp(Vec3(-0.03, 0.02, 0.01));
  const Vec3 p_i = m.position(t0) + Vec3(0.1, -0.2, 0.05), v_i = m.velocity(t0) + Vec3(0.02, 0.01, -0.03);
  const Vec3 p_j = m.position(t1) + Vec3(-0.1, 0.05, 0.2), v_j = m.velocity(t1) + Vec3(-0.01, 0.04, 0.02);
  const Vec3 bg = kGyroBias + Vec3(1e-3, -2e-3, 5e-4), ba = kAccelBias + Vec3(-0.01, 0.02, 0.03);
  const Vec9 expected = pre.residual(R_i, p_i, v_i, R_j, p_j, v_j, bg, ba, kGravity);
  const Eigen::Vector4d q_i = Quat(R_i).coeffs(), q_j = Quat(R_j).coeffs();  // [x, y, z, w]
  Vec9 r;
  pre.residual(q_i.data(), p_i.data(), v_i.data(), bg.data(), ba.data(), q_j.data(), p_j.data(), v_j.data(), kGravity,
               r.data());
  EXPECT_GT(expected.norm(), 0.05);
  // Two evaluation orders of the same terms (|terms| < 10): rounding only.
  EXPECT_NEAR((r - expected).norm(), 0.0, 1e-12);
  // -q is the same rotation
  const Eigen::Vector4d q_j_neg = -q_j;
  pre.residual(q_i.data(), p_i.data(), v_i.data(), bg.data(), ba.data(), q_j_neg.data(), p_j.data(), v_j.data(),
               kGravity, r.data());
  EXPECT_NEAR((r - expected).norm(), 0.0, 1e-12);
}

// Without rotation and under a constant specific force f the discrete covariance has a closed
// form (N intervals of dt, T = N dt, F = hat(f), sums over j = 0 .. N-1 of powers of j + ½):
//   φφ = sg² T,  vφ = -sg² F T²/2,  pφ = -sg² F (T³/6 + T dt²/12),
//   vv = sg² F F^T (T³/3 - T dt²/12) + sa² T,  pv = sg² F F^T T⁴/8 + sa² T²/2,
//   pp = sg² F F^T (T⁵/20 + T dt⁴/80) + sa² (T³/3 - T dt²/12)
// (sg, sa: the densities), which checks every block of the recursion, the within-interval terms
// (½ dt² in position, ¼ dt³ from the gyro) included, down to a single interval.
TEST(ImuPreintegration, CovarianceClosedFormWithoutRotation) {
  const ImuPreintegrationNoise noise;
  const Vec3 f(0.3, -0.2, 9.81);
  const Mat3 F = so3::hat(f), FF = F * F.transpose(), I = Mat3::Identity();
  const double sg2 = noise.gyro_noise_density * noise.gyro_noise_density;
  const double sa2 = noise.accel_noise_density * noise.accel_noise_density;
  const double dt = 0.005;
  for (int n : {1, 2, 20}) {
    ImuPreintegration pre(kGyroBias, kAccelBias, noise);
    for (int k = 0; k < n; ++k) pre.integrate(kGyroBias, f + kAccelBias, dt);
    const double T = n * dt, T2 = T * T, T3 = T2 * T, d2 = dt * dt;
    Mat9 expected;
    expected.block<3, 3>(0, 0) = sg2 * T * I;
    expected.block<3, 3>(3, 0) = -sg2 * F * T2 / 2;
    expected.block<3, 3>(6, 0) = -sg2 * F * (T3 / 6 + T * d2 / 12);
    expected.block<3, 3>(3, 3) = sg2 * FF * (T3 / 3 - T * d2 / 12) + sa2 * T * I;
    expected.block<3, 3>(6, 3) = sg2 * FF * T2 * T2 / 8 + sa2 * T2 / 2 * I;
    expected.block<3, 3>(6, 6) = sg2 * FF * (T3 * T2 / 20 + T * d2 * d2 / 80) + sa2 * (T3 / 3 - T * d2 / 12) * I;
    expected.block<3, 3>(0, 3) = expected.block<3, 3>(3, 0).transpose();
    expected.block<3, 3>(0, 6) = expected.block<3, 3>(6, 0).transpose();
    expected.block<3, 3>(3, 6) = expected.block<3, 3>(6, 3).transpose();
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        const Mat3 e = expected.block<3, 3>(3 * a, 3 * b), c = pre.covariance().block<3, 3>(3 * a, 3 * b);
        EXPECT_LE((c - e).norm(), 1e-12 * e.norm()) << "n " << n << " block " << a << b;  // rounding
      }
    }
  }
}

// On the rotating trajectory the covariance is the exact first-order propagation of independent
// noise on every interval's readings: with G_k the sensitivity of the end error to interval k's
// (gyro, accel) readings, by central differences of the integration, Cov = sum_k G_k Q G_k^T,
// Q = diag(sg², sa²) / dt. This checks the rotation-dependent terms (Jr, Exp(w dt)^T, the middle
// rotation) that the closed form above does not, far below the Monte-Carlo's resolution.
TEST(ImuPreintegration, CovarianceIsTheLinearisedNoisePropagation) {
  const Motion m;
  const double t0 = 0.3, duration = 0.2, rate = 200.0;
  const ImuPreintegrationNoise noise;
  const int n = static_cast<int>(std::lround(duration * rate));
  const double dt = duration / n;
  std::vector<Vec6> readings(n);
  for (int k = 0; k < n; ++k) {
    const double ta = t0 + k * dt, tb = ta + dt;
    readings[k] << 0.5 * (m.bodyRate(ta) + m.bodyRate(tb)) + kGyroBias,
        0.5 * (m.specificForce(ta) + m.specificForce(tb)) + kAccelBias;
  }
  auto integrateWith = [&](int k_perturbed, const Vec6& d) {
    ImuPreintegration pre(kGyroBias, kAccelBias, noise);
    for (int k = 0; k < n; ++k) {
      const Vec6 r = k == k_perturbed ? Vec6(readings[k] + d) : readings[k];
      pre.integrate(r.head<3>(), r.tail<3>(), dt);
    }
    return pre;
  };
  const ImuPreintegration ref = integrateWith(-1, Vec6::Zero());
  auto endError = [&](const ImuPreintegration& pre) {
    Vec9 e;
    e << so3::Log(Mat3(ref.deltaR().transpose() * pre.deltaR())), pre.deltaV() - ref.deltaV(),
        pre.deltaP() - ref.deltaP();
    return e;
  };
  Vec6 q;
  q << Vec3::Constant(noise.gyro_noise_density * noise.gyro_noise_density / dt),
      Vec3::Constant(noise.accel_noise_density * noise.accel_noise_density / dt);
  // truncation ~ h² |∂³e| ~ 1e-12; rounding ~ 1e-16 / h = 1e-10 on entries of G ~ dt = 5e-3, so
  // ~2e-8 relative (1e-8 seen); a missing Jr or Exp(w dt)^T shows at 1e-6 to 1e-1
  const double h = 1e-6;
  Mat9 linearised = Mat9::Zero();
  for (int k = 0; k < n; ++k) {
    Eigen::Matrix<double, 9, 6> G;
    for (int i = 0; i < 6; ++i) {
      const Vec6 d = Vec6::Unit(i) * h;
      G.col(i) = (endError(integrateWith(k, d)) - endError(integrateWith(k, -d))) / (2 * h);
    }
    linearised += G * q.asDiagonal() * G.transpose();
  }
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      const Mat3 e = linearised.block<3, 3>(3 * a, 3 * b), c = ref.covariance().block<3, 3>(3 * a, 3 * b);
      EXPECT_LE((c - e).norm(), 1e-7 * e.norm()) << "block " << a << b;
    }
  }
}

// The preintegrated covariance against the sample covariance of 500 noisy integrations (seeded):
// whitened by the predicted covariance, the sample covariance is a Wishart(I, N)/N sample. For
// d = 9, N = 500 its eigenvalues fill (1 ± sqrt(d/N))² = [0.75, 1.29], the largest exceeding 1.4
// with probability ~1e-3 (Tracy-Widom, scale 0.037), the smallest below 0.65 less often still; a
// factor 2 in any direction (a wrong dt scaling, a missing or doubled Jacobian block) leaves that.
TEST(ImuPreintegration, CovarianceMatchesMonteCarlo) {
  const Motion m;
  const double t0 = 0.3, duration = 0.2, rate = 200.0;
  const ImuPreintegrationNoise noise;  // the rig defaults
  const ImuPreintegration ref = preintegrate(m, t0, duration, rate, kGyroBias, kAccelBias, noise);
  std::mt19937 rng(20240611);
  const int runs = 500;
  Mat9 sample = Mat9::Zero();
  for (int n = 0; n < runs; ++n) {
    const ImuPreintegration noisy = preintegrate(m, t0, duration, rate, kGyroBias, kAccelBias, noise, &rng);
    Vec9 e;
    e << so3::Log(Mat3(ref.deltaR().transpose() * noisy.deltaR())), noisy.deltaV() - ref.deltaV(),
        noisy.deltaP() - ref.deltaP();
    sample += e * e.transpose() / runs;
  }
  const Mat9 L = ref.covariance().llt().matrixL();
  const Mat9 Linv = L.inverse();
  const Eigen::SelfAdjointEigenSolver<Mat9> eig(Linv * sample * Linv.transpose());
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0.65);
  EXPECT_LT(eig.eigenvalues().maxCoeff(), 1.4);
}

// sqrtInformation whitens: U Σ U^T = I, U upper triangular; a singular covariance (one interval:
// δp = ½ dt δv) still gives a finite U that never overweights: U Σ U^T <= I.
TEST(ImuPreintegration, SqrtInformationWhitens) {
  const Motion m;
  const ImuPreintegration pre = preintegrate(m, 0.3, 1.0, 200.0, kGyroBias, kAccelBias);
  const Mat9 U = pre.sqrtInformation();
  EXPECT_TRUE(U.triangularView<Eigen::StrictlyLower>().toDenseMatrix().isZero(0.0));
  // cond(Σ) ~ 1e5 here: the inversion loses ~ cond * 1e-16
  EXPECT_NEAR((U * pre.covariance() * U.transpose() - Mat9::Identity()).norm(), 0.0, 1e-8);

  ImuPreintegration one(kGyroBias, kAccelBias, ImuPreintegrationNoise{});
  one.integrate(m.bodyRate(0.3) + kGyroBias, m.specificForce(0.3) + kAccelBias, 0.005);
  const Mat9 U1 = one.sqrtInformation();
  ASSERT_TRUE(U1.allFinite());
  const Eigen::SelfAdjointEigenSolver<Mat9> eig(U1 * one.covariance() * U1.transpose());
  EXPECT_LT(eig.eigenvalues().maxCoeff(), 1.0 + 1e-6);
  EXPECT_GT(eig.eigenvalues().maxCoeff(), 1.0 - 1e-6);  // the noisy directions keep their weight
}

TEST(ImuPreintegration, ZeroAndNegativeIntervals) {
  const Motion m;
  ImuPreintegration pre = preintegrate(m, 0.3, 0.1, 200.0, kGyroBias, kAccelBias);
  const Vec3 p = pre.deltaP();
  const Mat9 c = pre.covariance();
  pre.integrate(Vec3(1, 2, 3), Vec3(4, 5, 6), 0.0);
  EXPECT_TRUE(pre.deltaP() == p);
  EXPECT_TRUE(pre.covariance() == c);
  EXPECT_THROW(pre.integrate(Vec3::Zero(), Vec3::Zero(), -1e-3), std::invalid_argument);
  pre.reset(Vec3(0.1, 0.2, 0.3), Vec3(1, 2, 3));
  EXPECT_EQ(pre.duration(), 0.0);
  EXPECT_TRUE(pre.deltaR() == Mat3::Identity());
  EXPECT_TRUE(pre.deltaV().isZero(0.0));
  EXPECT_TRUE(pre.covariance().isZero(0.0));
  EXPECT_TRUE(pre.dP_dbg().isZero(0.0));
  EXPECT_TRUE(pre.gyroBias() == Vec3(0.1, 0.2, 0.3));
  EXPECT_TRUE(pre.accelBias() == Vec3(1, 2, 3));
}

TEST(ImuPreintegration, NoiseFromRig) {
  ImuRig rig;
  rig.gyro_noise_density = 1.0;
  rig.accel_noise_density = 2.0;
  rig.gyro_random_walk = 3.0;
  rig.accel_random_walk = 4.0;
  const ImuPreintegrationNoise n = ImuPreintegrationNoise::fromRig(rig);
  EXPECT_EQ(n.gyro_noise_density, 1.0);
  EXPECT_EQ(n.accel_noise_density, 2.0);
  EXPECT_EQ(n.gyro_random_walk, 3.0);
  EXPECT_EQ(n.accel_random_walk, 4.0);
  ImuPreintegration pre(Vec3::Zero(), Vec3::Zero(), n);
  pre.integrate(Vec3::Zero(), Vec3::Zero(), 0.5);
  pre.integrate(Vec3::Zero(), Vec3::Zero(), 0.25);
  EXPECT_NEAR(pre.biasRandomWalkCovariance()(0, 0), 9.0 * 0.75, 1e-15);
  EXPECT_NEAR(pre.biasRandomWalkCovariance()(5, 5), 16.0 * 0.75, 1e-15);
  // at rest: the rotation variance per axis is density² t (the white-noise angle random walk)
  EXPECT_NEAR(pre.covariance()(0, 0), 0.75, 1e-15);
}

// The gyro's scale and misalignment in the noise budget: a steady turn about z at w for T seconds
// adds s² w² window to the density² about z (the turn's axis, where the rotation error stays put)
// and m² w² window about x and y (the cross-axis terms); at rest or with zero 1-sigmas the
// covariance is exactly the white-noise one. The same helper as livo-lio's propagation.
TEST(ImuPreintegration, GyroScaleAndMisalignmentInTheBudget) {
  ImuRig rig;
  rig.gyro_scale_std = 0.01;
  rig.gyro_misalignment_std = 0.005;
  ImuPreintegrationNoise n = ImuPreintegrationNoise::fromRig(rig);
  EXPECT_EQ(n.gyro_scale_std, 0.01);
  EXPECT_EQ(n.gyro_misalignment_std, 0.005);
  n.systematic_error_window_s = 0.1;
  const double w = 1.0, dt = 0.005, sigma2 = n.gyro_noise_density * n.gyro_noise_density;
  ImuPreintegration turn(Vec3::Zero(), Vec3::Zero(), n), rest(Vec3::Zero(), Vec3::Zero(), n);
  ImuPreintegrationNoise white = n;
  white.gyro_scale_std = white.gyro_misalignment_std = 0.0;
  ImuPreintegration turn_white(Vec3::Zero(), Vec3::Zero(), white), rest_white(Vec3::Zero(), Vec3::Zero(), white);
  for (int k = 0; k < 200; ++k) {
    turn.integrate(Vec3(0.0, 0.0, w), Vec3::Zero(), dt);
    turn_white.integrate(Vec3(0.0, 0.0, w), Vec3::Zero(), dt);
    rest.integrate(Vec3::Zero(), Vec3::Zero(), dt);
    rest_white.integrate(Vec3::Zero(), Vec3::Zero(), dt);
  }
  const Mat9 c = turn.covariance();
  EXPECT_NEAR(c(2, 2), (sigma2 + 0.01 * 0.01 * w * w * 0.1) * 1.0, 1e-12);
  EXPECT_NEAR(c(0, 0) + c(1, 1), 2.0 * (sigma2 + 0.005 * 0.005 * w * w * 0.1) * 1.0, 1e-4 * c(0, 0));
  EXPECT_TRUE(rest.covariance() == rest_white.covariance());
  EXPECT_GT(c(2, 2), 100.0 * turn_white.covariance()(2, 2));
  EXPECT_TRUE(gyroSystematicDensity2(Vec3(0.3, -0.2, 1.0), 0.0, 0.0, 0.1).isZero(0.0));
  EXPECT_NEAR(gyroSystematicDensity2(Vec3(0.3, -0.2, 1.0), 0.01, 0.005, 0.1).x(),
              (1e-4 * 0.09 + 2.5e-5 * (0.04 + 1.0)) * 0.1, 1e-18);
}

// The templated maps against so3.hpp, across the series threshold and for w < 0.
TEST(ImuPreintegrationQuaternionMaps, MatchSo3) {
  for (const Vec3& r : {Vec3(0, 0, 0), Vec3(1e-9, -2e-9, 3e-9), Vec3(7e-7, 0, 0), Vec3(1.2e-6, 0, 0),
                        Vec3(0.3, -0.2, 0.1), Vec3(Vec3(1, 2, -0.5).normalized() * 3.0)}) {
    const Quat q = quaternionExp<double>(r);
    EXPECT_NEAR(q.norm(), 1.0, 1e-15);
    EXPECT_NEAR((q.toRotationMatrix() - so3::Exp(r)).norm(), 0.0, 1e-14) << r.transpose();
    EXPECT_NEAR((quaternionLog<double>(q) - r).norm(), 0.0, 1e-14 * std::max(1.0, r.norm())) << r.transpose();
    const Quat neg(-q.w(), -q.x(), -q.y(), -q.z());
    EXPECT_NEAR((quaternionLog<double>(neg) - so3::Log(q)).norm(), 0.0, 1e-14) << r.transpose();
    const Quat scaled(2.0 * q.w(), 2.0 * q.x(), 2.0 * q.y(), 2.0 * q.z());  // not normalised
    EXPECT_NEAR((quaternionLog<double>(scaled) - so3::Log(q)).norm(), 0.0, 1e-14) << r.transpose();
  }
}

#ifdef LIVO_HAVE_CERES_JET
namespace {

template <int N>
using Jet = ceres::Jet<double, N>;

// The parameter blocks of the IMU residual, flattened: q_i p_i v_i bg ba q_j p_j v_j.
constexpr int kImuParams = 26;
constexpr int kImuBlockOffset[8] = {0, 4, 7, 10, 13, 16, 20, 23};

template <class T>
Eigen::Matrix<T, 9, 1> imuResidual(const ImuPreintegration& pre, const T* x) {
  Eigen::Matrix<T, 9, 1> r;
  const int* o = kImuBlockOffset;
  pre.residual(x + o[0], x + o[1], x + o[2], x + o[3], x + o[4], x + o[5], x + o[6], x + o[7], kGravity, r.data());
  return r;
}

}  // namespace

// The derivatives Ceres' AutoDiff would take, against central differences of the double residual,
// away from the truth and at a state where the rotation residual is zero (the Log's series branch).
TEST(ImuPreintegrationJet, DerivativesMatchCentralDifferences) {
  const Motion m;
  const double t0 = 0.3, t1 = 1.3;
  const ImuPreintegration pre = preintegrate(m, t0, t1 - t0, 200.0, kGyroBias, kAccelBias);
  const Vec3 bg = kGyroBias + Vec3(1e-3, -2e-3, 5e-4), ba = kAccelBias + Vec3(-0.01, 0.02, 0.03);
  Mat3 R_pred;
  Vec3 p_pred, v_pred;
  pre.predict(m.rotation(t0), m.position(t0), m.velocity(t0), bg, ba, kGravity, &R_pred, &p_pred, &v_pred);
  for (bool at_prediction : {false, true}) {
    const Mat3 R_j = at_prediction ? R_pred : Mat3(m.rotation(t1) * so3::Exp(Vec3(-0.03, 0.02, 0.01)));
    const Vec3 p_j = at_prediction ? p_pred : Vec3(m.position(t1) + Vec3(-0.1, 0.05, 0.2));
    const Vec3 v_j = at_prediction ? v_pred : Vec3(m.velocity(t1) + Vec3(-0.01, 0.04, 0.02));
    Eigen::Matrix<double, kImuParams, 1> x;
    x << Quat(m.rotation(t0)).coeffs(), m.position(t0), m.velocity(t0), bg, ba, Quat(R_j).coeffs(), p_j, v_j;
    std::array<Jet<kImuParams>, kImuParams> xj;
    for (int i = 0; i < kImuParams; ++i) xj[i] = Jet<kImuParams>(x[i], i);
    const Eigen::Matrix<Jet<kImuParams>, 9, 1> rj = imuResidual(pre, xj.data());
    if (at_prediction) {
      EXPECT_LT(imuResidual(pre, x.data()).head<3>().norm(), 1e-12);
    }
    // h = 1e-6: truncation h² |f'''| / 6 < 1e-10 for third derivatives below 1e2, rounding
    // ~ 1e-16 |r terms ~ 10| / h = 1e-9.
    const double h = 1e-6;
    for (int i = 0; i < kImuParams; ++i) {
      Eigen::Matrix<double, kImuParams, 1> xp = x, xm = x;
      xp[i] += h;
      xm[i] -= h;
      const Vec9 numeric = (imuResidual(pre, xp.data()) - imuResidual(pre, xm.data())) / (2 * h);
      for (int k = 0; k < 9; ++k) {
        ASSERT_TRUE(std::isfinite(rj[k].v[i]));
        EXPECT_NEAR(rj[k].v[i], numeric[k], 1e-7) << "residual " << k << " parameter " << i;
      }
    }
  }
}

// At the identity (where sqrt(|v|²) has no derivative) the Jet of Log is finite and exact:
// ∂Log/∂(x, y, z) = 2 I and ∂Log/∂w = 0 for q = [0, 0, 0, 1]; ∂Exp/∂r = [½ I; 0] at r = 0.
TEST(ImuPreintegrationJet, QuaternionMapsDifferentiableAtIdentity) {
  using J4 = Jet<4>;
  const Eigen::Quaternion<J4> q(J4(1.0, 3), J4(0.0, 0), J4(0.0, 1), J4(0.0, 2));  // (w, x, y, z)
  const Eigen::Matrix<J4, 3, 1> r = quaternionLog<J4>(q);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(r[k].a, 0.0);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(r[k].v[i], (i == k) ? 2.0 : 0.0) << k << " " << i;
  }
  using J3 = Jet<3>;
  const Eigen::Matrix<J3, 3, 1> zero(J3(0.0, 0), J3(0.0, 1), J3(0.0, 2));
  const Eigen::Quaternion<J3> e = quaternionExp<J3>(zero);
  EXPECT_EQ(e.w().a, 1.0);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(e.w().v[i], 0.0);
    EXPECT_EQ(e.x().v[i], i == 0 ? 0.5 : 0.0);
    EXPECT_EQ(e.y().v[i], i == 1 ? 0.5 : 0.0);
    EXPECT_EQ(e.z().v[i], i == 2 ? 0.5 : 0.0);
  }
}
#endif  // LIVO_HAVE_CERES_JET
