// The iterated ESIKF update: the information form against the textbook gain of eqs. (16)-(18) on the
// 32-dim state (pose alone, or pose and a sensor's calibration block; a calibration held fixed left
// exactly), the chi-square consistency gate against simulated linear-Gaussian measurements, a
// single-scan registration with a known offset converging to the truth, and the degeneracy analysis
// on a corridor (two walls and a floor) against a room.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "livo/esikf_update.hpp"
#include "livo/lio/degeneracy.hpp"
#include "livo/lio/scan_to_map.hpp"
#include "reference_algebra.hpp"
#include "synthetic_world.hpp"

using namespace livo;
using namespace livo::lio;
using namespace livo::test;

namespace {
StateCovariance randomCovariance(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  StateCovariance A;
  for (int i = 0; i < FilterState::kDim; ++i)
    for (int j = 0; j < FilterState::kDim; ++j) A(i, j) = 0.1 * n01(rng);
  return A * A.transpose() + StateCovariance::Identity() * 0.01;
}

// The error-state indices a measurement touches: the pose [0, 6) and, for block >= 0, the
// calibration block [block, block + 7) (MeasurementInformation's order).
std::vector<int> measuredStates(int block) {
  std::vector<int> idx = {0, 1, 2, 3, 4, 5};
  if (block >= 0)
    for (int k = 0; k < FilterState::kCalibrationDim; ++k) idx.push_back(block + k);
  return idx;
}

// A linearised measurement z + H δ with H nonzero on the measured states only (m rows), a prior
// covariance P̂ and an iterate x̌ != x̂ (so J of eq. 12 is not the identity), with the textbook's
// P = J^-1 P̂ J^-T.
struct LinearisedMeasurement {
  FilterState prior, x;
  StateCovariance Phat, P;
  Eigen::MatrixXd H, R;
  Eigen::VectorXd z;
  int block = -1;  // the calibration block measured (-1: the pose alone)

  // H on the measured columns (MeasurementInformation's order)
  Eigen::MatrixXd measuredColumns() const {
    const std::vector<int> idx = measuredStates(block);
    Eigen::MatrixXd HE(H.rows(), static_cast<int>(idx.size()));
    for (size_t k = 0; k < idx.size(); ++k) HE.col(static_cast<int>(k)) = H.col(idx[k]);
    return HE;
  }
  Mat6 S() const { return H.leftCols<6>().transpose() * inverseOf(R) * H.leftCols<6>(); }
  Vec6 g() const { return H.leftCols<6>().transpose() * inverseOf(R) * z; }
  MeasurementInformation info() const {
    MeasurementInformation m;
    const Eigen::MatrixXd HE = measuredColumns();
    const Eigen::MatrixXd S = HE.transpose() * inverseOf(R) * HE;
    const Eigen::VectorXd g = HE.transpose() * inverseOf(R) * z;
    m.HtRinvH.topLeftCorner(S.rows(), S.cols()) = S;
    m.HtRinvz.head(g.size()) = g;
    if (block >= 0) m.calibration_block = block;
    m.count = static_cast<int>(z.size());
    return m;
  }
  // the gain K = (H^T R^-1 H + P^-1)^-1 H^T R^-1 of eq. (17)
  Eigen::MatrixXd gain() const {
    const Eigen::MatrixXd Rinv = inverseOf(R);
    return inverseOf(H.transpose() * Rinv * H + inverseOf(P)) * H.transpose() * Rinv;
  }
};

// A prior with non-trivial calibration rotations, so that all three rotation blocks of J differ
// from the identity once the iterate moves them.
FilterState calibratedPrior(const Vec3& rot, const Vec3& pos) {
  FilterState x;
  x.rot = so3::Exp(rot);
  x.pos = pos;
  x.lidar = SensorCalibration{so3::Exp(Vec3(0.1, -0.3, 1.4)), Vec3(0.05, 0.0, 0.1), 0.002};
  x.camera = SensorCalibration{so3::Exp(Vec3(-1.2, 1.2, -1.2)), Vec3(0.08, -0.01, 0.02), -0.004};
  return x;
}

// `moved` marks the error states the iterate has moved from the prior; `block` the calibration
// block the measurement also sees (-1: none).
LinearisedMeasurement randomMeasurement(unsigned seed, int m, const StateVector& moved, const Vec3& rot,
                                        const Vec3& pos, int block = -1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  LinearisedMeasurement lm;
  lm.block = block;
  lm.prior = calibratedPrior(rot, pos);
  StateVector d0;
  for (int i = 0; i < FilterState::kDim; ++i) d0[i] = 0.05 * n01(rng) * moved[i];
  lm.x = lm.prior.boxplus(d0);
  lm.Phat = randomCovariance(seed - 4);
  lm.H = Eigen::MatrixXd::Zero(m, FilterState::kDim);
  for (int i = 0; i < m; ++i)
    for (int j : measuredStates(block)) lm.H(i, j) = n01(rng);
  lm.z.resize(m);
  for (int i = 0; i < m; ++i) lm.z[i] = 0.1 * n01(rng);
  lm.R = Eigen::MatrixXd::Zero(m, m);
  for (int i = 0; i < m; ++i) lm.R(i, i) = 0.01 * (1 + i);
  const StateCovariance Jinv = inverseOf(FilterState::boxminusJacobian(lm.x, lm.prior));
  lm.P = Jinv * lm.Phat * Jinv.transpose();
  return lm;
}
}  // namespace

