// Motion undistortion of a synthetic sweep with known motion: each point, moved to the body frame
// at the sweep end, must match the true hit point seen from the true end pose.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "livo/lio/imu_propagator.hpp"
#include "livo/lio/undistorter.hpp"
#include "synthetic_world.hpp"

using namespace livo;
using namespace livo::lio;

TEST(Undistorter, SmallAngleExpIsExact) {
  for (const Vec3& w : {Vec3(1e-9, 0, 0), Vec3(0.01, -0.02, 0.03), Vec3(0.03, 0.03, -0.02), Vec3(0.2, 0.1, 0.0)})
    for (const Vec3& v : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)})  // the columns of Exp(w)
      EXPECT_LT((expSmallTimes(w, v) - so3::Exp(w) * v).cwiseAbs().maxCoeff(), 1e-15) << w.transpose();
}

TEST(Undistorter, SweepWithKnownMotion) {
  const auto traj = synth::roomTrajectory(0.0);
  const auto scene = synth::roomScene();
  const int64_t base = 5'000'000;
  Pose3 T_I_L = se3::fromRotationTranslation(so3::Exp(Vec3(0.01, -0.02, 0.5)), Vec3(0.1, -0.05, 0.2));
  const double time_offset = 0.0125;  // t_imu = t_lidar + 12.5 ms
  const double t_start = 3.0;         // walking at ~1.3 m/s, turning at ~0.6 rad/s
  std::mt19937 rng(1);
  // sweep stamped in the LiDAR clock; the trajectory (IMU clock) time is t_lidar + offset
  LidarScan scan = synth::simulateSweep(scene, traj, synth::LidarModel::vlp16(),
                                        base + static_cast<int64_t>((t_start + time_offset) * 1e6), base, T_I_L, &rng);
  scan.utime -= static_cast<int64_t>(time_offset * 1e6);
  ASSERT_GT(scan.points.size(), 20000u);

  const double t0 = t_start + time_offset, t1 = t0 + 0.1;
  const auto imu = synth::simulateImu(traj, t0 - 0.01, t1 + 0.01, 200.0, base, synth::ImuErrorModel::exact(), &rng);
  ImuPropagator prop;
  size_t i = 0;
  while (imu[i + 1].utime <= base + static_cast<int64_t>(t0 * 1e6)) ++i;
  prop.reset(traj.state(imu[i].utime * 1e-6 - base * 1e-6), StateCovariance::Identity() * 1e-9, imu[i]);
  const int64_t t_end = base + static_cast<int64_t>(std::llround(t1 * 1e6));
  for (++i; imu[i].utime <= t_end; ++i) prop.addSample(imu[i]);
  prop.propagateTo(t_end, imu[i]);

  const Undistorter und(prop.segments(), prop.state().rot, prop.state().pos, t_end, T_I_L);
  std::vector<size_t> all(scan.points.size());
  for (size_t k = 0; k < all.size(); ++k) all[k] = k;
  std::vector<Vec3> body;
  und.undistort(scan, scan.utime + static_cast<int64_t>(time_offset * 1e6), 0.0, all, &body);

  const Pose3 T_end_inv = traj.pose(t1).inverse();
  double max_err = 0.0, max_raw = 0.0;
  for (size_t k = 0; k < scan.points.size(); ++k) {
    const double t = t0 + scan.time_offset[k];
    const Vec3 hit_world = traj.pose(t) * (T_I_L * scan.points[k]);
    const Vec3 truth = T_end_inv * hit_world;
    max_err = std::max(max_err, (body[k] - truth).norm());
    max_raw = std::max(max_raw, (T_I_L * scan.points[k] - truth).norm());
  }
  // Without undistortion points are off by up to decimetres; with it, by the integration error.
  EXPECT_GT(max_raw, 0.1);
  EXPECT_LT(max_err, 1e-3);

  // A LiDAR clock 4 ms behind (the sweep stamped 4 ms before it was taken) with that time shift
  // given moves every point as the true stamps do: each point along the motion from its own instant.
  std::vector<Vec3> body_shifted;
  und.undistort(scan, scan.utime + static_cast<int64_t>(time_offset * 1e6) - 4000, 0.004, all, &body_shifted);
  for (size_t k = 0; k < all.size(); ++k) ASSERT_LT((body_shifted[k] - body[k]).norm(), 1e-9) << k;

  // A whole sweep (which reuses the previous point's IMU segment) moves each point as a single
  // point is moved, in any point order.
  std::vector<size_t> shuffled = all;
  std::shuffle(shuffled.begin(), shuffled.end(), rng);
  std::vector<Vec3> body_shuffled;
  und.undistort(scan, scan.utime + static_cast<int64_t>(time_offset * 1e6), 0.0, shuffled, &body_shuffled);
  for (size_t k = 0; k < shuffled.size(); k += 7) {
    const size_t j = shuffled[k];
    const Vec3 single =
        und.toEnd(scan.points[j], scan.utime + static_cast<int64_t>(time_offset * 1e6), scan.time_offset[j]);
    ASSERT_EQ(body_shuffled[k], single) << k;
    ASSERT_EQ(body[j], single) << j;
  }
}
