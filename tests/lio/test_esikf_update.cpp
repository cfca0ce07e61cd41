// The iterated ESIKF update: the information form against the textbook gain of eqs. (16)-(18),
// a single-scan registration with a known offset converging to the truth, and the degeneracy
// analysis on a corridor (two walls and a floor) against a room.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <random>

#include "livo/lio/degeneracy.hpp"
#include "livo/esikf_update.hpp"
#include "livo/lio/scan_to_map.hpp"
#include "synthetic_world.hpp"

using namespace livo;
using namespace livo::lio;

namespace {
Mat18 randomCovariance(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  Mat18 A;
  for (int i = 0; i < 18; ++i)
    for (int j = 0; j < 18; ++j) A(i, j) = 0.1 * n01(rng);
  return A * A.transpose() + Mat18::Identity() * 0.01;
}

// A linearised pose measurement z + H δ with H = [H6 0] (m rows), a prior covariance P̂ and an
// iterate x̌ != x̂ (so J of eq. 12 is not the identity), with the textbook's P = J^-1 P̂ J^-T.
struct LinearisedPoseMeasurement {
  FilterState prior, x;
  Mat18 Phat, P;
  Eigen::MatrixXd H, R;
  Eigen::VectorXd z;
  Mat6 S() const { return H.leftCols<6>().transpose() * R.inverse() * H.leftCols<6>(); }
  Vec6 g() const { return H.leftCols<6>().transpose() * R.inverse() * z; }
  // the gain K = (H^T R^-1 H + P^-1)^-1 H^T R^-1 of eq. (17)
  Eigen::MatrixXd gain() const {
    const Eigen::MatrixXd Rinv = R.inverse();
    return (H.transpose() * Rinv * H + P.inverse()).inverse() * H.transpose() * Rinv;
  }
};

// `moved` marks the error states the iterate has moved from the prior.
LinearisedPoseMeasurement randomPoseMeasurement(unsigned seed, int m, const Vec18& moved, const Vec3& rot,
                                                const Vec3& pos) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01;
  LinearisedPoseMeasurement lm;
  lm.prior.rot = so3::Exp(rot);
  lm.prior.pos = pos;
  Vec18 d0;
  for (int i = 0; i < 18; ++i) d0[i] = 0.05 * n01(rng) * moved[i];
  lm.x = lm.prior.boxplus(d0);
  lm.Phat = randomCovariance(seed - 4);
  lm.H = Eigen::MatrixXd::Zero(m, 18);
  for (int i = 0; i < m; ++i)
    for (int j = 0; j < 6; ++j) lm.H(i, j) = n01(rng);
  lm.z.resize(m);
  for (int i = 0; i < m; ++i) lm.z[i] = 0.1 * n01(rng);
  lm.R = Eigen::MatrixXd::Zero(m, m);
  for (int i = 0; i < m; ++i) lm.R(i, i) = 0.01 * (1 + i);
  const Mat18 Jinv = FilterState::boxminusJacobian(lm.x, lm.prior).inverse();
  lm.P = Jinv * lm.Phat * Jinv.transpose();
  return lm;
}
}  // namespace

