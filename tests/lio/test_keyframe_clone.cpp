// The odometry increment's covariance from a cloned pose (keyframe_clone.hpp): the relative pose's
// Jacobians against numeric differentiation, the cross-covariance carried through updates against
// the filter augmented with the clone as states, and through propagation against the product of the
// propagation Jacobians.
#include <gtest/gtest.h>

#include <random>

#include "livo/esikf_update.hpp"
#include "livo/lio/imu_propagator.hpp"
#include "livo/lio/keyframe_clone.hpp"
#include "livo/so3.hpp"

using namespace livo;
using namespace livo::lio;

namespace {

Eigen::MatrixXd randomCovariance(int n, std::mt19937& rng, double scale) {
  std::normal_distribution<double> g(0.0, 1.0);
  Eigen::MatrixXd A(n, n);
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) A(r, c) = g(rng);
  return scale * (A * A.transpose() / n + 0.05 * Eigen::MatrixXd::Identity(n, n));
}

Pose3 somePose(const Vec3& r, const Vec3& t) {
  Pose3 T = Pose3::Identity();
  T.linear() = so3::Exp(r);
  T.translation() = t;
  return T;
}

// xi of T_a'^-1 T_b' against T_a^-1 T_b, with a and b perturbed as the filter's errors
Vec6 relativeError(const Pose3& Ta, const Pose3& Tb, const Vec6& da, const Vec6& db) {
  const auto perturbed = [](const Pose3& T, const Vec6& d) {
    Pose3 P = T;
    P.linear() = T.linear() * so3::Exp(d.head<3>());
    P.translation() = T.translation() + d.tail<3>();
    return P;
  };
  const Pose3 rel = Ta.inverse() * Tb;
  const Pose3 rel_p = perturbed(Ta, da).inverse() * perturbed(Tb, db);
  Vec6 xi;
  xi.head<3>() = so3::Log(Mat3(rel.linear().transpose() * rel_p.linear()));
  xi.tail<3>() = rel.linear().transpose() * (rel_p.translation() - rel.translation());
  return xi;
}

}  // namespace

TEST(KeyframeClone, RelativePoseCovarianceMatchesNumericJacobians) {
  std::mt19937 rng(7);
  const Pose3 Ta = somePose(Vec3(0.2, -0.4, 1.1), Vec3(3.0, -1.0, 0.5));
  const Pose3 Tb = somePose(Vec3(-0.3, 0.1, 2.0), Vec3(7.5, 2.0, 0.9));
  Eigen::Matrix<double, 6, 12> J;
  const double h = 1e-6;
  for (int i = 0; i < 12; ++i) {
    Vec6 da = Vec6::Zero(), db = Vec6::Zero();
    (i < 6 ? da[i] : db[i - 6]) = h;
    const Vec6 plus = relativeError(Ta, Tb, da, db);
    const Vec6 minus = relativeError(Ta, Tb, -da, -db);
    J.col(i) = (plus - minus) / (2 * h);
  }
  const Eigen::MatrixXd S = randomCovariance(12, rng, 1e-3);  // [a; b]
  const Eigen::MatrixXd expected = J * S * J.transpose();
  const Mat6 got =
      relativePoseCovariance(Ta, Tb, S.topLeftCorner(6, 6), S.bottomRightCorner(6, 6), S.bottomLeftCorner(6, 6));
  EXPECT_LT((got - expected).norm(), 1e-8 * expected.norm()) << got << "\n\n" << expected;
}