TEST(EsikfUpdate, InformationFormEqualsTextbookGain) {
  const LinearisedMeasurement lm = randomMeasurement(7, 9, StateVector::Ones(), Vec3(0.2, 0.1, -0.4), Vec3(1, 2, 3));
  // textbook: K of eq. (17), the step and covariance of eqs. (17) and (18)
  const Eigen::MatrixXd K = lm.gain();
  const StateCovariance Jinv = inverseOf(FilterState::boxminusJacobian(lm.x, lm.prior));
  const StateVector delta_ref = -K * lm.z - (StateCovariance::Identity() - K * lm.H) * Jinv * lm.x.boxminus(lm.prior);
  const StateCovariance Ppost_ref = (StateCovariance::Identity() - K * lm.H) * lm.P;
  StateVector delta;
  StateCovariance Ppost;
  informationStep(lm.x, lm.prior, lm.Phat, lm.S(), lm.g(), &delta, &Ppost);
  EXPECT_LT((delta - delta_ref).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT((Ppost - Ppost_ref).cwiseAbs().maxCoeff(), 1e-10);
}

// The same with the measurement seeing a sensor's calibration: H nonzero on the pose and the 7
// states of the block, every state (three rotation blocks) moved by the iterate.
TEST(EsikfUpdate, InformationFormWithACalibrationBlockEqualsTextbookGain) {
  for (const int block : {FilterState::kLidar, FilterState::kCamera}) {
    SCOPED_TRACE(block == FilterState::kLidar ? "LiDAR block" : "camera block");
    const LinearisedMeasurement lm =
        randomMeasurement(17 + block, 16, StateVector::Ones(), Vec3(-0.3, 0.2, 0.5), Vec3(-1, 4, 0.5), block);
    for (const int b : FilterState::kRotationBlocks)
      ASSERT_GT((FilterState::boxminusJacobian(lm.x, lm.prior).block<3, 3>(b, b) - Mat3::Identity()).norm(), 1e-3);
    const Eigen::MatrixXd K = lm.gain();
    const StateCovariance Jinv = inverseOf(FilterState::boxminusJacobian(lm.x, lm.prior));
    const StateVector delta_ref = -K * lm.z - (StateCovariance::Identity() - K * lm.H) * Jinv * lm.x.boxminus(lm.prior);
    const StateCovariance Ppost_ref = (StateCovariance::Identity() - K * lm.H) * lm.P;
    StateVector delta;
    StateCovariance Ppost;
    informationStep(lm.x, lm.prior, lm.Phat, lm.info(), &delta, &Ppost);
    EXPECT_LT((delta - delta_ref).cwiseAbs().maxCoeff(), 1e-10);
    EXPECT_LT((Ppost - Ppost_ref).cwiseAbs().maxCoeff(), 1e-10);
    // the other sensor's calibration is stepped through its correlations only
    const int other = block == FilterState::kLidar ? FilterState::kCamera : FilterState::kLidar;
    EXPECT_GT(delta.segment<FilterState::kCalibrationDim>(other).cwiseAbs().maxCoeff(), 1e-4);
  }
}

// A calibration the rig states as exact (zero prior variance: zero rows and columns) gets no gain:
// the update leaves it exactly where it is, its covariance rows stay exactly zero, and the other
// states step as the textbook filter over the estimated states alone.
TEST(EsikfUpdate, CalibrationWithZeroPriorVarianceIsLeftExactlyUnchanged) {
  for (const int block : {FilterState::kLidar, FilterState::kCamera}) {
    SCOPED_TRACE(block == FilterState::kLidar ? "LiDAR block" : "camera block");
    StateVector estimated = StateVector::Ones();
    estimated.segment<FilterState::kCalibrationDim>(block).setZero();
    // the iterate has not moved the fixed block (it never does: its delta is zero)
    LinearisedMeasurement lm =
        randomMeasurement(23 + block, 16, estimated, Vec3(0.4, -0.1, 0.2), Vec3(2, -1, 0.3), block);
    lm.Phat = estimated.asDiagonal() * lm.Phat * estimated.asDiagonal();
    const StateCovariance Jinv = inverseOf(FilterState::boxminusJacobian(lm.x, lm.prior));
    lm.P = Jinv * lm.Phat * Jinv.transpose();
    ASSERT_TRUE(isUsableCovariance(lm.Phat));
    ASSERT_GT(lm.H.middleCols<FilterState::kCalibrationDim>(block).cwiseAbs().maxCoeff(), 0.1);  // it is measured
    StateVector delta;
    StateCovariance Ppost;
    informationStep(lm.x, lm.prior, lm.Phat, lm.info(), &delta, &Ppost);
    EXPECT_EQ(delta.segment<FilterState::kCalibrationDim>(block), (Eigen::Matrix<double, 7, 1>::Zero()));
    EXPECT_EQ(Ppost.middleRows<FilterState::kCalibrationDim>(block).cwiseAbs().maxCoeff(), 0.0);
    EXPECT_EQ(Ppost.middleCols<FilterState::kCalibrationDim>(block).cwiseAbs().maxCoeff(), 0.0);
    const FilterState post = lm.x.boxplus(delta);
    const SensorCalibration &c0 = lm.prior.calibration(block), &c1 = post.calibration(block);
    EXPECT_EQ(c1.rot, c0.rot);
    EXPECT_EQ(c1.pos, c0.pos);
    EXPECT_EQ(c1.dt, c0.dt);
    // the estimated states: the textbook filter on them alone (the fixed ones are known constants)
    std::vector<int> idx;
    for (int i = 0; i < FilterState::kDim; ++i)
      if (estimated[i] > 0.0) idx.push_back(i);
    const int n = static_cast<int>(idx.size());
    Eigen::MatrixXd Pr(n, n), Jr(n, n), Hr(lm.H.rows(), n);
    Eigen::VectorXd er(n);
    const StateVector e0 = lm.x.boxminus(lm.prior);
    for (int r = 0; r < n; ++r) {
      er[r] = e0[idx[r]];
      Hr.col(r) = lm.H.col(idx[r]);
      for (int c = 0; c < n; ++c) {
        Pr(r, c) = lm.P(idx[r], idx[c]);
        Jr(r, c) = Jinv(idx[r], idx[c]);
      }
    }
    const Eigen::MatrixXd Rinv = inverseOf(lm.R);
    const Eigen::MatrixXd K = inverseOf(Hr.transpose() * Rinv * Hr + inverseOf(Pr)) * Hr.transpose() * Rinv;
    const Eigen::MatrixXd I_KH = Eigen::MatrixXd::Identity(n, n) - K * Hr;
    const Eigen::VectorXd delta_ref = -K * lm.z - I_KH * Jr * er;
    const Eigen::MatrixXd Ppost_ref = I_KH * Pr;
    for (int r = 0; r < n; ++r) {
      EXPECT_NEAR(delta[idx[r]], delta_ref[r], 1e-10) << "state " << idx[r];
      for (int c = 0; c < n; ++c) EXPECT_NEAR(Ppost(idx[r], idx[c]), Ppost_ref(r, c), 1e-10) << idx[r] << "," << idx[c];
    }
  }
}

TEST(EsikfUpdate, ConsiderStepEqualsTheSchmidtKalmanFilter) {
  // the gyro bias (and only it) considered: against the textbook Schmidt-Kalman filter, K' = M K
  // with M zero on the considered rows and P+ = (I - K'H) P (I - K'H)^T + K' R K'^T
  StateVector keep = StateVector::Ones();
  keep.segment<3>(FilterState::kGyroBias).setZero();
  // the iterate has moved everything but the considered states
  const LinearisedMeasurement lm = randomMeasurement(9, 8, keep, Vec3(-0.1, 0.3, 0.2), Vec3(-1, 0.5, 2));
  const Eigen::MatrixXd Ks = keep.asDiagonal() * lm.gain();
  const StateCovariance Jinv = inverseOf(FilterState::boxminusJacobian(lm.x, lm.prior));
  const StateVector delta_ref = -Ks * lm.z - (StateCovariance::Identity() - Ks * lm.H) * Jinv * lm.x.boxminus(lm.prior);
  const StateCovariance I_KH = StateCovariance::Identity() - Ks * lm.H;
  const StateCovariance Ppost_ref = I_KH * lm.P * I_KH.transpose() + Ks * lm.R * Ks.transpose();
  StateVector delta;
  StateCovariance Ppost;
  informationStep(lm.x, lm.prior, lm.Phat, lm.S(), lm.g(), &delta, &Ppost, &keep);
  EXPECT_LT((delta - delta_ref).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT((Ppost - Ppost_ref).cwiseAbs().maxCoeff(), 1e-10);
  // the considered states keep their value and their variance; the rest steps as the full filter
  EXPECT_TRUE(delta.segment<3>(FilterState::kGyroBias).isZero());
  EXPECT_LT((Ppost.block<3, 3>(9, 9) - lm.P.block<3, 3>(9, 9)).cwiseAbs().maxCoeff(), 1e-12);
  StateVector delta_full;
  StateCovariance Pfull;
  informationStep(lm.x, lm.prior, lm.Phat, lm.S(), lm.g(), &delta_full, &Pfull);
  EXPECT_LT((delta - keep.asDiagonal() * delta_full).cwiseAbs().maxCoeff(), 1e-12);
  // and it never claims more than the optimal filter: P+ - P_full is positive semi-definite
  EXPECT_GT(minEigenvalue(Ppost - Pfull), -1e-12);
}

TEST(EsikfUpdate, InformationBeyondPriorKeepsTheLargerInformationPerDirection) {
  // diagonal case: per axis max(0, s_i - 1/p_i)
  const Vec6 p = (Vec6() << 1e-4, 4e-4, 1e-2, 1e-6, 1.0, 0.25).finished();
  const Vec6 si = (Vec6() << 5e3, 1e3, 1e3, 1e5, 10.0, 0.0).finished();
  const Mat6 E = informationBeyondPrior(Mat6(si.asDiagonal()), Mat6(p.asDiagonal()));
  for (int i = 0; i < 6; ++i) EXPECT_NEAR(E(i, i), std::max(0.0, si[i] - 1.0 / p[i]), 1e-9 * (1.0 + si[i])) << i;
  EXPECT_LT((E - Mat6(E.diagonal().asDiagonal())).cwiseAbs().maxCoeff(), 1e-9);
  // general case: in the prior's whitened frame the posterior information is max(I, W) per
  // eigendirection of W = L^T S L, so it is never below the prior's or the measurement's
  const Mat6 P = randomCovariance(3).topLeftCorner<6, 6>();
  std::mt19937 rng(11);
  std::normal_distribution<double> n01;
  Eigen::Matrix<double, 6, 3> H;
  for (int i = 0; i < H.size(); ++i) H.data()[i] = 30.0 * n01(rng);
  const Mat6 S = H * H.transpose();  // rank 3: three directions carry no measurement information
  const Mat6 B = informationBeyondPrior(S, P);
  const Mat6 P_inv = inverseOf(P);
  const Mat6 post = P_inv + B;
  EXPECT_GT(minEigenvalue(post - S), -1e-6 * S.norm());
  EXPECT_GT(minEigenvalue(post - P_inv), -1e-6 * S.norm());
  EXPECT_GT(minEigenvalue(B), -1e-6 * S.norm());
  const Mat6 L = choleskyFactor(P);
  const SymmetricEigen w = symmetricEigen(L.transpose() * S * L);
  const Mat6 expected = w.vectors * w.values.cwiseMax(1.0).asDiagonal() * w.vectors.transpose();
  EXPECT_LT((L.transpose() * post * L - expected).norm(), 1e-6 * expected.norm());
  EXPECT_EQ(rankOf(B), 3);  // nothing where the measurement says nothing
  // a measurement weaker than the prior in every direction adds nothing
  EXPECT_LT(informationBeyondPrior(Mat6(1e-3 * P_inv), P).norm(), 1e-9 * P_inv.norm());
}

// Over a pose and a calibration block: the same per-direction maximum in the prior's whitened frame;
// with the calibration held fixed (zero prior variance) it gets nothing and the pose gets what the
// pose-only version gives.
TEST(EsikfUpdate, InformationBeyondPriorOverACalibrationBlock) {
  std::mt19937 rng(13);
  std::normal_distribution<double> n01;
  Eigen::Matrix<double, kMeasuredDim, 9> Hs;
  for (int i = 0; i < Hs.size(); ++i) Hs.data()[i] = 10.0 * n01(rng);
  const Mat13 S = Hs * Hs.transpose();  // rank 9
  const Mat13 P = measuredCovariance(randomCovariance(14), FilterState::kCamera);
  const Mat13 B = informationBeyondPrior(S, P);
  const Mat13 L = choleskyFactor(P);
  const SymmetricEigen w = symmetricEigen(L.transpose() * S * L);
  const Mat13 expected = w.vectors * w.values.cwiseMax(1.0).asDiagonal() * w.vectors.transpose();
  EXPECT_LT((L.transpose() * (inverseOf(P) + B) * L - expected).norm(), 1e-6 * expected.norm());
  EXPECT_LE(rankOf(B), 9);
  // the calibration held fixed
  StateCovariance P32 = randomCovariance(15);
  setCalibrationPrior(FilterState::kLidar, CalibrationStd{}, &P32);
  const Mat13 Pf = measuredCovariance(P32, FilterState::kLidar);
  const Mat13 Bf = informationBeyondPrior(S, Pf);
  EXPECT_EQ((Bf.bottomRows<7>().cwiseAbs().maxCoeff()), 0.0);
  EXPECT_EQ((Bf.rightCols<7>().cwiseAbs().maxCoeff()), 0.0);
  const Mat6 pose_only = informationBeyondPrior(Mat6(S.topLeftCorner<6, 6>()), Mat6(Pf.topLeftCorner<6, 6>()));
  EXPECT_LT((Bf.topLeftCorner<6, 6>() - pose_only).norm(), 1e-9 * pose_only.norm());
}

namespace {
// Draws of a linear-Gaussian measurement of the 13 measured states (MeasurementInformation's order)
// tested by consistencyTest: a prior error δ ~ N(0, P), a measurement y = H (δ + offset) + v with
// v ~ N(0, I) (whitened rows), evaluated at a fixed iterate e (x ⊟ prior; zero on fixed states):
// z = H (e - δ - offset) - v, S = H^T H, g = H^T z, so ν = e - S^-1 g = δ + offset + S^-1 H^T v.
struct ConsistencyRun {
  double acceptance = 0.0;
  double mean_nis = 0.0;
  int min_dof = 1000, max_dof = -1;
};

ConsistencyRun simulateConsistency(const Mat13& P, const Eigen::MatrixXd& H, const Vec13& offset, int draws,
                                   double probability, double min_information, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  const SymmetricEigen es = symmetricEigen(P);
  const Mat13 A = es.vectors * es.values.cwiseMax(0.0).cwiseSqrt().asDiagonal();  // P = A A^T
  Vec13 e;
  for (int i = 0; i < kMeasuredDim; ++i) e[i] = P(i, i) > 0.0 ? 0.3 * std::sqrt(P(i, i)) * n01(rng) : 0.0;
  const Mat13 S = H.transpose() * H;
  ConsistencyRun run;
  int accepted = 0;
  for (int k = 0; k < draws; ++k) {
    Vec13 n;
    for (int i = 0; i < kMeasuredDim; ++i) n[i] = n01(rng);
    const Vec13 delta = A * n;
    Eigen::VectorXd v(H.rows());
    for (int i = 0; i < H.rows(); ++i) v[i] = n01(rng);
    const Eigen::VectorXd z = H * (e - delta - offset) - v;
    const Vec13 g = H.transpose() * z;
    const ConsistencyTest t = consistencyTest(e, S, g, P, probability, min_information);
    accepted += t.passed;
    run.mean_nis += t.nis / draws;
    run.min_dof = std::min(run.min_dof, t.dof);
    run.max_dof = std::max(run.max_dof, t.dof);
  }
  run.acceptance = static_cast<double>(accepted) / draws;
  return run;
}

Eigen::MatrixXd randomRows(unsigned seed, int m, double scale) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  Eigen::MatrixXd H(m, kMeasuredDim);
  for (int i = 0; i < H.size(); ++i) H.data()[i] = scale * n01(rng);
  return H;
}
}  // namespace

// A measurement that agrees with the prior: the NIS is chi-square with 13 degrees of freedom, so
// the 0.99 gate accepts 99 % of the draws (binomial standard error over 4000: 0.16 %) and the mean
// NIS is 13 (standard error sqrt(2 13 / 4000) = 0.08).
TEST(EsikfUpdate, ConsistencyTestAcceptsAConsistentMeasurementAtItsProbability) {
  const Mat13 P = measuredCovariance(randomCovariance(31), FilterState::kLidar);
  // prior variances 0.01 to 0.5: rows of information ~20 put the measurement's information in the
  // prior's units (λ of consistencyTest) between about 0.2 and 10, where λ / (1 + λ) matters
  const Eigen::MatrixXd H = randomRows(32, 20, 1.0);
  const ConsistencyRun run = simulateConsistency(P, H, Vec13::Zero(), 4000, 0.99, 0.01, 33);
  RecordProperty("acceptance", std::to_string(run.acceptance));
  RecordProperty("mean_nis", std::to_string(run.mean_nis));
  EXPECT_EQ(run.min_dof, kMeasuredDim);
  EXPECT_EQ(run.max_dof, kMeasuredDim);
  EXPECT_NEAR(run.acceptance, 0.99, 0.005);
  EXPECT_NEAR(run.mean_nis, 13.0, 0.3);
  // at 0.9 one in ten is refused
  const ConsistencyRun run90 = simulateConsistency(P, H, Vec13::Zero(), 4000, 0.9, 0.01, 34);
  EXPECT_NEAR(run90.acceptance, 0.9, 0.015);

  // one draw by hand: with every direction tested the NIS is ν^T (P + S^-1)^-1 ν
  std::mt19937 rng(35);
  std::normal_distribution<double> n01;
  Vec13 e, g;
  for (int i = 0; i < kMeasuredDim; ++i) e[i] = 0.1 * n01(rng), g[i] = 10.0 * n01(rng);
  const Mat13 S = H.transpose() * H;
  const Vec13 nu = e - solveSymmetric(S, g);
  const Vec13 C_inv_nu = solveSymmetric(P + inverseOf(S), nu);
  const double nis = nu.dot(C_inv_nu);
  const ConsistencyTest t = consistencyTest(e, S, g, P, 0.99);
  EXPECT_NEAR(t.nis, nis, 1e-9 * nis);
  EXPECT_EQ(t.dof, kMeasuredDim);
  EXPECT_NEAR(t.threshold, 27.688, 1e-3);  // chi-square 0.99 quantile, 13 dof
  EXPECT_EQ(t.passed, nis <= t.threshold);
}

// A measurement 6 sigma off the prior in one direction (of P + S^-1) is refused: alone its NIS is
// exactly 36 > 27.69; with the noise on top the NIS is non-central chi-square (13 dof, non-centrality
// 36: mean 49) and beyond the 0.99 quantile in 96.4 % of the draws (2e5 simulated draws).
TEST(EsikfUpdate, ConsistencyTestRejectsAPlantedInconsistentMeasurement) {
  const Mat13 P = measuredCovariance(randomCovariance(41), FilterState::kCamera);
  const Eigen::MatrixXd H = randomRows(42, 20, 1.0);
  const Mat13 S = H.transpose() * H;
  const Mat13 C = P + inverseOf(S);  // the covariance of ν when the two agree
  Vec13 u;
  for (int i = 0; i < kMeasuredDim; ++i) u[i] = std::cos(1.0 + 2.0 * i);
  u.normalize();
  const Vec13 offset = 6.0 * C * u / std::sqrt(u.dot(C * u));  // Mahalanobis length 6
  // the offset alone (no prior error, no noise), at the prior
  const Vec13 g = H.transpose() * (H * (-offset));
  const ConsistencyTest alone = consistencyTest(Vec13::Zero(), S, g, P, 0.99);
  EXPECT_NEAR(alone.nis, 36.0, 1e-8);
  EXPECT_EQ(alone.dof, kMeasuredDim);
  EXPECT_FALSE(alone.passed);
  // with the prior's error and the measurement's noise
  const ConsistencyRun run = simulateConsistency(P, H, offset, 4000, 0.99, 0.01, 43);
  RecordProperty("rejection", std::to_string(1.0 - run.acceptance));
  RecordProperty("mean_nis", std::to_string(run.mean_nis));
  EXPECT_NEAR(run.mean_nis, 49.0, 0.8);  // standard error sqrt(2 (13 + 2 36) / 4000) = 0.21
  EXPECT_NEAR(1.0 - run.acceptance, 0.964, 0.012);
}

// Directions where the measurement knows less than min_information of what the prior knows (λ of
// W = L^T S L below it) are not tested: they are not counted in the degrees of freedom, and the NIS
// over the rest is still chi-square with that many.
TEST(EsikfUpdate, ConsistencyTestLeavesOutDirectionsTheMeasurementBarelySees) {
  const Mat13 P = measuredCovariance(randomCovariance(51), FilterState::kLidar);
  const Mat13 L = choleskyFactor(P);
  // a random orthonormal basis of the whitened space and the information along each of its vectors
  std::mt19937 rng(52);
  std::normal_distribution<double> n01;
  Mat13 M;
  for (int i = 0; i < M.size(); ++i) M.data()[i] = n01(rng);
  const Mat13 V = orthogonalFactor(M);
  Vec13 lambda;
  lambda << 0.0, 0.002, 0.005, 0.0099, 0.0101, 0.02, 0.5, 1.0, 3.0, 10.0, 100.0, 1e3, 1e4;
  // H = Λ^1/2 V^T L^-1: S = H^T H = L^-T V Λ V^T L^-1, i.e. W = V Λ V^T
  const Mat13 Linv = L.triangularView<Eigen::Lower>().solve(Mat13::Identity());
  const Eigen::MatrixXd H = lambda.cwiseSqrt().asDiagonal() * V.transpose() * Linv;
  const ConsistencyRun tested = simulateConsistency(P, H, Vec13::Zero(), 4000, 0.99, 0.01, 53);
  RecordProperty("acceptance", std::to_string(tested.acceptance));
  RecordProperty("mean_nis", std::to_string(tested.mean_nis));
  EXPECT_EQ(tested.min_dof, 9);  // λ >= 0.01
  EXPECT_EQ(tested.max_dof, 9);
  EXPECT_NEAR(tested.mean_nis, 9.0, 0.25);  // standard error sqrt(2 9 / 4000) = 0.067
  EXPECT_NEAR(tested.acceptance, 0.99, 0.005);
  const ConsistencyRun wider = simulateConsistency(P, H, Vec13::Zero(), 4000, 0.99, 0.001, 54);
  EXPECT_EQ(wider.min_dof, 12);  // λ >= 0.001: all but the direction without information
  EXPECT_EQ(wider.max_dof, 12);
  EXPECT_NEAR(wider.mean_nis, 12.0, 0.3);
  // a planted error along the weakest untested direction does not count at min_information 0.01
  // (the measurement says almost nothing there), but does once that direction is tested
  const Vec13 weak = L * V.col(3);                                      // λ = 0.0099
  const Vec13 offset = 50.0 * weak * std::sqrt(1.0 + 1.0 / lambda[3]);  // 50 sigma of P + S^-1 along it
  const Vec13 g = H.transpose() * (H * (-offset));
  const ConsistencyTest strict = consistencyTest(Vec13::Zero(), Mat13(H.transpose() * H), g, P, 0.99, 0.01);
  EXPECT_EQ(strict.dof, 9);
  EXPECT_LT(strict.nis, 1e-6);
  EXPECT_TRUE(strict.passed);
  const ConsistencyTest loose = consistencyTest(Vec13::Zero(), Mat13(H.transpose() * H), g, P, 0.99, 0.001);
  EXPECT_EQ(loose.dof, 12);
  EXPECT_NEAR(loose.nis, 2500.0, 1e-6 * 2500.0);
  EXPECT_FALSE(loose.passed);
}

// States held fixed (zero prior variance) are not tested: a measurement of the pose and a fixed
// calibration block has the pose's 6 degrees of freedom.
TEST(EsikfUpdate, ConsistencyTestLeavesOutFixedStates) {
  StateCovariance P32 = randomCovariance(61);
  setCalibrationPrior(FilterState::kLidar, CalibrationStd{}, &P32);
  const Mat13 P = measuredCovariance(P32, FilterState::kLidar);
  ASSERT_EQ((P.bottomRightCorner<7, 7>().cwiseAbs().maxCoeff()), 0.0);
  const Eigen::MatrixXd H = randomRows(62, 20, 1.0);
  const ConsistencyRun run = simulateConsistency(P, H, Vec13::Zero(), 4000, 0.99, 0.01, 63);
  RecordProperty("acceptance", std::to_string(run.acceptance));
  RecordProperty("mean_nis", std::to_string(run.mean_nis));
  EXPECT_EQ(run.min_dof, 6);
  EXPECT_EQ(run.max_dof, 6);
  EXPECT_NEAR(run.mean_nis, 6.0, 0.2);  // standard error sqrt(2 6 / 4000) = 0.055
  EXPECT_NEAR(run.acceptance, 0.99, 0.005);
  // nothing estimated: nothing tested, passed
  const ConsistencyTest none = consistencyTest(Vec13::Ones(), Mat13::Identity(), Vec13::Ones(), Mat13::Zero(), 0.99);
  EXPECT_EQ(none.dof, 0);
  EXPECT_TRUE(none.passed);
}

TEST(EsikfUpdate, DirectPoseMeasurementConvergesToTheMapEstimate) {
  // Measure the pose directly (z = T ⊟ T_meas) with a tight noise: the iterated update must land
  // on the measurement (to the prior's small weight) and shrink the pose covariance.
  FilterState prior;
  prior.rot = so3::Exp(Vec3(0.1, -0.2, 0.3));
  prior.pos = Vec3(1.0, 0.5, -0.2);
  const Pose3 meas = se3::boxplus(prior.pose(), (Vec6() << 0.05, -0.03, 0.08, 0.3, -0.2, 0.1).finished());
  const double sigma = 1e-3;
  const StateCovariance Phat = StateCovariance::Identity() * 0.1;
  auto measure = [&](const FilterState& x, int, MeasurementInformation* info) {
    const Vec6 z = se3::boxminus(x.pose(), meas);
    Mat6 H = Mat6::Identity();
    H.topLeftCorner<3, 3>() = so3::rightJacobianInverse(z.head<3>());
    info->HtRinvH.topLeftCorner<6, 6>() = H.transpose() * H / (sigma * sigma);
    info->HtRinvz.head<6>() = H.transpose() * z / (sigma * sigma);
    info->count = 6;
    return true;
  };
  FilterState post;
  StateCovariance Ppost;
  EsikfOptions opts;
  opts.max_iterations = 10;
  const EsikfResult r = iteratedUpdate(prior, Phat, measure, opts, &post, &Ppost);
  ASSERT_TRUE(r.valid);
  EXPECT_TRUE(r.converged);
  EXPECT_LE(r.iterations, 5);
  // the prior pulls by sigma^2 / (sigma^2 + 0.1) ~ 1e-5 of the offset
  EXPECT_LT(se3::boxminus(post.pose(), meas).norm(), 1e-5);
  EXPECT_LT(Ppost(3, 3), 1.1e-6);
  EXPECT_NEAR(Ppost(9, 9), 0.1, 1e-12);  // states the measurement does not touch keep their variance
  EXPECT_NEAR(Ppost(FilterState::kLidar + FilterState::kCalDt, FilterState::kLidar + FilterState::kCalDt), 0.1, 1e-12);
}

namespace {
struct RegistrationSetup {
  VoxelMap map;
  std::vector<Vec3> body;  // scan in the body frame
  Pose3 truth;
};

RegistrationSetup makeRegistration(const synth::Scene& scene, const synth::Trajectory& traj, double t, double noise) {
  RegistrationSetup s;
  std::mt19937 rng(11);
  auto model = synth::LidarModel::vlp16();
  model.range_noise_std = noise;
  // map from three sweeps around t, registered with the true poses (still sensor: t_still large)
  for (double dt : {-1.0, 0.0, 1.0}) {
    synth::Trajectory still = traj;
    still.t_still = 1e9;
    still.p0 = traj.pose(t + dt).translation();
    still.phi0 = so3::Log(traj.pose(t + dt).linear());
    const LidarScan scan = synth::simulateSweep(scene, still, model, 0, 0, Pose3::Identity(), &rng);
    std::vector<Vec3> world;
    for (const auto& p : scan.points) world.push_back(traj.pose(t + dt) * p);
    const auto idx = firstPointPerVoxel(world, 0.5);
    for (size_t i : idx) s.map.insert(world[i]);
  }
  synth::Trajectory still = traj;
  still.t_still = 1e9;
  still.p0 = traj.pose(t + 0.3).translation();
  still.phi0 = so3::Log(traj.pose(t + 0.3).linear());
  s.truth = traj.pose(t + 0.3);
  const LidarScan scan = synth::simulateSweep(scene, still, model, 0, 0, Pose3::Identity(), &rng);
  for (size_t i : firstPointPerVoxel(scan.points, 0.5)) s.body.push_back(scan.points[i]);
  return s;
}

FilterState offsetPrior(const Pose3& truth, const Vec6& offset) {
  FilterState x;
  const Pose3 T = se3::boxplus(truth, offset);
  x.rot = T.linear();
  x.pos = T.translation();
  return x;
}

// the navigation state loose, the sensors' calibration held fixed (the registration tests are about the pose)
StateCovariance looseCovariance() {
  StateCovariance P = StateCovariance::Zero();
  P.topLeftCorner<FilterState::kNavDim, FilterState::kNavDim>().setIdentity();
  P *= 1e-2;
  P.topLeftCorner<3, 3>() *= 1.0;          // 0.1 rad
  P.block<3, 3>(3, 3) = Mat3::Identity();  // 1 m
  return P;
}
}  // namespace

TEST(EsikfUpdate, SingleScanRegistrationWithKnownOffsetConverges) {
  auto setup = makeRegistration(synth::roomScene(), synth::roomTrajectory(0.0), 6.0, 0.01);
  ASSERT_GT(setup.body.size(), 500u);
  const Vec6 offset = (Vec6() << 0.02, -0.03, 0.08, 0.25, -0.2, 0.1).finished();  // ~5 deg, 0.34 m
  const FilterState prior = offsetPrior(setup.truth, offset);
  ScanToMapOptions mo;
  mo.point_noise_std = 0.03;
  mo.residual_range_factor = 1.0;  // a large initial offset: admit large residuals
  ScanToMap s2m(setup.map, nullptr, setup.body, mo);
  EsikfOptions eo;
  eo.max_iterations = 15;
  FilterState post;
  StateCovariance Ppost;
  const EsikfResult r = iteratedUpdate(
      prior, looseCovariance(),
      [&](const FilterState& x, int it, MeasurementInformation* info) { return s2m.evaluate(x, it, info); }, eo, &post,
      &Ppost);
  ASSERT_TRUE(r.valid);
  EXPECT_TRUE(r.converged);
  const Vec6 err = se3::boxminus(post.pose(), setup.truth);
  EXPECT_LT(err.head<3>().norm(), 2e-3) << err.transpose();  // rad
  EXPECT_LT(err.tail<3>().norm(), 1e-2) << err.transpose();  // m
  EXPECT_GT(r.info.count, 300);
  const DegeneracyReport dr = analyzeDegeneracy(r.info.geometry, 0.01);
  EXPECT_FALSE(dr.degenerate) << dr.translation_eigenvalues.transpose() << " | " << dr.rotation_eigenvalues.transpose();
  // the posterior pose covariance shrank from the loose prior
  EXPECT_LT(Ppost(3, 3), 1e-3);
  EXPECT_LT(Ppost(0, 0), 1e-4);
}

TEST(EsikfUpdate, TheRegistrationFloorBoundsWhatASweepSaysAboutThePose) {
  // Without a floor, a sweep's pose variance falls as 1 / (number of residuals): doubling the points
  // halves it, as if every point's error were its own. With the registration floor (the map's error,
  // shared by all residuals) the sweep is a pose measurement of covariance S^-1 + F: per axis the
  // floor's variance plus the points', so it stays above the floor's and more points change only
  // the points' share.
  auto setup = makeRegistration(synth::roomScene(), synth::roomTrajectory(0.0), 6.0, 0.01);
  std::vector<Vec3> half;
  for (size_t i = 0; i < setup.body.size(); i += 2) half.push_back(setup.body[i]);
  const FilterState prior = offsetPrior(setup.truth, Vec6::Zero());
  auto posterior = [&](const std::vector<Vec3>& body, double floor_rot, double floor_trans) {
    ScanToMapOptions mo;
    mo.registration_floor_rotation = floor_rot;
    mo.registration_floor_translation = floor_trans;
    ScanToMap s2m(setup.map, nullptr, body, mo);
    FilterState post;
    StateCovariance P;
    const EsikfResult r = iteratedUpdate(
        prior, looseCovariance(),
        [&](const FilterState& x, int it, MeasurementInformation* info) { return s2m.evaluate(x, it, info); },
        EsikfOptions{}, &post, &P);
    EXPECT_TRUE(r.valid);
    return Mat6(P.topLeftCorner<6, 6>());
  };
  const Mat6 all = posterior(setup.body, 0.0, 0.0), some = posterior(half, 0.0, 0.0);
  const double kRot = 2e-3, kTrans = 0.02;  // a floor well above what the points say
  const Mat6 all_f = posterior(setup.body, kRot, kTrans), some_f = posterior(half, kRot, kTrans);
  for (int i = 0; i < 6; ++i) {
    const double floor2 = i < 3 ? kRot * kRot : kTrans * kTrans;
    EXPECT_NEAR(some(i, i) / all(i, i), 2.0, 0.4) << i;  // independent errors: twice the points, half the variance
    EXPECT_GT(all_f(i, i), 0.9 * floor2) << i;           // never surer than the floor
    EXPECT_NEAR(all_f(i, i), floor2 + all(i, i), 0.02 * all_f(i, i)) << i;     // the floor plus the points
    EXPECT_NEAR(some_f(i, i), floor2 + some(i, i), 0.02 * some_f(i, i)) << i;  // ... with half of them
    EXPECT_LT(some_f(i, i) / all_f(i, i), 1.15) << i;  // more points, hardly a change (at most 1.10)
  }
}

TEST(EsikfUpdate, CorridorIsFlaggedDegenerateAlongItsAxis) {
  auto setup = makeRegistration(synth::corridorScene(), synth::corridorTrajectory(0.0), 4.0, 0.01);
  const Vec6 offset = (Vec6() << 0.0, 0.0, 0.02, 0.3, 0.05, 0.0).finished();
  const FilterState prior = offsetPrior(setup.truth, offset);
  ScanToMapOptions mo;
  mo.residual_range_factor = 1.0;
  ScanToMap s2m(setup.map, nullptr, setup.body, mo);
  EsikfOptions eo;
  eo.max_iterations = 10;
  FilterState post;
  StateCovariance Ppost;
  const StateCovariance P0 = looseCovariance();
  const EsikfResult r = iteratedUpdate(
      prior, P0, [&](const FilterState& x, int it, MeasurementInformation* info) { return s2m.evaluate(x, it, info); },
      eo, &post, &Ppost);
  ASSERT_TRUE(r.valid);
  const DegeneracyReport dr = analyzeDegeneracy(r.info.geometry, 0.01);
  EXPECT_TRUE(dr.degenerate) << dr.translation_eigenvalues.transpose();
  // only one direction is unconstrained: the translation along the corridor (world x)
  EXPECT_EQ(dr.degenerate_translations, 1);
  EXPECT_EQ(dr.degenerate_rotations, 0);
  EXPECT_LT(dr.translation_eigenvalues[0], 2e-3);  // range noise tilting the normals, no more
  EXPECT_GT(dr.translation_eigenvalues[1], 0.03);
  EXPECT_GT(std::abs(dr.translation_directions.col(0).x()), 0.999) << dr.translation_directions;
  EXPECT_GT(std::abs(dr.weakest_direction[3]), 0.999);
  // ... where the update leaves the prior alone: the x offset stays, y and yaw are corrected
  const Vec6 err = se3::boxminus(post.pose(), setup.truth);
  const Vec3 pos_err_world = post.pos - setup.truth.translation();
  EXPECT_NEAR(pos_err_world.x(), (prior.pos - setup.truth.translation()).x(), 0.02);
  EXPECT_LT(std::abs(pos_err_world.y()), 0.01);
  EXPECT_LT(std::abs(pos_err_world.z()), 0.01);
  EXPECT_LT(err.head<3>().norm(), 3e-3);
  // and its uncertainty along x stays that of the prior
  const Mat3 Pp = Ppost.block<3, 3>(3, 3);
  EXPECT_GT(Pp(0, 0), 0.9 * P0(3, 3));
}

TEST(EsikfUpdate, DegenerateDirectionsAreMarginalisedOutOfTheSweepsInformation) {
  // Rows that see the corridor's axis (world x) only together with a rotation: a corner's plane,
  // normal along x, at a lever arm. Removing x must also remove the rotation those rows measure
  // jointly with it; what is left is what the rows say about the rest whatever x is.
  std::mt19937 rng(11);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix<double, 40, 6> H;
  for (int r = 0; r < 40; ++r) {
    const bool along_axis = r < 3;  // three rows at one corner 3 m ahead with a normal along x
    const Vec3 normal =
        along_axis ? Vec3(1.0, 0.1 * n(rng), 0.1 * n(rng)).normalized() : Vec3(0.0, n(rng), n(rng)).normalized();
    const Vec3 lever = along_axis ? Vec3(3.0 + 0.3 * n(rng), 1.4 + 0.05 * n(rng), -1.1 + 0.05 * n(rng))
                                  : Vec3(5.0 * n(rng), 5.0 * n(rng), 2.0 * n(rng));
    H.row(r) << (lever.cross(normal)).transpose(), normal.transpose();
  }
  Eigen::Matrix<double, 40, 1> z;
  for (int r = 0; r < 40; ++r) z[r] = 0.01 * n(rng);
  Mat6 S = H.transpose() * H;
  Vec6 g = H.transpose() * z;
  Mat6 G = S / 40.0;
  G.topLeftCorner<3, 3>() /= 25.0, G.topRightCorner<3, 3>() /= 5.0, G.bottomLeftCorner<3, 3>() /= 5.0;
  const DegeneracyReport dr = analyzeDegeneracy(G, 0.1);  // the three rows: a share of 0.075
  ASSERT_EQ(dr.degenerate_translations, 1);
  ASSERT_EQ(dr.degenerate_rotations, 0);
  const Vec3 e = dr.translation_directions.col(0);
  EXPECT_GT(std::abs(e.x()), 0.99);
  Mat6 Sm = S;
  Vec6 gm = g;
  removeDegenerateInformation(dr, &Sm, &gm);
  // nothing left along the direction, and the information stays symmetric and positive semi-definite
  Vec6 e6;
  e6 << Vec3::Zero(), e;
  EXPECT_LT((Sm * e6).norm(), 1e-9 * S.norm());
  EXPECT_LT(std::abs(gm.dot(e6)), 1e-9 * g.norm());
  EXPECT_LT((Sm - Sm.transpose()).cwiseAbs().maxCoeff(), 1e-12 * S.norm());
  EXPECT_GT(minEigenvalue(Sm), -1e-9 * S.norm());
  // the rest: the least-squares answer of the full rows with the direction left free (the rows
  // alone are full rank, so it is their own solution) ...
  const Vec6 full = solveSymmetric(S, g);
  Mat6 Q = Mat6::Identity() - e6 * e6.transpose();
  const Vec6 rest = minimumNormSolution(Sm, gm);
  EXPECT_LT((Q * rest - Q * full).norm(), 1e-6 * full.norm() + 1e-12);
  // ... and its information the Schur complement: the inverse of the full covariance's block
  Eigen::Matrix<double, 6, 5> B;
  int c = 0;
  for (int i = 0; i < 6; ++i) {
    Vec6 u = Vec6::Unit(i) - e6 * e6[i];
    for (int j = 0; j < c; ++j) u -= B.col(j) * B.col(j).dot(u);
    if (u.norm() > 1e-6 && c < 5) B.col(c++) = u.normalized();
  }
  ASSERT_EQ(c, 5);
  const Eigen::Matrix<double, 5, 5> expected = inverseOf(B.transpose() * inverseOf(S) * B);
  EXPECT_LT((B.transpose() * Sm * B - expected).norm(), 1e-8 * expected.norm());
  // projecting instead keeps the rotation the along-axis rows measure jointly with x: more
  // information about the rotation than the rows hold when x is free
  const Mat6 projected = Q * S * Q;
  EXPECT_GT((B.transpose() * projected * B - expected).norm(), 5e-3 * expected.norm());
  // every direction degenerate: nothing is left; none: the information is untouched
  const DegeneracyReport all = analyzeDegeneracy(G, 1e9);
  ASSERT_EQ(all.degenerate_rotations + all.degenerate_translations, 6);
  Mat6 S_all = S;
  Vec6 g_all = g;
  removeDegenerateInformation(all, &S_all, &g_all);
  EXPECT_TRUE(S_all.isZero(0.0) && g_all.isZero(0.0));
  const DegeneracyReport none = analyzeDegeneracy(G, 0.0);
  ASSERT_FALSE(none.degenerate);
  Mat6 S_none = S;
  Vec6 g_none = g;
  removeDegenerateInformation(none, &S_none, &g_none);
  EXPECT_TRUE(S_none == S && g_none == g);
}

TEST(EsikfUpdate, PoseMeasurementFloorAddsItsCovarianceAndKeepsTheMeasuredPose) {
  // a pose measurement of information S (gradient g) with a floor F behaves as one of covariance
  // S^-1 + F around the same measured pose S^-1 g; a direction S knows nothing about stays empty
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix<double, 6, 9> J;
  for (int i = 0; i < J.size(); ++i) J.data()[i] = n(rng);
  const Mat6 S = 1e4 * J * J.transpose();
  Vec6 g;
  for (int i = 0; i < 6; ++i) g[i] = n(rng);
  Mat6 F = Mat6::Zero();
  F.diagonal() << 1e-6, 2e-6, 1e-6, 1e-4, 4e-4, 1e-4;
  Mat6 Sf = S;
  Vec6 gf = g;
  applyPoseMeasurementFloor(F, &Sf, &gf);
  const Mat6 expected = inverseOf(inverseOf(S) + F);
  EXPECT_LT((Sf - expected).norm(), 1e-9 * expected.norm());
  const Vec6 measured = solveSymmetric(S, g);
  EXPECT_LT((solveSymmetric(Sf, gf) - measured).norm(), 1e-9 * measured.norm());
  EXPECT_LT((Sf - Sf.transpose()).cwiseAbs().maxCoeff(), 1e-12 * Sf.norm());
  // the floor caps the information: no direction exceeds F^-1
  EXPECT_LT(maxEigenvalue(F.cwiseSqrt() * Sf * F.cwiseSqrt()), 1.0);
  // a singular S (nothing along the last position axis) keeps that direction at zero
  Mat6 S1 = S;
  S1.row(5).setZero();
  S1.col(5).setZero();
  Vec6 g1 = g;
  g1[5] = 0.0;
  applyPoseMeasurementFloor(F, &S1, &g1);
  EXPECT_TRUE(S1.allFinite());
  EXPECT_LT(S1.row(5).cwiseAbs().maxCoeff(), 1e-12 * S1.norm());
  EXPECT_NEAR(g1[5], 0.0, 1e-12);
}

// The floor over a pose and a calibration block: the measurement of covariance S^-1 + F around the
// same measured states S^-1 g.
TEST(EsikfUpdate, MeasurementFloorOverACalibrationBlock) {
  std::mt19937 rng(17);
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Matrix<double, kMeasuredDim, 20> J;
  for (int i = 0; i < J.size(); ++i) J.data()[i] = n(rng);
  const Mat13 S = 1e4 * J * J.transpose();
  Vec13 g;
  for (int i = 0; i < kMeasuredDim; ++i) g[i] = n(rng);
  Vec13 f;
  f << 1e-6, 2e-6, 1e-6, 1e-4, 4e-4, 1e-4, 3e-6, 3e-6, 3e-6, 1e-4, 1e-4, 1e-4, 1e-6;
  const Mat13 F = f.asDiagonal();
  Mat13 Sf = S;
  Vec13 gf = g;
  applyMeasurementFloor(F, &Sf, &gf);
  const Mat13 expected = inverseOf(inverseOf(S) + F);
  EXPECT_LT((Sf - expected).norm(), 1e-9 * expected.norm());
  const Vec13 measured = solveSymmetric(S, g);
  EXPECT_LT((solveSymmetric(Sf, gf) - measured).norm(), 1e-9 * measured.norm());
  EXPECT_EQ(Sf, Sf.transpose());
}

TEST(EsikfUpdate, CalibrationShareKeepsTheOptimumAndScalesTheCalibrationInformation) {
  // a measurement of the pose and a calibration block: its share of the calibration's information
  // keeps where the measurement on its own puts the measured states (-S^-1 g) and scales the
  // calibration's information with the pose eliminated by the share, the pose's with the
  // calibration eliminated not at all when they are uncorrelated
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  Eigen::Matrix<double, 40, kMeasuredDim> H;
  for (int i = 0; i < H.size(); ++i) H.data()[i] = n01(rng);
  MeasurementInformation m;
  m.calibration_block = FilterState::kCamera;
  m.HtRinvH = H.transpose() * H;
  for (int i = 0; i < kMeasuredDim; ++i) m.HtRinvz[i] = n01(rng);
  const Vec13 optimum = -solveSymmetric(m.HtRinvH, m.HtRinvz);
  const auto calibrationInformation = [](const Mat13& S) {
    const Mat6 Spp = S.topLeftCorner<6, 6>();
    const Eigen::Matrix<double, 6, 7> Spc = S.topRightCorner<6, 7>();
    return Eigen::Matrix<double, 7, 7>(S.bottomRightCorner<7, 7>() - Spc.transpose() * solveSymmetric(Spp, Spc));
  };
  const Mat13 P = Mat13::Identity() * 1e-2;  // every measured state estimated
  MeasurementInformation scaled = m;
  scaleCalibrationInformation(0.2, P, &scaled);
  EXPECT_LT((-solveSymmetric(scaled.HtRinvH, scaled.HtRinvz) - optimum).norm(), 1e-9 * optimum.norm());
  EXPECT_LT((calibrationInformation(scaled.HtRinvH) - 0.2 * calibrationInformation(m.HtRinvH)).norm(),
            1e-9 * calibrationInformation(m.HtRinvH).norm());
  EXPECT_LT((scaled.HtRinvH - scaled.HtRinvH.transpose()).cwiseAbs().maxCoeff(), 1e-12 * m.HtRinvH.norm());
  // the share 1 changes nothing, nor any share when the calibration is held fixed
  for (const double share : {1.0, 0.2}) {
    Mat13 held = P;
    if (share != 1.0) held.bottomRightCorner<7, 7>().setZero();
    MeasurementInformation same = m;
    scaleCalibrationInformation(share, held, &same);
    EXPECT_EQ(same.HtRinvH, m.HtRinvH);
    EXPECT_EQ(same.HtRinvz, m.HtRinvz);
  }
  // with only the rotation estimated, the optimum over the estimated states is kept, the held
  // ones staying where they are
  Mat13 rotation_only = P;
  rotation_only.block<4, 4>(9, 9).setZero();
  MeasurementInformation part = m;
  scaleCalibrationInformation(0.2, rotation_only, &part);
  const Eigen::Matrix<double, 9, 9> S9 = m.HtRinvH.topLeftCorner<9, 9>(), S9p = part.HtRinvH.topLeftCorner<9, 9>();
  const Eigen::Matrix<double, 9, 1> g9 = m.HtRinvz.head<9>(), g9p = part.HtRinvz.head<9>();
  const Eigen::VectorXd kept = solveSymmetric(S9, g9);
  EXPECT_LT((solveSymmetric(S9p, g9p) - kept).norm(), 1e-9 * kept.norm());
}
