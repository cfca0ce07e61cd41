// The VIO core on rendered images of the simulated room: the map seeded from an image at the
// true pose, then a single-image update from a perturbed prior recovers the true pose; the map
// stays within its bounds; a loop correction moves it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "livo/vio/vio_estimator.hpp"
#include "sim_fixture.hpp"

using namespace livo;
using namespace livo::vio;

namespace {

struct PoseError {
  double rot_deg, pos_m;
};
PoseError poseError(const FilterState& a, const FilterState& b) {
  const Vec18 d = a.boxminus(b);
  return {d.head<3>().norm() * 180.0 / M_PI, d.segment<3>(3).norm()};
}

// Seeds the map at trajectory time t0 with the true pose (scans of the two sweeps before t0) and a
// covariance that says so (0.03 deg, 1 mm): the references carry it (UpdateOptions::reference_floor).
void seed(const livo_test::SimScene& s, VioEstimator* vio, double t0, double sweep = 0.1) {
  vio->addScan(s.utime(t0 - sweep), s.sweep(t0 - 2 * sweep, 1));
  vio->addScan(s.utime(t0), s.sweep(t0 - sweep, 2));
  const ImageResult r = vio->processImage(s.image(t0, 1), s.trueState(t0), livo_test::priorCovariance(5e-4, 0.001));
  EXPECT_FALSE(r.valid);  // nothing to align on yet
  EXPECT_EQ(r.why, "the point-patch map is empty");
  EXPECT_GT(r.new_points, 50);
}

Vec18 offsetOf(double rot_deg, double pos_m, int k) {
  Vec18 d = Vec18::Zero();
  d.head<3>() = Vec3(std::sin(1.3 * k + 0.2), std::cos(0.7 * k), std::sin(0.4 * k + 1.0)).normalized() * (rot_deg * M_PI / 180.0);
  d.segment<3>(3) = Vec3(std::cos(1.1 * k), std::sin(0.9 * k + 0.5), std::cos(0.3 * k + 2.0)).normalized() * pos_m;
  return d;
}

}  // namespace