TEST(KeyframeClone, CrossCovarianceThroughUpdatesEqualsTheAugmentedFilter) {
  // the filter with the clone appended as six more states, updated by measurements of the filter's
  // states only: its cross block is what carriedThroughUpdate gives from the filter's P alone
  std::mt19937 rng(11);
  constexpr int n = FilterState::kDim;
  Eigen::MatrixXd Aug = randomCovariance(n + 6, rng, 1e-2);
  // a calibration held fixed: zero rows and columns (the filter's convention)
  for (int i = FilterState::kLidar; i < FilterState::kLidar + 3; ++i) {
    Aug.row(i).setZero();
    Aug.col(i).setZero();
  }
  StateCovariance P = Aug.topLeftCorner(n, n);
  CloneCrossCovariance C = Aug.topRightCorner(n, 6);
  FilterState x;  // the iterate at the prior: J = I
  for (int round = 0; round < 3; ++round) {
    MeasurementInformation m;
    m.calibration_block = round == 1 ? FilterState::kLidar : FilterState::kCamera;
    const Eigen::MatrixXd Hs = randomCovariance(kMeasuredDim, rng, 50.0);
    m.HtRinvH = Hs;
    for (int i = 6; i < 9 && m.calibration_block == FilterState::kLidar; ++i) {  // the held states see nothing
      m.HtRinvH.row(i).setZero();
      m.HtRinvH.col(i).setZero();
    }
    StateVector delta;
    StateCovariance P_post;
    informationStep(x, x, P, m, &delta, &P_post);
    // the augmented update: (Aug^-1 + E S E^T)^-1 over the non-held states
    Eigen::MatrixXd Info = Eigen::MatrixXd::Zero(n + 6, n + 6);
    for (int r = 0; r < kMeasuredDim; ++r)
      for (int c = 0; c < kMeasuredDim; ++c) Info(m.stateIndex(r), m.stateIndex(c)) = m.HtRinvH(r, c);
    Eigen::MatrixXd Kh = Aug * Info;  // Aug_post = (I + Aug Info)^-1 Aug
    const Eigen::MatrixXd Aug_post = (Eigen::MatrixXd::Identity(n + 6, n + 6) + Kh).partialPivLu().solve(Aug);
    C = carriedThroughUpdate(P, P_post, C);
    P = P_post;
    Aug = 0.5 * (Aug_post + Aug_post.transpose());
    const Eigen::MatrixXd C_ref = Aug.topRightCorner(n, 6);
    EXPECT_LT((C - C_ref).norm(), 1e-8 * C_ref.norm()) << "round " << round;
    EXPECT_LT((P - Aug.topLeftCorner(n, n)).norm(), 1e-8 * P.norm()) << "round " << round;
    EXPECT_LT((Aug.bottomRightCorner(6, 6) - Aug_post.bottomRightCorner(6, 6)).norm(), 1e-12);
  }
}

TEST(KeyframeClone, PropagationCarriesTheCrossCovarianceWithTheStateTransition) {
  ImuNoise noise;
  noise.gyro_scale_std = 0.01;
  ImuPropagator prop(noise);
  FilterState x0;
  x0.rot = so3::Exp(Vec3(0.1, -0.2, 0.7));
  x0.vel = Vec3(2.0, 0.5, 0.1);
  x0.gravity = Vec3(0.0, 0.0, -9.81);
  std::mt19937 rng(3);
  const StateCovariance P0 = randomCovariance(FilterState::kDim, rng, 1e-3);
  ImuSample s0;
  s0.utime = 1'000'000;
  s0.gyro = Vec3(0.1, -0.05, 0.4);
  s0.accel = Vec3(0.3, 0.1, 9.7);
  prop.reset(x0, P0, s0);
  prop.setCloneCross(P0.leftCols<6>());
  Mat18 Phi = Mat18::Identity();
  for (int k = 1; k <= 40; ++k) {
    ImuSample s;
    s.utime = s0.utime + k * 5000;
    s.gyro = Vec3(0.1 + 0.01 * k, -0.05, 0.4 - 0.005 * k);
    s.accel = Vec3(0.3, 0.1 * std::sin(0.2 * k), 9.7);
    const double dt = static_cast<double>(s.utime - prop.lastSample().utime) * 1e-6;
    Mat18 Fx;
    Mat18x12 Fw;
    propagationJacobians(prop.state(), 0.5 * (prop.lastSample().gyro + s.gyro),
                         0.5 * (prop.lastSample().accel + s.accel), dt, &Fx, &Fw);
    Phi = Fx * Phi;
    ASSERT_TRUE(prop.addSample(s));
  }
  CloneCrossCovariance expected = P0.leftCols<6>();
  expected.topRows<FilterState::kNavDim>() = Phi * P0.leftCols<6>().topRows<FilterState::kNavDim>();
  EXPECT_LT((prop.cloneCross() - expected).norm(), 1e-12 * expected.norm());
  // the pose block of a clone taken now is the pose's own covariance: the increment has none yet
  const StateCovariance& P = prop.covariance();
  const Mat6 rel = relativePoseCovariance(prop.state().pose(), prop.state().pose(), P.topLeftCorner<6, 6>(),
                                          P.topLeftCorner<6, 6>(), P.topLeftCorner<6, 6>());
  EXPECT_LT(rel.norm(), 1e-15);
}

