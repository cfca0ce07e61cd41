// The whole estimator on ray-cast sequences with exact ground truth (tests/lio's synthetic world):
// the room walk with realistic IMU noise and biases, tracked to centimetres; outputs finite and
// deterministic; the window bounded.
#include <gtest/gtest.h>

#include <iostream>

#include "livo/lio_graph/lio_graph_estimator.hpp"
#include "synthetic_world.hpp"

using namespace livo;
using namespace livo::lio_graph;
namespace synth = livo::lio::synth;

namespace {

struct RunLog {
  std::vector<Vec3> est, gt;
  std::vector<Pose3> poses;
  int tracked = 0, outputs = 0, degenerate = 0;
  size_t max_window = 0;
  int planes = 0;
  size_t max_landmarks = 0;
};

LioGraphOptions optionsFor(const synth::SequenceSpec& spec, bool planar = true) {
  LioGraphOptions o;
  o.planar_factors = planar;
  o.extrinsics.T_I_L = spec.T_I_L;
  o.imu_noise = ImuPreintegrationNoise{};  // the rig's defaults: what realisticImu() draws
  return o;
}

RunLog run(const synth::SequenceSpec& spec, bool planar = true) {
  const synth::SyntheticSequence seq(spec);
  LioGraphEstimator est(optionsFor(spec, planar));
  RunLog r;
  size_t next_imu = 0;
  for (int k = 0; k < seq.numScans(); ++k) {
    const int64_t t_end = seq.scanEndUtime(k);
    while (next_imu < seq.imu().size() && seq.imu()[next_imu].utime <= t_end + 10000) est.addImu(seq.imu()[next_imu++]);
    const GraphScanResult res = est.addScan(seq.scan(k));
    r.max_window = std::max(r.max_window, est.windowSize());
    if (!res.hasOutput()) continue;
    EXPECT_TRUE(res.pose.matrix().allFinite()) << k;
    EXPECT_TRUE(res.pose_covariance.allFinite()) << k;
    ++r.outputs;
    r.tracked += res.status == GraphScanResult::Status::kTracked;
    r.planes += res.planes;
    r.max_landmarks = std::max(r.max_landmarks, est.planeLandmarks());
    r.degenerate += res.degenerate;
    r.est.push_back(res.pose.translation());
    r.poses.push_back(res.pose);
    r.gt.push_back(seq.truth(res.utime).translation());
  }
  return r;
}

}  // namespace

TEST(LioGraphEstimator, TracksTheRoomWalkWithARealisticImu) {
  synth::SequenceSpec spec;
  spec.duration = 12.0;
  spec.imu_error = synth::realisticImu();
  spec.lidar.range_noise_std = 0.01;
  const RunLog r = run(spec);
  ASSERT_GT(r.outputs, 100);
  EXPECT_GT(r.tracked, r.outputs - 3);
  const double ate = synth::alignedRmse(r.est, r.gt);
  EXPECT_LT(ate, 0.05) << "ATE " << ate;
  EXPECT_LE(r.max_window, static_cast<size_t>(LioGraphOptions{}.window_states));
  // the room's floor and walls are seen as planes in every sweep; their landmarks stay bounded
  EXPECT_GT(r.planes, 2 * r.outputs);
  EXPECT_LT(r.max_landmarks, 60u);
  // without the planar factors (the same sweeps, LiDAR odometry and IMU only)
  const RunLog flat = run(spec, false);
  const double ate_flat = synth::alignedRmse(flat.est, flat.gt);
  std::cout << "room walk ATE: planar factors " << ate << " m, without " << ate_flat << " m; " << r.planes
            << " plane observations in " << r.outputs << " sweeps, at most " << r.max_landmarks << " landmarks\n";
  EXPECT_LT(ate_flat, 0.05);
}

TEST(LioGraphEstimator, SameInputsSameOutputs) {
  synth::SequenceSpec spec;
  spec.duration = 4.0;
  spec.imu_error = synth::realisticImu();
  const RunLog a = run(spec), b = run(spec);
  ASSERT_EQ(a.poses.size(), b.poses.size());
  for (size_t i = 0; i < a.poses.size(); ++i) EXPECT_TRUE(a.poses[i].matrix() == b.poses[i].matrix()) << i;
}