TEST(VioEstimator, SingleImageUpdateRecoversAKnownPoseOffset) {
  const livo_test::SimScene s;
  VioEstimator vio(VioOptions{}, s.camera());
  const double t0 = 6.0, t1 = 6.05;
  seed(s, &vio, t0);
  ASSERT_GT(vio.map().size(), 50u);

  const FilterState truth = s.trueState(t1);
  Vec18 offset = Vec18::Zero();
  offset.head<3>() = Vec3(0.3, -0.25, 0.2).normalized() * (0.5 * M_PI / 180.0);  // 0.5 deg
  offset.segment<3>(3) = Vec3(0.02, -0.015, 0.015).normalized() * 0.03;          // 3 cm
  const FilterState prior = truth.boxplus(offset);
  const Mat18 P = livo_test::priorCovariance(1.0 * M_PI / 180.0, 0.05);
  const ImageResult r = vio.processImage(s.image(t1, 2), prior, P);
  ASSERT_TRUE(r.valid) << r.why << " (in view " << r.selection.in_view << ", occluded " << r.selection.occluded << ", depth edge " << r.selection.depth_edge << ", no reference " << r.selection.no_reference << ", selected " << r.selection.selected << ")";
  const PoseError before = poseError(prior, truth), after = poseError(r.state, truth);
  std::printf("prior error %.3f deg %.4f m -> posterior %.3f deg %.4f m; %d patches, %d residuals, %d iterations, "
              "Mahalanobis^2 %.2f, cost %.2f -> %.2f, selection in view %d occluded %d no ref %d\n",
              before.rot_deg, before.pos_m, after.rot_deg, after.pos_m, r.patches, r.num_measurements, r.iterations,
              r.mahalanobis, r.cost_prior, r.cost_post, r.selection.in_view, r.selection.occluded,
              r.selection.no_reference);
  EXPECT_NEAR(before.rot_deg, 0.5, 1e-9);
  EXPECT_NEAR(before.pos_m, 0.03, 1e-9);
  EXPECT_LT(after.rot_deg, 0.1 * before.rot_deg);
  EXPECT_LT(after.pos_m, 0.2 * before.pos_m);
  EXPECT_GE(r.patches, 50);
  EXPECT_EQ(r.num_measurements, r.patches * kPatchArea);
  // the posterior covariance shrinks on the pose and stays symmetric positive definite
  const double trace_post = r.covariance.topLeftCorner<6, 6>().trace(), trace_prior = P.topLeftCorner<6, 6>().trace();
  EXPECT_LT(trace_post, 0.5 * trace_prior);
  EXPECT_LT((r.covariance - r.covariance.transpose()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(Eigen::LLT<Mat18>(r.covariance).info(), Eigen::Success);
}

TEST(VioEstimator, TracksASequenceAndMaintainsTheMap) {
  // 1.5 s of the walk at 20 Hz, sweeps at 10 Hz from the true poses, every prior 1 cm / 0.2 deg
  // off the truth with a matching covariance; the map is maintained from the posteriors.
  const livo_test::SimScene s;
  VioEstimator vio(VioOptions{}, s.camera());
  const double t0 = 8.0;
  seed(s, &vio, t0);
  const Mat18 P = livo_test::priorCovariance(0.2 * M_PI / 180.0, 0.01);
  std::vector<double> pos_err, rot_err;
  int valid = 0, new_points = 0, new_patches = 0;
  for (int k = 1; k <= 30; ++k) {
    const double t = t0 + 0.05 * k;
    if (k % 2 == 0) vio.addScan(s.utime(t), s.sweep(t - 0.1, static_cast<uint64_t>(10 + k)));
    const FilterState truth = s.trueState(t);
    const ImageResult r = vio.processImage(s.image(t, static_cast<uint64_t>(10 + k)), truth.boxplus(offsetOf(0.2, 0.01, k)), P);
    valid += r.valid;
    new_points += r.new_points;
    new_patches += r.new_patches;
    const PoseError e = poseError(r.state, truth);
    pos_err.push_back(e.pos_m);
    rot_err.push_back(e.rot_deg);
    EXPECT_LE(r.map_points, static_cast<size_t>(VioOptions{}.map.max_points));
  }
  std::sort(pos_err.begin(), pos_err.end());
  std::sort(rot_err.begin(), rot_err.end());
  std::printf("sequence: %d/30 valid, median error %.4f m %.4f deg, worst %.4f m %.4f deg, %d new points, "
              "%d new patches, map %zu points\n",
              valid, pos_err[15], rot_err[15], pos_err.back(), rot_err.back(), new_points, new_patches, vio.map().size());
  EXPECT_GE(valid, 28);
  EXPECT_LT(pos_err[15], 0.004);       // from 10 mm
  EXPECT_LT(rot_err[15], 0.05);        // from 0.2 deg
  EXPECT_LT(pos_err.back(), 0.01);
  EXPECT_GT(new_points, 20);           // the map grows as the view moves on
  EXPECT_GT(new_patches, 5);           // and tracked points get new patches as their view changes
}

TEST(VioEstimator, SolidStateLidarPointsWorkTheSame) {
  // a Livox-like non-repetitive pattern instead of the spinning VLP-16: only the points in the
  // camera's field of view matter, whatever the pattern
  const livo_test::SimScene s("config/sim/room.yaml", 0, "livox-avia");
  VioEstimator vio(VioOptions{}, s.camera());
  const double t0 = 6.0, t1 = 6.05;
  seed(s, &vio, t0, s.sweepDuration());
  const FilterState truth = s.trueState(t1);
  const ImageResult r = vio.processImage(s.image(t1, 2), truth.boxplus(offsetOf(0.5, 0.03, 3)),
                                         livo_test::priorCovariance(1.0 * M_PI / 180.0, 0.05));
  ASSERT_TRUE(r.valid) << r.why;
  const PoseError after = poseError(r.state, truth);
  EXPECT_LT(after.rot_deg, 0.05);
  EXPECT_LT(after.pos_m, 0.006);
}

TEST(VioEstimator, LoopCorrectionMovesMapAndScans) {
  const livo_test::SimScene s;
  VioEstimator vio(VioOptions{}, s.camera());
  seed(s, &vio, 6.0);
  const Vec3 p0 = vio.map().point(0).position;
  const Pose3 T_obs = vio.map().point(0).observations[0].T_W_C;
  const Pose3 T = se3::fromRotationTranslation(so3::Exp(Vec3(0.01, -0.02, 0.3)), Vec3(1.0, -0.5, 0.1));
  const size_t n = vio.map().size(), scan_points = vio.recentScanPoints();
  vio.applyCorrection(T);
  EXPECT_TRUE(vio.map().point(0).position.isApprox(T * p0, 1e-12));
  EXPECT_TRUE(vio.map().point(0).observations[0].T_W_C.isApprox(T * T_obs, 1e-12));
  EXPECT_EQ(vio.map().size(), n);
  EXPECT_EQ(vio.recentScanPoints(), scan_points);
  // the corrected frame: the truth moved by T is recovered from a perturbed prior
  FilterState truth = s.trueState(6.05);
  truth.rot = T.linear() * truth.rot;
  truth.pos = T * truth.pos;
  const ImageResult r = vio.processImage(s.image(6.05, 2), truth.boxplus(offsetOf(0.3, 0.02, 5)),
                                         livo_test::priorCovariance(1.0 * M_PI / 180.0, 0.05));
  ASSERT_TRUE(r.valid) << r.why;
  EXPECT_LT(poseError(r.state, truth).pos_m, 0.006);
}

TEST(VioEstimator, ConsidersTheGyroBiasOnceTheFilterKnowsIt) {
  // a prior whose attitude error is correlated with the gyro bias (as after propagation): while
  // the bias is uncertain the image corrects it through that correlation; once its 1-sigma is at
  // most update.gyro_bias_std_to_update the image leaves it, and its variance, as the prior had them
  const livo_test::SimScene s;
  const FilterState truth = s.trueState(6.05);
  const FilterState prior = truth.boxplus(offsetOf(0.3, 0.01, 3));
  for (const double bias_std : {1e-3, 5e-5}) {
    Mat18 P = livo_test::priorCovariance(0.3 * M_PI / 180.0, 0.02);
    const double rot_std = 0.3 * M_PI / 180.0;
    P.block<3, 3>(FilterState::kGyroBias, FilterState::kGyroBias) = Mat3::Identity() * bias_std * bias_std;
    P.block<3, 3>(FilterState::kRot, FilterState::kGyroBias) = Mat3::Identity() * 0.8 * rot_std * bias_std;
    P.block<3, 3>(FilterState::kGyroBias, FilterState::kRot) = Mat3::Identity() * 0.8 * rot_std * bias_std;
    VioEstimator vio(VioOptions{}, s.camera());
    seed(s, &vio, 6.0);
    const ImageResult r = vio.processImage(s.image(6.05, 2), prior, P);
    ASSERT_TRUE(r.valid) << r.why;
    const Vec3 dbg = r.state.gyro_bias - prior.gyro_bias;
    const Mat3 var_post = r.covariance.block<3, 3>(FilterState::kGyroBias, FilterState::kGyroBias);
    if (bias_std > VioOptions{}.update.gyro_bias_std_to_update) {
      EXPECT_GT(dbg.norm(), 0.1 * bias_std);
      EXPECT_LT(var_post.trace(), 0.9 * 3.0 * bias_std * bias_std);
    } else {
      EXPECT_EQ(dbg.norm(), 0.0);
      EXPECT_LT((var_post - Mat3::Identity() * bias_std * bias_std).cwiseAbs().maxCoeff(), 1e-6 * bias_std * bias_std);
    }
    EXPECT_LT(poseError(r.state, truth).rot_deg, 0.5 * poseError(prior, truth).rot_deg);
    EXPECT_EQ(Eigen::LLT<Mat18>(r.covariance).info(), Eigen::Success);
  }
}

TEST(VioEstimator, RejectsAnUpdateThatContradictsThePrior) {
  // a prior 2 cm off with a covariance claiming 2 mm: a confident photometric measurement
  // (low noise) moves the pose by far more than the prior allows
  const livo_test::SimScene s;
  VioOptions o;
  o.photometric.noise_std = 10.0;
  o.update.reference_floor = 0.0;  // the references as exact (the seed is the truth)
  VioEstimator vio(o, s.camera());
  seed(s, &vio, 6.0);
  const FilterState truth = s.trueState(6.05);
  const FilterState prior = truth.boxplus(offsetOf(0.2, 0.02, 7));
  const Mat18 P = livo_test::priorCovariance(0.03 * M_PI / 180.0, 0.002);
  const ImageResult r = vio.processImage(s.image(6.05, 2), prior, P);
  EXPECT_FALSE(r.valid);
  EXPECT_NE(r.why.find("Mahalanobis"), std::string::npos) << r.why;
  EXPECT_GT(r.mahalanobis, o.update.max_mahalanobis);
  // the answer is the prior, untouched
  EXPECT_EQ(r.state.boxminus(prior).norm(), 0.0);
  EXPECT_TRUE(r.covariance == P);
}

TEST(VioEstimator, RollingShutterRowsArePlacedWithTheGyroRate) {
  CameraRig rig = livo_test::SimScene().camera();
  rig.rolling_shutter_s = 0.02;
  VioEstimator vio(VioOptions{}, rig);
  const int64_t t = 1'700'000'000'000'000;
  FilterState x;
  x.gyro_bias = Vec3(0.01, -0.02, 0.03);
  // no samples and no earlier image: no rate
  EXPECT_EQ(vio.shutterAt(t, x).omega_I, Vec3::Zero());
  EXPECT_DOUBLE_EQ(vio.shutterAt(t, x).line_time, 0.02 / rig.height);
  // the mean of the samples within 15 ms of the image, less the state's gyro bias
  vio.addGyro(t - 30000, Vec3(9.0, 9.0, 9.0));  // too early
  vio.addGyro(t - 10000, Vec3(0.4, 0.0, -0.2));
  vio.addGyro(t - 5000, Vec3(0.6, 0.2, -0.4));
  vio.addGyro(t + 5000, Vec3(0.5, 0.1, -0.3));
  vio.addGyro(t + 20000, Vec3(-9.0, 9.0, 9.0));  // too late
  EXPECT_TRUE(vio.shutterAt(t, x).omega_I.isApprox(Vec3(0.49, 0.12, -0.33), 1e-12));
  // a global shutter needs no rate
  VioEstimator global(VioOptions{}, livo_test::SimScene().camera());
  global.addGyro(t, Vec3(1.0, 1.0, 1.0));
  EXPECT_FALSE(global.shutterAt(t, x).active());
  EXPECT_EQ(global.shutterAt(t, x).omega_I, Vec3::Zero());
}

TEST(VioEstimator, VoxelPointsSnapFlatVoxelsOntoTheirPlane) {
  // one voxel (0.3 m) of a wall z = 0.15 seen with 3 cm range noise: its first point is moved
  // onto the fitted plane; a voxel holding a corner and one with too few points keep theirs
  MapOptions o;
  o.plane_snap_max_rms = 0.05;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.03);
  std::uniform_real_distribution<double> u(0.01, 0.29);
  std::vector<float> x, y, z;
  auto add = [&](double a, double b, double c) { x.push_back(a), y.push_back(b), z.push_back(c); };
  add(0.15, 0.15, 0.15 + 0.06);  // the wall's first point, 2 sigma off
  for (int i = 0; i < 60; ++i) add(u(rng), u(rng), std::clamp(0.15 + noise(rng), 0.001, 0.299));
  add(std::nan(""), 0.1, 0.1);   // skipped
  // corner voxel at x in [1.2, 1.5): half the points on z = 0.05, half on x = 1.25
  add(1.4, 0.15, 0.12);
  for (int i = 0; i < 30; ++i) add(1.2 + u(rng), u(rng), 0.05), add(1.25, u(rng), u(rng));
  // a voxel with three points
  add(3.1, 0.1, 0.1), add(3.2, 0.1, 0.2), add(3.15, 0.2, 0.15);
  const std::vector<Vec3> snapped = voxelPoints(x.data(), y.data(), z.data(), x.size(), o);
  ASSERT_EQ(snapped.size(), 3u);
  EXPECT_LT(std::abs(snapped[0].z() - 0.15), 0.015);  // 6 cm off before
  EXPECT_NEAR(snapped[0].x(), 0.15, 0.02);            // moved along the normal only
  EXPECT_TRUE(snapped[1].isApprox(Vec3(1.4, 0.15, 0.12), 1e-6));
  EXPECT_TRUE(snapped[2].isApprox(Vec3(3.1, 0.1, 0.1), 1e-6));
  o.plane_snap_max_rms = 0.0;  // off: the raw first points
  const std::vector<Vec3> raw = voxelPoints(x.data(), y.data(), z.data(), x.size(), o);
  ASSERT_EQ(raw.size(), 3u);
  EXPECT_NEAR(raw[0].z(), 0.21, 1e-6);
}

TEST(VioEstimator, CovarianceCountsOnlyTheInformationBeyondThePrior) {
  // the same image and prior through both covariance rules: the state steps alike, but with a
  // prior tighter than the image along some directions `beyond_prior` leaves those directions as
  // the prior had them, while `full` adds the image's information everywhere
  const livo_test::SimScene s;
  const double t0 = 6.0, t1 = 6.05;
  const FilterState truth = s.trueState(t1);
  const FilterState prior = truth.boxplus(offsetOf(0.05, 0.003, 1));
  Mat18 P = livo_test::priorCovariance(0.2 * M_PI / 180.0, 0.01);
  P.block<3, 3>(0, 0) = Mat3::Identity() * std::pow(0.005 * M_PI / 180.0, 2);  // rotation: tighter than the image
  ImageResult r[2];
  for (int k = 0; k < 2; ++k) {
    VioOptions o;
    o.update.covariance = k == 0 ? CovarianceUpdate::kFull : CovarianceUpdate::kBeyondPrior;
    VioEstimator vio(o, s.camera());
    seed(s, &vio, t0);
    r[k] = vio.processImage(s.image(t1, 2), prior, P);
    ASSERT_TRUE(r[k].valid) << r[k].why;
  }
  EXPECT_LT(r[0].state.boxminus(r[1].state).norm(), 1e-12);  // the step does not depend on the rule
  const Mat6 P0 = P.topLeftCorner<6, 6>(), full = r[0].covariance.topLeftCorner<6, 6>(),
             beyond = r[1].covariance.topLeftCorner<6, 6>();
  const double rot0 = P0.topLeftCorner(3, 3).trace(), pos0 = P0.bottomRightCorner(3, 3).trace();
  // rotation: full still shrinks it a little, beyond_prior keeps it to within 1 %
  EXPECT_LT(full.topLeftCorner(3, 3).trace(), 0.99 * rot0);
  EXPECT_NEAR(beyond.topLeftCorner(3, 3).trace(), rot0, 0.01 * rot0);
  // position (looser than the image): both shrink it, beyond_prior less, never below full
  EXPECT_LT(beyond.bottomRightCorner(3, 3).trace(), 0.5 * pos0);
  const Eigen::SelfAdjointEigenSolver<Mat6> diff(beyond - full);
  EXPECT_GT(diff.eigenvalues().minCoeff(), -1e-15);
  EXPECT_EQ(Eigen::LLT<Mat18>(r[1].covariance).info(), Eigen::Success);
}

TEST(VioEstimator, CalibrationFloorLiesAcrossTheBaselines) {
  // a rotation error ε of the camera shifts a patch seen again a baseline b away as a move by ε × b:
  // nothing along b, σ |b| across it; the image's floor averages its patches
  const double sigma = 0.3 * M_PI / 180.0;
  std::vector<TrackedPatch> patches(2);
  const Vec3 c(1.0, 2.0, 0.5);
  patches[0].reference_centre = c - Vec3(2.0, 0.0, 0.0);
  patches[1].reference_centre = c - Vec3(2.0, 0.0, 0.0);
  Mat3 F = calibrationFloor(patches, c, sigma);
  EXPECT_LT((F - sigma * sigma * Vec3(0.0, 4.0, 4.0).asDiagonal().toDenseMatrix()).norm(), 1e-15);
  patches[1].reference_centre = c - Vec3(0.0, 0.0, 1.0);  // a vertical baseline of 1 m
  F = calibrationFloor(patches, c, sigma);
  EXPECT_LT((F - sigma * sigma * Vec3(0.5, 2.5, 2.0).asDiagonal().toDenseMatrix()).norm(), 1e-15);
  // a numeric check of the model: the mean squared displacement ε × b over sampled ε
  std::mt19937 rng(3);
  std::normal_distribution<double> n(0.0, sigma);
  Mat3 M = Mat3::Zero();
  const int N = 200000;
  for (int k = 0; k < N; ++k) {
    const Vec3 eps(n(rng), n(rng), n(rng));
    for (const TrackedPatch& t : patches) {
      const Vec3 d = eps.cross(c - t.reference_centre);
      M += d * d.transpose() / (2.0 * N);
    }
  }
  EXPECT_LT((M - F).norm(), 0.02 * F.norm());
  EXPECT_TRUE(calibrationFloor({}, c, sigma).isZero());
}

TEST(VioEstimator, ReferencesCarryThePoseCovarianceTheyWereCutAt) {
  // every observation keeps the pose covariance of the image it was cut in (rotation turned into
  // the world frame); an image's reference floor is their mean, rotation back in its body frame
  const livo_test::SimScene s;
  VioEstimator vio(VioOptions{}, s.camera());
  const double t0 = 6.0;
  vio.addScan(s.utime(t0 - 0.1), s.sweep(t0 - 0.2, 1));
  vio.addScan(s.utime(t0), s.sweep(t0 - 0.1, 2));
  Mat18 P_seed = livo_test::priorCovariance(0.004, 0.02);
  P_seed(0, 0) = 0.002 * 0.002;  // anisotropic, to see the rotation's frame
  P_seed(3, 4) = P_seed(4, 3) = 1e-4;
  const FilterState x0 = s.trueState(t0);
  vio.processImage(s.image(t0, 1), x0, P_seed);
  ASSERT_GT(vio.map().size(), 50u);
  Mat6 J = Mat6::Identity();
  J.topLeftCorner<3, 3>() = x0.rot;
  const Mat6 expected_W = J * P_seed.topLeftCorner<6, 6>() * J.transpose();
  const Mat6 stored = vio.map().point(0).observations[0].pose_cov_W.cast<double>();
  EXPECT_LT((stored - expected_W).norm(), 1e-6 * expected_W.norm());

  std::vector<TrackedPatch> patches(2);
  patches[0].reference_cov_W = expected_W;
  patches[1].reference_cov_W = Mat6::Identity() * 1e-4;
  const Mat3 R = so3::Exp(Vec3(0.3, -0.2, 1.1));
  const Mat6 F = referenceFloor(patches, R);
  Mat6 Jb = Mat6::Identity();
  Jb.topLeftCorner<3, 3>() = R.transpose();
  EXPECT_LT((F - 0.5 * Jb * (expected_W + Mat6::Identity() * 1e-4) * Jb.transpose()).norm(), 1e-12);
  // at the seed's own attitude the floor is the seed's pose covariance
  EXPECT_LT((referenceFloor({patches[0]}, x0.rot) - P_seed.topLeftCorner<6, 6>()).norm(), 1e-6 * expected_W.norm());
  EXPECT_TRUE(referenceFloor({}, R).isZero());
}

TEST(VioEstimator, AnImageMeasuresThePoseOnlyAsWellAsItsReferencesWereKnown) {
  // the same rendered images and prior (3 cm, 0.5 deg off, 5 cm / 1 deg 1-sigma); the map seeded at
  // the true pose, once with a covariance of 1 mm / 0.03 deg, once claiming the prior's own 5 cm /
  // 1 deg. With references that uncertain the image is a pose measurement no better than the prior:
  // the posterior goes about halfway; with exact references it goes nearly all the way.
  const livo_test::SimScene s;
  const double t0 = 6.0, t1 = 6.05;
  const FilterState truth = s.trueState(t1);
  Vec18 offset = Vec18::Zero();
  offset.head<3>() = Vec3(0.3, -0.25, 0.2).normalized() * (0.5 * M_PI / 180.0);
  offset.segment<3>(3) = Vec3(0.02, -0.015, 0.015).normalized() * 0.03;
  const FilterState prior = truth.boxplus(offset);
  const Mat18 P = livo_test::priorCovariance(1.0 * M_PI / 180.0, 0.05);
  double remaining[2];
  for (int k = 0; k < 2; ++k) {
    VioEstimator vio(VioOptions{}, s.camera());
    vio.addScan(s.utime(t0 - 0.1), s.sweep(t0 - 0.2, 1));
    vio.addScan(s.utime(t0), s.sweep(t0 - 0.1, 2));
    vio.processImage(s.image(t0, 1), s.trueState(t0), k == 0 ? livo_test::priorCovariance(5e-4, 0.001) : P);
    const ImageResult r = vio.processImage(s.image(t1, 2), prior, P);
    ASSERT_TRUE(r.valid) << r.why;
    remaining[k] = poseError(r.state, truth).pos_m / poseError(prior, truth).pos_m;
  }
  std::printf("position error left: %.2f with exact references, %.2f with references as uncertain as the prior\n",
              remaining[0], remaining[1]);
  EXPECT_LT(remaining[0], 0.1);
  EXPECT_GT(remaining[1], 0.35);
  EXPECT_LT(remaining[1], 0.65);
}
