// The VIO core on rendered images of the simulated room: the map seeded from an image at the
// true pose, then a single-image update from a perturbed prior recovers the true pose; the map
// stays within its bounds; a loop correction moves it; over a sequence the camera's calibration in
// the state (its rotation and time shift) converges to a planted error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <string>

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
  const StateVector d = a.boxminus(b);
  return {d.head<3>().norm() * 180.0 / M_PI, d.segment<3>(3).norm()};
}

// A posterior covariance the filter can use: finite, symmetric, positive definite on the
// navigation state, the calibration held fixed by the prior (zero rows and columns) left so.
void expectUsable(const StateCovariance& P, bool calibration_fixed = true) {
  EXPECT_TRUE(isUsableCovariance(P));
  EXPECT_LT((P - P.transpose()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(Eigen::LLT<Mat18>(P.topLeftCorner<FilterState::kNavDim, FilterState::kNavDim>()).info(), Eigen::Success);
  if (calibration_fixed) {
    EXPECT_TRUE(P.rightCols<2 * FilterState::kCalibrationDim>().isZero(0.0));
    EXPECT_TRUE(P.bottomRows<2 * FilterState::kCalibrationDim>().isZero(0.0));
  }
}

// Seeds the map at trajectory time t0 with the true pose (scans of the two sweeps before t0) and a
// covariance that says so (0.03 deg, 1 mm): the references carry it (UpdateOptions::reference_floor).
void seed(const livo_test::SimScene& s, VioEstimator* vio, double t0, double sweep = 0.1) {
  vio->addScan(s.utime(t0 - sweep), s.sweep(t0 - 2 * sweep, 1));
  vio->addScan(s.utime(t0), s.sweep(t0 - sweep, 2));
  const ImageResult r =
      vio->processImage(s.image(t0, 1), s.trueState(t0), livo_test::priorCovariance(5e-4, 0.001), s.bodyRate(t0));
  EXPECT_FALSE(r.valid);  // nothing to align on yet
  EXPECT_EQ(r.why, "the point-patch map is empty");
  EXPECT_GT(r.new_points, 50);
}

StateVector offsetOf(double rot_deg, double pos_m, int k) {
  StateVector d = StateVector::Zero();
  d.head<3>() =
      Vec3(std::sin(1.3 * k + 0.2), std::cos(0.7 * k), std::sin(0.4 * k + 1.0)).normalized() * (rot_deg * M_PI / 180.0);
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
  StateVector offset = StateVector::Zero();
  offset.head<3>() = Vec3(0.3, -0.25, 0.2).normalized() * (0.5 * M_PI / 180.0);  // 0.5 deg
  offset.segment<3>(3) = Vec3(0.02, -0.015, 0.015).normalized() * 0.03;          // 3 cm
  const FilterState prior = truth.boxplus(offset);
  const StateCovariance P = livo_test::priorCovariance(1.0 * M_PI / 180.0, 0.05);
  const ImageResult r = vio.processImage(s.image(t1, 2), prior, P, s.bodyRate(t1));
  ASSERT_TRUE(r.valid) << r.why << " (in view " << r.selection.in_view << ", occluded " << r.selection.occluded
                       << ", depth edge " << r.selection.depth_edge << ", no reference " << r.selection.no_reference
                       << ", selected " << r.selection.selected << ")";
  const PoseError before = poseError(prior, truth), after = poseError(r.state, truth);
  std::printf(
      "prior error %.3f deg %.4f m -> posterior %.3f deg %.4f m; %d patches, %d residuals, %d iterations, "
      "NIS %.2f (%d dof, gate %.2f), cost %.2f -> %.2f, selection in view %d occluded %d no ref %d\n",
      before.rot_deg, before.pos_m, after.rot_deg, after.pos_m, r.patches, r.num_measurements, r.iterations,
      r.consistency.nis, r.consistency.dof, r.consistency.threshold, r.cost_prior, r.cost_post, r.selection.in_view,
      r.selection.occluded, r.selection.no_reference);
  EXPECT_NEAR(before.rot_deg, 0.5, 1e-9);
  EXPECT_NEAR(before.pos_m, 0.03, 1e-9);
  EXPECT_LT(after.rot_deg, 0.1 * before.rot_deg);
  EXPECT_LT(after.pos_m, 0.2 * before.pos_m);
  EXPECT_GE(r.patches, 50);
  EXPECT_EQ(r.num_measurements, r.patches * kPatchArea);
  // the posterior covariance shrinks on the pose and stays symmetric positive definite
  const double trace_post = r.covariance.topLeftCorner<6, 6>().trace(), trace_prior = P.topLeftCorner<6, 6>().trace();
  EXPECT_LT(trace_post, 0.5 * trace_prior);
  expectUsable(r.covariance);
  EXPECT_TRUE(r.consistency.passed);
  EXPECT_GT(r.consistency.dof, 0);
  // the calibration the prior holds fixed (zero variance) is left exactly as it was
  EXPECT_EQ(r.state.camera.rot, prior.camera.rot);
  EXPECT_EQ(r.state.camera.pos, prior.camera.pos);
  EXPECT_EQ(r.state.camera.dt, prior.camera.dt);
  EXPECT_EQ(r.state.lidar.rot, prior.lidar.rot);
}

TEST(VioEstimator, TracksASequenceAndMaintainsTheMap) {
  // 1.5 s of the walk at 20 Hz, sweeps at 10 Hz from the true poses, every prior 1 cm / 0.2 deg
  // off the truth with a matching covariance; the map is maintained from the posteriors.
  const livo_test::SimScene s;
  VioEstimator vio(VioOptions{}, s.camera());
  const double t0 = 8.0;
  seed(s, &vio, t0);
  const StateCovariance P = livo_test::priorCovariance(0.2 * M_PI / 180.0, 0.01);
  std::vector<double> pos_err, rot_err;
  int valid = 0, new_points = 0, new_patches = 0;
  for (int k = 1; k <= 30; ++k) {
    const double t = t0 + 0.05 * k;
    if (k % 2 == 0) vio.addScan(s.utime(t), s.sweep(t - 0.1, static_cast<uint64_t>(10 + k)));
    const FilterState truth = s.trueState(t);
    const ImageResult r = vio.processImage(s.image(t, static_cast<uint64_t>(10 + k)),
                                           truth.boxplus(offsetOf(0.2, 0.01, k)), P, s.bodyRate(t));
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
  std::printf(
      "sequence: %d/30 valid, median error %.4f m %.4f deg, worst %.4f m %.4f deg, %d new points, "
      "%d new patches, map %zu points\n",
      valid, pos_err[15], rot_err[15], pos_err.back(), rot_err.back(), new_points, new_patches, vio.map().size());
  EXPECT_GE(valid, 28);
  EXPECT_LT(pos_err[15], 0.004);  // from 10 mm
  EXPECT_LT(rot_err[15], 0.05);   // from 0.2 deg
  EXPECT_LT(pos_err.back(), 0.01);
  EXPECT_GT(new_points, 20);  // the map grows as the view moves on
  EXPECT_GT(new_patches, 5);  // and tracked points get new patches as their view changes
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
                                         livo_test::priorCovariance(1.0 * M_PI / 180.0, 0.05), s.bodyRate(t1));
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
  const Pose3 T_obs = vio.map().point(0).observations[0].view.cameraPose();
  const Pose3 T = se3::fromRotationTranslation(so3::Exp(Vec3(0.01, -0.02, 0.3)), Vec3(1.0, -0.5, 0.1));
  const size_t n = vio.map().size(), scan_points = vio.recentScanPoints();
  vio.applyCorrection(T);
  EXPECT_TRUE(vio.map().point(0).position.isApprox(T * p0, 1e-12));
  EXPECT_TRUE(vio.map().point(0).observations[0].view.cameraPose().isApprox(T * T_obs, 1e-12));
  EXPECT_EQ(vio.map().size(), n);
  EXPECT_EQ(vio.recentScanPoints(), scan_points);
  // the corrected frame: the truth moved by T is recovered from a perturbed prior
  FilterState truth = s.trueState(6.05);
  truth.rot = T.linear() * truth.rot;
  truth.pos = T * truth.pos;
  // (the body rate is a body-frame quantity: the correction leaves it)
  const ImageResult r = vio.processImage(s.image(6.05, 2), truth.boxplus(offsetOf(0.3, 0.02, 5)),
                                         livo_test::priorCovariance(1.0 * M_PI / 180.0, 0.05), s.bodyRate(6.05));
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
    StateCovariance P = livo_test::priorCovariance(0.3 * M_PI / 180.0, 0.02);
    const double rot_std = 0.3 * M_PI / 180.0;
    P.block<3, 3>(FilterState::kGyroBias, FilterState::kGyroBias) = Mat3::Identity() * bias_std * bias_std;
    P.block<3, 3>(FilterState::kRot, FilterState::kGyroBias) = Mat3::Identity() * 0.8 * rot_std * bias_std;
    P.block<3, 3>(FilterState::kGyroBias, FilterState::kRot) = Mat3::Identity() * 0.8 * rot_std * bias_std;
    VioEstimator vio(VioOptions{}, s.camera());
    seed(s, &vio, 6.0);
    const ImageResult r = vio.processImage(s.image(6.05, 2), prior, P, s.bodyRate(6.05));
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
    expectUsable(r.covariance);
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
  const StateCovariance P = livo_test::priorCovariance(0.03 * M_PI / 180.0, 0.002);
  const ImageResult r = vio.processImage(s.image(6.05, 2), prior, P, s.bodyRate(6.05));
  EXPECT_FALSE(r.valid);
  // the chi-square consistency gate (update.gate_probability) refuses it
  EXPECT_NE(r.why.find("inconsistent with the prior"), std::string::npos) << r.why;
  EXPECT_FALSE(r.consistency.passed);
  EXPECT_GT(r.consistency.dof, 0);
  EXPECT_GT(r.consistency.threshold, 0.0);
  EXPECT_GT(r.consistency.nis, r.consistency.threshold);
  std::printf("contradicting prior: NIS %.1f > %.1f (%d dof)\n", r.consistency.nis, r.consistency.threshold,
              r.consistency.dof);
  // the answer is the prior, untouched
  EXPECT_EQ(r.state.boxminus(prior).norm(), 0.0);
  EXPECT_TRUE(r.covariance == P);
}

TEST(VioEstimator, RollingShutterRowsArePlacedWithTheGivenBodyRate) {
  // the body rate comes with the prior (filter_state_t.angular_velocity): a rolling shutter's rows
  // and the camera's time shift move the body with it. Every patch cut from an image keeps the view
  // it was cut in: the body pose at its row's time (stamp + time shift + row time), that rate, the
  // velocity and the calibration; a global shutter cuts every patch at stamp + time shift.
  const livo_test::SimScene s;
  const double t0 = 6.0, shift = 0.004;
  const Vec3 rate(0.3, -0.5, 0.4);  // not the truth: only what the estimator does with it matters here
  FilterState prior = s.trueState(t0);
  prior.camera.dt = shift;
  for (const double readout : {0.02, 0.0}) {
    CameraRig rig = s.camera();
    rig.rolling_shutter_s = readout;
    VioEstimator vio(VioOptions{}, rig);
    vio.addScan(s.utime(t0 - 0.1), s.sweep(t0 - 0.2, 1));
    vio.addScan(s.utime(t0), s.sweep(t0 - 0.1, 2));
    vio.processImage(s.image(t0, 1), prior, livo_test::priorCovariance(5e-4, 0.001), rate);
    ASSERT_GT(vio.map().size(), 50u);
    const RollingShutter shutter = RollingShutter::fromReadout(readout, rig.height);
    double min_row = 1e9, max_row = -1e9, worst_rot = 0.0, worst_pos = 0.0;
    for (const MapPoint& m : vio.map().points()) {
      ASSERT_EQ(m.observations.size(), 1u);
      const ReferenceView& v = m.observations[0].view;
      EXPECT_EQ(v.omega_I, rate);
      EXPECT_EQ(v.vel_W, prior.vel);
      EXPECT_EQ(v.time_shift, shift);
      EXPECT_TRUE(v.T_I_C.isApprox(prior.camera.pose(), 1e-15));
      const double row = shutter.rowTime(v.pixel.y());
      min_row = std::min(min_row, row);
      max_row = std::max(max_row, row);
      const double dt = shift + row;
      worst_rot =
          std::max(worst_rot, so3::Log((prior.rot * so3::Exp(rate * dt)).transpose() * v.T_W_I.linear()).norm());
      worst_pos = std::max(worst_pos, (v.T_W_I.translation() - (prior.pos + prior.vel * dt)).norm());
    }
    // (the row time is that of the projection before the last fixed-point step: a few hundredths
    // of a row from the patch's own)
    EXPECT_LE(worst_rot, 0.05 * shutter.line_time * rate.norm()) << "readout " << readout;
    EXPECT_LE(worst_pos, 0.05 * shutter.line_time * prior.vel.norm() + 1e-12) << "readout " << readout;
    if (readout > 0.0) {
      EXPECT_GT(max_row - min_row, 0.5 * readout);  // the patches lie on rows far apart
    } else {
      EXPECT_EQ(min_row, 0.0);
      EXPECT_EQ(max_row, 0.0);
    }
  }
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
  add(std::nan(""), 0.1, 0.1);  // skipped
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

TEST(VioEstimator, VoxelPointsGiveTheNormalsOfPlanarVoxelsOnly) {
  // a wall voxel with 3 cm range noise: its normal; a corner, one ring's arc (a line with the
  // noise across it) and a voxel of three points: none
  MapOptions o;
  o.normal_max_rms = 0.05;
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.03);
  std::uniform_real_distribution<double> u(0.01, 0.29);
  std::vector<float> x, y, z;
  auto add = [&](double a, double b, double c) { x.push_back(a), y.push_back(b), z.push_back(c); };
  for (int i = 0; i < 40; ++i) add(u(rng), u(rng), std::clamp(0.15 + noise(rng), 0.001, 0.299));
  for (int i = 0; i < 20; ++i) add(1.2 + u(rng), u(rng), 0.05), add(1.25, u(rng), u(rng));
  for (int i = 0; i < 20; ++i) add(2.1 + u(rng), 0.15, std::clamp(0.15 + noise(rng), 0.001, 0.299));
  add(3.1, 0.1, 0.1), add(3.2, 0.1, 0.2), add(3.15, 0.2, 0.15);
  std::vector<Vec3> normals;
  const std::vector<Vec3> points = voxelPoints(x.data(), y.data(), z.data(), x.size(), o, &normals);
  ASSERT_EQ(points.size(), 4u);
  ASSERT_EQ(normals.size(), 4u);
  EXPECT_NEAR(normals[0].norm(), 1.0, 1e-9);
  EXPECT_GT(std::abs(normals[0].z()), std::cos(10.0 * M_PI / 180.0));  // 40 points, 3 cm noise: a few deg
  EXPECT_EQ(normals[1], Vec3::Zero());
  EXPECT_EQ(normals[2], Vec3::Zero());
  EXPECT_EQ(normals[3], Vec3::Zero());
  EXPECT_TRUE(points[0].isApprox(Vec3(x[0], y[0], z[0]), 1e-6));  // normals do not move the points
  o.normal_max_rms = 0.0;                                         // off: no normals
  voxelPoints(x.data(), y.data(), z.data(), x.size(), o, &normals);
  ASSERT_EQ(normals.size(), 4u);
  EXPECT_EQ(normals[0], Vec3::Zero());
}

TEST(VioEstimator, CovarianceCountsOnlyTheInformationBeyondThePrior) {
  // the same image and prior through both covariance rules: the state steps alike, but with a
  // prior tighter than the image along some directions `beyond_prior` leaves those directions as
  // the prior had them, while `full` adds the image's information everywhere
  const livo_test::SimScene s;
  const double t0 = 6.0, t1 = 6.05;
  const FilterState truth = s.trueState(t1);
  const FilterState prior = truth.boxplus(offsetOf(0.05, 0.003, 1));
  StateCovariance P = livo_test::priorCovariance(0.2 * M_PI / 180.0, 0.01);
  // rotation: tighter than the image (0.01 deg; at 0.005 deg `full` now shrinks it by only 0.9 %:
  // the image's rotation information, with each patch's map point and reference pose eliminated as
  // nuisances, is under 1 % of such a prior's)
  P.block<3, 3>(0, 0) = Mat3::Identity() * std::pow(0.01 * M_PI / 180.0, 2);
  ImageResult r[2];
  for (int k = 0; k < 2; ++k) {
    VioOptions o;
    o.update.covariance = k == 0 ? CovarianceUpdate::kFull : CovarianceUpdate::kBeyondPrior;
    VioEstimator vio(o, s.camera());
    seed(s, &vio, t0);
    r[k] = vio.processImage(s.image(t1, 2), prior, P, s.bodyRate(t1));
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
  expectUsable(r[1].covariance);
}

TEST(VioEstimator, ReferencesCarryThePoseCovarianceTheyWereCutAt) {
  // every observation keeps the pose covariance of the image it was cut in (rotation turned into
  // the world frame); an image's reference floor is their mean, rotation back in its body frame
  const livo_test::SimScene s;
  VioEstimator vio(VioOptions{}, s.camera());
  const double t0 = 6.0;
  vio.addScan(s.utime(t0 - 0.1), s.sweep(t0 - 0.2, 1));
  vio.addScan(s.utime(t0), s.sweep(t0 - 0.1, 2));
  StateCovariance P_seed = livo_test::priorCovariance(0.004, 0.02);
  P_seed(0, 0) = 0.002 * 0.002;  // anisotropic, to see the rotation's frame
  P_seed(3, 4) = P_seed(4, 3) = 1e-4;
  const FilterState x0 = s.trueState(t0);
  vio.processImage(s.image(t0, 1), x0, P_seed, s.bodyRate(t0));
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
  StateVector offset = StateVector::Zero();
  offset.head<3>() = Vec3(0.3, -0.25, 0.2).normalized() * (0.5 * M_PI / 180.0);
  offset.segment<3>(3) = Vec3(0.02, -0.015, 0.015).normalized() * 0.03;
  const FilterState prior = truth.boxplus(offset);
  const StateCovariance P = livo_test::priorCovariance(1.0 * M_PI / 180.0, 0.05);
  double remaining[2];
  for (int k = 0; k < 2; ++k) {
    VioEstimator vio(VioOptions{}, s.camera());
    vio.addScan(s.utime(t0 - 0.1), s.sweep(t0 - 0.2, 1));
    vio.addScan(s.utime(t0), s.sweep(t0 - 0.1, 2));
    vio.processImage(s.image(t0, 1), s.trueState(t0), k == 0 ? livo_test::priorCovariance(5e-4, 0.001) : P,
                     s.bodyRate(t0));
    const ImageResult r = vio.processImage(s.image(t1, 2), prior, P, s.bodyRate(t1));
    ASSERT_TRUE(r.valid) << r.why;
    remaining[k] = poseError(r.state, truth).pos_m / poseError(prior, truth).pos_m;
  }
  std::printf("position error left: %.2f with exact references, %.2f with references as uncertain as the prior\n",
              remaining[0], remaining[1]);
  EXPECT_LT(remaining[0], 0.1);
  EXPECT_GT(remaining[1], 0.35);
  EXPECT_LT(remaining[1], 0.65);
}

namespace {

using Mat7 = Eigen::Matrix<double, FilterState::kCalibrationDim, FilterState::kCalibrationDim>;
using Vec7 = Eigen::Matrix<double, FilterState::kCalibrationDim, 1>;

// A walk through the room at 20 Hz with the camera mounted `T_err` off the rig's T_I_C and its
// images taken `time_shift` after their stamps, sweeps at 10 Hz from the true poses. Every prior
// is the true body pose, a little off (0.02 deg, 2 mm, with a covariance of 0.03 deg / 3 mm: a LIO
// in a room), with the camera calibration and its covariance block of the previous posterior, as
// lio carries them from one image to the next (the first: the rig's T_I_C and no shift, rotation
// 0.5 deg and time 5 ms 1-sigma, translation held). Returns the camera calibration's error
// (⊟ the truth: rotation, translation, time shift) and covariance after each image.
struct CalibrationRun {
  std::vector<double> t;
  std::vector<Vec7> error;
  std::vector<Mat7> covariance;
  int valid = 0, images = 0;
  std::map<std::string, int> why;  // of the images not valid (numbers dropped)
  Vec3 final_translation_change = Vec3::Zero();
};

CalibrationRun runCalibration(const Pose3& T_err, double time_shift, double t0, double duration,
                              const CalibrationStd& sigma = CalibrationStd{0.5 * M_PI / 180.0, 0.0, 0.005},
                              const VioOptions& options = VioOptions{}, double prior_rot_deg = 0.03,
                              double prior_pos = 0.003) {
  const bool verbose = std::getenv("LIVO_VIO_TEST_VERBOSE") != nullptr;
  livo_test::SimScene s;
  s.mountCameraWithError(T_err);
  VioEstimator vio(options, s.camera());
  constexpr int c = FilterState::kCamera;
  FilterState truth_calibration;
  truth_calibration.camera = SensorCalibration::fromPose(s.camera().T_I_C * T_err, time_shift);
  SensorCalibration camera = SensorCalibration::fromPose(s.camera().T_I_C);
  StateCovariance P_block = StateCovariance::Zero();
  setCalibrationPrior(c, sigma, &P_block);
  Mat7 P_camera = P_block.block<7, 7>(c, c);
  const StateCovariance P_nav = livo_test::priorCovariance(prior_rot_deg * M_PI / 180.0, prior_pos);
  CalibrationRun run;
  vio.addScan(s.utime(t0 - 0.1), s.sweep(t0 - 0.2, 1));
  const int n = static_cast<int>(std::lround(duration / 0.05));
  for (int k = 0; k <= n; ++k) {
    const double t = t0 + 0.05 * k;
    if (k % 2 == 0) vio.addScan(s.utime(t), s.sweep(t - 0.1, static_cast<uint64_t>(100 + k)));
    FilterState prior = s.trueState(t).boxplus(offsetOf(2.0 / 3.0 * prior_rot_deg, 2.0 / 3.0 * prior_pos, k));
    prior.camera = camera;
    StateCovariance P = P_nav;
    P.block<7, 7>(c, c) = P_camera;
    const ImageResult r =
        vio.processImage(s.image(t, static_cast<uint64_t>(100 + k), time_shift), prior, P, s.bodyRate(t));
    ++run.images;
    if (!r.valid) ++run.why[r.why.substr(0, r.why.find(" ("))];
    if (r.valid) {
      ++run.valid;
      camera = r.state.camera;
      P_camera = r.covariance.block<7, 7>(c, c);
      EXPECT_TRUE(isUsableCovariance(r.covariance)) << "image " << k;
    }
    FilterState estimate;
    estimate.camera = camera;
    run.t.push_back(t);
    run.error.push_back(estimate.boxminus(truth_calibration).segment<7>(c));
    run.covariance.push_back(P_camera);
    if (verbose) {
      const Vec7& e = run.error.back();
      std::printf(
          "    %5.2f %d %3d patches, NIS %6.2f / %6.2f (%d dof), pose err %.3f deg %.4f m, cal err [%.3f %.3f %.3f] "
          "deg "
          "%.3f ms %s\n",
          t, r.valid, r.patches, r.consistency.nis, r.consistency.threshold, r.consistency.dof,
          poseError(r.state, s.trueState(t)).rot_deg, poseError(r.state, s.trueState(t)).pos_m, e[0] * 180.0 / M_PI,
          e[1] * 180.0 / M_PI, e[2] * 180.0 / M_PI, e[6] * 1e3, r.why.c_str());
    }
  }
  run.final_translation_change = camera.pos - s.camera().T_I_C.translation();
  return run;
}

void printRun(const char* what, const CalibrationRun& run) {
  std::printf("%s: %d/%d images valid; error of the camera calibration (estimate - truth) and 1-sigma:\n", what,
              run.valid, run.images);
  for (size_t i = 0; i < run.t.size(); i += 20) {
    const Vec7& e = run.error[i];
    const Vec7 sd = run.covariance[i].diagonal().cwiseSqrt();
    const double d = 180.0 / M_PI;
    std::printf("  t %5.2f  rot [%7.3f %7.3f %7.3f] +- [%5.3f %5.3f %5.3f] deg  dt %7.3f +- %5.3f ms\n", run.t[i],
                e[0] * d, e[1] * d, e[2] * d, sd[0] * d, sd[1] * d, sd[2] * d, e[6] * 1e3, sd[6] * 1e3);
  }
  for (const auto& [why, n] : run.why) std::printf("  not valid %d x: %s\n", n, why.c_str());
}

}  // namespace

TEST(VioEstimator, RecoversAPlantedCameraRotationAndTimeShift) {
  // the camera turned 0.4 deg against the rig's T_I_C and its images taken 3 ms after their stamps:
  // over 8 s of the walk the state's camera calibration goes from the rig's to the truth, within
  // its 3 sigma and at least 3x closer than the rig's; with nothing planted it stays at the rig's
  const Vec3 axis = Vec3(0.5, -0.7, 0.5).normalized();
  const double angle = 0.4 * M_PI / 180.0, shift = 0.003;
  const Pose3 T_err = se3::fromRotationTranslation(so3::Exp(axis * angle), Vec3::Zero());
  const double t0 = 5.0, duration = 8.0;
  const CalibrationRun planted = runCalibration(T_err, shift, t0, duration);
  printRun("planted 0.4 deg, 3 ms", planted);
  const CalibrationRun none = runCalibration(Pose3::Identity(), 0.0, t0, duration);
  printRun("nothing planted", none);

  // the rig's error (the rig ⊟ the truth): the planted one, none when nothing is planted; the
  // first image only maps, so its error is the rig's
  const Vec7 rig_error = (Vec7() << -axis * angle, Vec3::Zero(), -shift).finished();
  EXPECT_LT((planted.error.front() - rig_error).norm(), 1e-12);
  EXPECT_LT(none.error.front().norm(), 1e-12);
  const Vec7& e = planted.error.back();
  const Vec7 sd = planted.covariance.back().diagonal().cwiseSqrt();
  for (const int k : {0, 1, 2, 6})
    EXPECT_LT(std::abs(e[k]), 3.0 * sd[k]) << "planted: component " << k << " error " << e[k] << " sigma " << sd[k];
  // with nothing planted: within 3 sigma of the rig (the truth) after every image
  for (size_t i = 0; i < none.t.size(); ++i) {
    const Vec7 sd0 = none.covariance[i].diagonal().cwiseSqrt();
    for (const int k : {0, 1, 2, 6})
      EXPECT_LT(std::abs(none.error[i][k]), 3.0 * sd0[k]) << "nothing planted: t " << none.t[i] << " component " << k
                                                          << " error " << none.error[i][k] << " sigma " << sd0[k];
  }
  EXPECT_LT(e.segment<3>(0).norm(), rig_error.segment<3>(0).norm() / 3.0)
      << "rotation error " << e.segment<3>(0).norm() * 180.0 / M_PI << " deg";
  EXPECT_LT(std::abs(e[6]), std::abs(rig_error[6]) / 3.0) << "time shift error " << e[6] * 1e3 << " ms";
  // the translation, held (zero variance), is the rig's throughout
  EXPECT_EQ(planted.final_translation_change, Vec3::Zero());
  EXPECT_EQ(none.final_translation_change, Vec3::Zero());
  for (const Mat7& P : {planted.covariance.back(), none.covariance.back()}) {
    EXPECT_TRUE(P.middleRows<3>(FilterState::kCalPos).isZero(0.0));
    EXPECT_TRUE(P.middleCols<3>(FilterState::kCalPos).isZero(0.0));
  }
}