TEST(EsikfUpdate, InformationFormEqualsTextbookGain) {
  const LinearisedPoseMeasurement lm =
      randomPoseMeasurement(7, 9, Vec18::Ones(), Vec3(0.2, 0.1, -0.4), Vec3(1, 2, 3));
  // textbook: K of eq. (17), the step and covariance of eqs. (17) and (18)
  const Eigen::MatrixXd K = lm.gain();
  const Mat18 Jinv = FilterState::boxminusJacobian(lm.x, lm.prior).inverse();
  const Vec18 delta_ref = -K * lm.z - (Mat18::Identity() - K * lm.H) * Jinv * lm.x.boxminus(lm.prior);
  const Mat18 Ppost_ref = (Mat18::Identity() - K * lm.H) * lm.P;
  Vec18 delta;
  Mat18 Ppost;
  informationStep(lm.x, lm.prior, lm.Phat, lm.S(), lm.g(), &delta, &Ppost);
  EXPECT_LT((delta - delta_ref).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT((Ppost - Ppost_ref).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(EsikfUpdate, ConsiderStepEqualsTheSchmidtKalmanFilter) {
  // the gyro bias (and only it) considered: against the textbook Schmidt-Kalman filter, K' = M K
  // with M zero on the considered rows and P+ = (I - K'H) P (I - K'H)^T + K' R K'^T
  Vec18 keep = Vec18::Ones();
  keep.segment<3>(FilterState::kGyroBias).setZero();
  // the iterate has moved everything but the considered states
  const LinearisedPoseMeasurement lm = randomPoseMeasurement(9, 8, keep, Vec3(-0.1, 0.3, 0.2), Vec3(-1, 0.5, 2));
  const Eigen::MatrixXd Ks = keep.asDiagonal() * lm.gain();
  const Mat18 Jinv = FilterState::boxminusJacobian(lm.x, lm.prior).inverse();
  const Vec18 delta_ref = -Ks * lm.z - (Mat18::Identity() - Ks * lm.H) * Jinv * lm.x.boxminus(lm.prior);
  const Mat18 I_KH = Mat18::Identity() - Ks * lm.H;
  const Mat18 Ppost_ref = I_KH * lm.P * I_KH.transpose() + Ks * lm.R * Ks.transpose();
  Vec18 delta;
  Mat18 Ppost;
  informationStep(lm.x, lm.prior, lm.Phat, lm.S(), lm.g(), &delta, &Ppost, &keep);
  EXPECT_LT((delta - delta_ref).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT((Ppost - Ppost_ref).cwiseAbs().maxCoeff(), 1e-10);
  // the considered states keep their value and their variance; the rest steps as the full filter
  EXPECT_TRUE(delta.segment<3>(FilterState::kGyroBias).isZero());
  EXPECT_LT((Ppost.block<3, 3>(9, 9) - lm.P.block<3, 3>(9, 9)).cwiseAbs().maxCoeff(), 1e-12);
  Vec18 delta_full;
  Mat18 Pfull;
  informationStep(lm.x, lm.prior, lm.Phat, lm.S(), lm.g(), &delta_full, &Pfull);
  EXPECT_LT((delta - keep.asDiagonal() * delta_full).cwiseAbs().maxCoeff(), 1e-12);
  // and it never claims more than the optimal filter: P+ - P_full is positive semi-definite
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat18>(Ppost - Pfull).eigenvalues().minCoeff(), -1e-12);
}

TEST(EsikfUpdate, InformationBeyondPriorKeepsTheLargerInformationPerDirection) {
  // diagonal case: per axis max(0, s_i - 1/p_i)
  const Vec6 p = (Vec6() << 1e-4, 4e-4, 1e-2, 1e-6, 1.0, 0.25).finished();
  const Vec6 si = (Vec6() << 5e3, 1e3, 1e3, 1e5, 10.0, 0.0).finished();
  const Mat6 E = informationBeyondPrior(si.asDiagonal(), p.asDiagonal());
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
  const Mat6 post = P.inverse() + B;
  const Eigen::SelfAdjointEigenSolver<Mat6> below_meas(post - S), below_prior(post - P.inverse()), b(B);
  EXPECT_GT(below_meas.eigenvalues().minCoeff(), -1e-6 * S.norm());
  EXPECT_GT(below_prior.eigenvalues().minCoeff(), -1e-6 * S.norm());
  EXPECT_GT(b.eigenvalues().minCoeff(), -1e-6 * S.norm());
  const Mat6 L = Eigen::LLT<Mat6>(P).matrixL();
  const Eigen::SelfAdjointEigenSolver<Mat6> w(L.transpose() * S * L);
  const Mat6 expected = w.eigenvectors() * w.eigenvalues().cwiseMax(1.0).asDiagonal() * w.eigenvectors().transpose();
  EXPECT_LT((L.transpose() * post * L - expected).norm(), 1e-6 * expected.norm());
  EXPECT_EQ(Eigen::FullPivLU<Mat6>(B).rank(), 3);  // nothing where the measurement says nothing
  // a measurement weaker than the prior in every direction adds nothing
  EXPECT_LT(informationBeyondPrior(1e-3 * P.inverse(), P).norm(), 1e-9 * P.inverse().norm());
}

TEST(EsikfUpdate, DirectPoseMeasurementConvergesToTheMapEstimate) {
  // Measure the pose directly (z = T ⊟ T_meas) with a tight noise: the iterated update must land
  // on the measurement (to the prior's small weight) and shrink the pose covariance.
  FilterState prior;
  prior.rot = so3::Exp(Vec3(0.1, -0.2, 0.3));
  prior.pos = Vec3(1.0, 0.5, -0.2);
  const Pose3 meas = se3::boxplus(prior.pose(), (Vec6() << 0.05, -0.03, 0.08, 0.3, -0.2, 0.1).finished());
  const double sigma = 1e-3;
  const Mat18 Phat = Mat18::Identity() * 0.1;
  auto measure = [&](const FilterState& x, int, PoseInformation* info) {
    const Vec6 z = se3::boxminus(x.pose(), meas);
    Mat6 H = Mat6::Identity();
    H.topLeftCorner<3, 3>() = so3::rightJacobianInverse(z.head<3>());
    info->HtRinvH = H.transpose() * H / (sigma * sigma);
    info->HtRinvz = H.transpose() * z / (sigma * sigma);
    info->count = 6;
    return true;
  };
  FilterState post;
  Mat18 Ppost;
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
}

namespace {
struct RegistrationSetup {
  VoxelMap map;
  std::vector<Vec3> body;  // scan in the body frame
  Pose3 truth;
};

RegistrationSetup makeRegistration(const synth::Scene& scene, const synth::Trajectory& traj, double t,
                                   double noise) {
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

Mat18 looseCovariance() {
  Mat18 P = Mat18::Identity() * 1e-2;
  P.topLeftCorner<3, 3>() *= 1.0;           // 0.1 rad
  P.block<3, 3>(3, 3) = Mat3::Identity();   // 1 m
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
  ScanToMap s2m(setup.map, setup.body, mo);
  EsikfOptions eo;
  eo.max_iterations = 15;
  FilterState post;
  Mat18 Ppost;
  const EsikfResult r = iteratedUpdate(prior, looseCovariance(),
                                       [&](const FilterState& x, int it, PoseInformation* info) {
                                         return s2m.evaluate(x, it, info);
                                       },
                                       eo, &post, &Ppost);
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

TEST(EsikfUpdate, CorridorIsFlaggedDegenerateAlongItsAxis) {
  auto setup = makeRegistration(synth::corridorScene(), synth::corridorTrajectory(0.0), 4.0, 0.01);
  const Vec6 offset = (Vec6() << 0.0, 0.0, 0.02, 0.3, 0.05, 0.0).finished();
  const FilterState prior = offsetPrior(setup.truth, offset);
  ScanToMapOptions mo;
  mo.residual_range_factor = 1.0;
  ScanToMap s2m(setup.map, setup.body, mo);
  EsikfOptions eo;
  eo.max_iterations = 10;
  FilterState post;
  Mat18 Ppost;
  const Mat18 P0 = looseCovariance();
  const EsikfResult r = iteratedUpdate(prior, P0,
                                       [&](const FilterState& x, int it, PoseInformation* info) {
                                         return s2m.evaluate(x, it, info);
                                       },
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
  const Mat6 expected = (S.inverse() + F).inverse();
  EXPECT_LT((Sf - expected).norm(), 1e-9 * expected.norm());
  EXPECT_LT((Sf.ldlt().solve(gf) - S.ldlt().solve(g)).norm(), 1e-9 * S.ldlt().solve(g).norm());
  EXPECT_LT((Sf - Sf.transpose()).cwiseAbs().maxCoeff(), 1e-12 * Sf.norm());
  // the floor caps the information: no direction exceeds F^-1
  const Eigen::SelfAdjointEigenSolver<Mat6> es(F.cwiseSqrt() * Sf * F.cwiseSqrt());
  EXPECT_LT(es.eigenvalues().maxCoeff(), 1.0);
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