// The held calibration's consider covariance against the errors themselves: the body increment a
// LiDAR mounted at X Exp(c) reports through the nominal X (numeric differentiation in c), and a
// gyro with scale and misalignment errors M turning the increment's rotation by M theta.
TEST(KeyframeClone, HeldCalibrationCovarianceMatchesTheErrorsItStandsFor) {
  const Pose3 X = somePose(Vec3(0.02, -0.05, 0.3), Vec3(0.1, -0.05, 0.15));
  const Pose3 T_rel = somePose(Vec3(0.01, -0.02, 0.25), Vec3(1.4, 0.2, -0.05));
  const Pose3 lidar_motion = X.inverse() * T_rel * X;  // what the LiDAR registers
  const double h = 1e-6;
  Mat6 J;
  for (int i = 0; i < 6; ++i) {
    Vec6 c = Vec6::Zero();
    c[i] = h;
    Pose3 E = Pose3::Identity();  // the true mount: X's right perturbation by c
    E.linear() = so3::Exp(c.head<3>());
    E.translation() = c.tail<3>();
    const Pose3 X_true = X * E;
    const Pose3 truth = X_true * lidar_motion * X_true.inverse();
    Vec6 xi;  // the truth as T_rel's right perturbation (relativePoseCovariance's convention)
    xi.head<3>() = so3::Log(Mat3(T_rel.linear().transpose() * truth.linear()));
    xi.tail<3>() = T_rel.linear().transpose() * (truth.translation() - T_rel.translation());
    J.col(i) = xi / h;
  }
  HeldCalibration held;
  held.T_I_L = X;
  held.lidar_rotation_std = 0.005;
  held.lidar_translation_std = 0.01;
  Vec6 var;
  var << Vec3::Constant(0.005 * 0.005), Vec3::Constant(0.01 * 0.01);
  const Mat6 expected = J * var.asDiagonal() * J.transpose();
  const Mat6 got = heldCalibrationCovariance(T_rel, held);
  EXPECT_LT((got - expected).norm(), 1e-6 * expected.norm()) << got << "\n\n" << expected;
  // a rotation error of the mount turns the increment's 1.4 m: about 7 mm across it, 7 mm up
  EXPECT_NEAR(std::sqrt(got(5, 5)), 0.005 * 1.4, 0.0015);

  // the gyro: M theta with independent scale and misalignment entries
  HeldCalibration gyro;
  gyro.gyro_scale_std = 0.01;
  gyro.gyro_misalignment_std = 0.007;
  const Vec3 theta = so3::Log(Mat3(T_rel.linear()));
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  Mat3 sample_cov = Mat3::Zero();
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    Mat3 M;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) M(r, c) = g(rng) * (r == c ? gyro.gyro_scale_std : gyro.gyro_misalignment_std);
    const Vec3 e = M * theta;
    sample_cov += e * e.transpose() / n;
  }
  const Mat6 gyro_cov = heldCalibrationCovariance(T_rel, gyro);
  const bool rotation_only = gyro_cov.bottomRows(3).isZero() && gyro_cov.topRightCorner(3, 3).isZero();
  EXPECT_TRUE(rotation_only);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(gyro_cov(i, i), sample_cov(i, i), 0.05 * sample_cov.trace());
  EXPECT_TRUE(heldCalibrationCovariance(T_rel, HeldCalibration{}).isZero());
}
