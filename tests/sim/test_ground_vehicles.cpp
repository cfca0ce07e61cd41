// The ground-vehicle configs of the second paper's sequences (bridge_deck: M2DGR-PLUS Bridge1-like,
// tree_campus: Tree-like): they load, every sensor logs at its configured rate, the wheels slip, and
// the bridge deck is what it claims to be: a sweep's point-to-plane information leaves the position
// along the road nearly unconstrained, unlike the tree-lined campus road.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <unordered_map>

#include <Eigen/Eigenvalues>

#include "livo/sim/calibration_errors.hpp"
#include "livo/sim/lidar_scanner.hpp"
#include "livo/sim/simulation_setup.hpp"
#include "livo/sim/simulator.hpp"
#include "sim_test_support.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

std::string configPath(const std::string& name) {
  return std::string(LIVO_SOURCE_DIR) + "/config/sim/" + name + ".yaml";
}

/// Stamps of k = 0, 1, ... at `rate_hz` from `start` (+ phase periods) that are within `duration`.
void expectStampsAtRate(const std::vector<int64_t>& stamps, int64_t start, double rate_hz, double duration,
                        double phase, const std::string& what) {
  SCOPED_TRACE(what);
  const size_t n = static_cast<size_t>(std::floor(duration * rate_hz - phase + 1e-9)) + 1;
  ASSERT_EQ(stamps.size(), n);
  for (size_t k = 0; k < n; ++k)
    EXPECT_EQ(stamps[k], start + std::llround((static_cast<double>(k) + phase) * 1e6 / rate_hz)) << k;
}

template <class Msg>
std::vector<int64_t> stampsOf(const std::vector<Msg>& messages) {
  std::vector<int64_t> out;
  for (const Msg& m : messages) out.push_back(m.utime);
  return out;
}

}  // namespace

TEST(GroundVehicleConfigs, BridgeDeckAndTreeCampusLogEverySensorAtItsConfiguredRate) {
  for (const std::string name : {"bridge_deck", "tree_campus"}) {
    SCOPED_TRACE(name);
    SimOverrides o;
    o.duration_s = 2.0;
    const SimulationSetup setup = loadSimulation(configPath(name), o);
    const SensorRig& rig = setup.rig;
    ASSERT_TRUE(rig.lidar && rig.camera && rig.wheel);
    EXPECT_EQ(rig.lidar->model, "VLP-16");
    EXPECT_EQ(rig.lidar->rate_hz, 10.0);
    EXPECT_EQ(rig.imu.rate_hz, 200.0);
    EXPECT_EQ(rig.camera->rate_hz, 20.0);
    EXPECT_EQ(rig.wheel->rate_hz, 50.0);
    EXPECT_TRUE(setup.options.wheel_slip.enabled());
    EXPECT_TRUE(setup.calibration_errors.any());  // the truth differs from the rig
    test::CollectingSink sink;
    Simulator(setup).run(sink);
    const int64_t t0 = setup.start_utime;
    expectStampsAtRate(stampsOf(sink.imu), t0, rig.imu.rate_hz, 2.0, 0.0, "IMU");
    expectStampsAtRate(stampsOf(sink.wheel), t0, rig.wheel->rate_hz, 2.0, 0.0, "WHEEL");
    expectStampsAtRate(stampsOf(sink.poses), t0, setup.options.ground_truth_rate_hz, 2.0, 0.0, "GROUND_TRUTH");
    expectStampsAtRate(stampsOf(sink.images), t0, rig.camera->rate_hz, 2.0, 0.5,
                       "CAMERA");        // mid-exposure, halfway between ticks
    ASSERT_EQ(sink.sweeps.size(), 20u);  // only complete sweeps: 2 s at 10 Hz
    for (size_t k = 0; k < sink.sweeps.size(); ++k) {
      EXPECT_EQ(sink.sweeps[k].utime, t0 + static_cast<int64_t>(k) * 100'000);
      EXPECT_EQ(sink.sweeps[k].num_rings, 16);
      EXPECT_GT(sink.sweeps[k].size(), 8000u) << k;  // of 28,928 beams, the lower half or more return
    }
    for (const CameraImage& image : sink.images) {
      EXPECT_EQ(image.width, 640);
      EXPECT_EQ(image.height, 480);
      EXPECT_FALSE(image.color);
      ASSERT_EQ(image.data.size(), 640u * 480u);
    }
    // the order of the whole log is by stamp
    for (size_t i = 1; i < sink.order.size(); ++i) ASSERT_LE(sink.order[i - 1], sink.order[i]) << i;
    // the vehicle stands still for 2 s: the wheels read noise around 0
    for (const WheelReading& w : sink.wheel) EXPECT_LT(std::abs(w.left_speed) + std::abs(w.right_speed), 0.3);
  }
}

namespace {

struct Degeneracy {
  Eigen::Matrix3d H_tt = Eigen::Matrix3d::Zero();  // sum of n n^T over the planar points
  Vec3 eigenvalues = Vec3::Zero();                 // of H_tt, ascending
  Vec3 weakest = Vec3::Zero();                     // eigenvector of the smallest
  int points = 0, planar = 0;
  Vec3 road = Vec3::Zero();  // the direction of travel
};

/// One sweep of `config` starting at trajectory time t (the TRUE LiDAR mounting, the configured
/// receiver effects), in the world frame. Each sample point of a 0.3 m voxel grid gets a normal by
/// a plane fit to the points within 1 m (accepted when the patch is flat: its smallest spread below
/// 5 cm and below 5 % of the next, the next above 10 cm, at least 10 points); the translational
/// part of the point-to-plane information is the sum of n n^T over them.
Degeneracy sweepDegeneracy(const std::string& config, double t) {
  const SimulationSetup setup = loadSimulation(configPath(config));
  const SensorRig truth = trueRig(setup.rig, setup.calibration_errors);
  const LidarScanner scanner(*truth.lidar, setup.options.lidar, setup.options.lidar_effects);
  const LidarSweep sweep = scanner.scan(*setup.scene, *setup.trajectory, t, 0, t, Random(1, 3, 77));
  std::vector<Vec3> world(sweep.size());
  for (size_t i = 0; i < sweep.size(); ++i) {
    const Pose3 T_W_L = setup.trajectory->at(t + sweep.time_offset[i]).T_W_I * truth.lidar->T_I_L;
    world[i] = T_W_L * Vec3(sweep.x[i], sweep.y[i], sweep.z[i]);
  }
  const double radius = 1.0, sample = 0.3;
  auto key = [](const Vec3& p, double cell) {
    const int64_t x = static_cast<int64_t>(std::floor(p.x() / cell)),
                  y = static_cast<int64_t>(std::floor(p.y() / cell)),
                  z = static_cast<int64_t>(std::floor(p.z() / cell));
    return ((x & 0x1fffff) << 42) | ((y & 0x1fffff) << 21) | (z & 0x1fffff);
  };
  std::unordered_map<int64_t, std::vector<int>> grid;  // cells of `radius`
  std::unordered_map<int64_t, int> samples;            // first point per voxel of `sample`
  for (size_t i = 0; i < world.size(); ++i) {
    grid[key(world[i], radius)].push_back(static_cast<int>(i));
    samples.emplace(key(world[i], sample), static_cast<int>(i));
  }
  Degeneracy d;
  d.points = static_cast<int>(world.size());
  const BodyState s = setup.trajectory->at(t);
  d.road = s.velocity.normalized();
  for (const auto& [k, index] : samples) {
    const Vec3& p = world[index];
    std::vector<Vec3> near;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find(key(p + radius * Vec3(dx, dy, dz), radius));
          if (it == grid.end()) continue;
          for (int j : it->second)
            if ((world[j] - p).norm() < radius) near.push_back(world[j]);
        }
    if (near.size() < 10) continue;
    Vec3 mean = Vec3::Zero();
    for (const Vec3& q : near) mean += q;
    mean /= static_cast<double>(near.size());
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    for (const Vec3& q : near) C += (q - mean) * (q - mean).transpose();
    C /= static_cast<double>(near.size());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(C);
    const Vec3 l = es.eigenvalues();
    if (!(l[0] < 0.05 * 0.05 && l[0] < 0.05 * l[1] && l[1] > 0.1 * 0.1)) continue;
    const Vec3 n = es.eigenvectors().col(0);
    d.H_tt += n * n.transpose();
    ++d.planar;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(d.H_tt);
  d.eigenvalues = es.eigenvalues();
  d.weakest = es.eigenvectors().col(0);
  return d;
}

void print(const std::string& what, const Degeneracy& d) {
  std::cout << what << ": " << d.points << " points, " << d.planar << " planar samples; information eigenvalues "
            << d.eigenvalues.transpose() << " (smallest / middle " << d.eigenvalues[0] / d.eigenvalues[1]
            << "), weakest direction " << d.weakest.transpose() << ", |cos| to the road "
            << std::abs(d.weakest.dot(d.road)) << "\n";
}

}  // namespace

TEST(GroundVehicleConfigs, BridgeDeckLidarGeometryIsDegenerateAlongTheRoadUnlikeTheTreeCampus) {
  // 40 s in, the vehicle is 150 m along the deck: the west end is out of range
  if (const char* explore = std::getenv("LIVO_SIM_DEGENERACY_TIMES")) {  // report more sweeps
    for (const std::string config : {"bridge_deck", "tree_campus"})
      for (std::istringstream times(explore); !times.eof();) {
        double t = 0.0;
        times >> t;
        print(config + " at " + std::to_string(t) + " s", sweepDegeneracy(config, t));
      }
  }
  const Degeneracy bridge = sweepDegeneracy("bridge_deck", 40.0);
  print("bridge_deck at 40 s", bridge);
  ASSERT_GT(bridge.planar, 300);
  EXPECT_GT(std::abs(bridge.weakest.dot(bridge.road)), 0.99);      // along the road
  EXPECT_GT(std::abs(bridge.road.x()), 0.999);                     // which is x
  EXPECT_LT(bridge.eigenvalues[0], 0.01 * bridge.eigenvalues[1]);  // and almost unconstrained
  // on the tree-lined road the curbs, trunks, poles and facades in the gaps hold the position along
  // it: its weakest direction is also along the road, but more than 10 times better constrained per
  // planar sample, and more than 5 times as much relative to the next direction
  const Degeneracy trees = sweepDegeneracy("tree_campus", 20.0);
  print("tree_campus at 20 s", trees);
  ASSERT_GT(trees.planar, 300);
  EXPECT_GT(trees.eigenvalues[0] / trees.planar, 10.0 * bridge.eigenvalues[0] / bridge.planar);
  EXPECT_GT(trees.eigenvalues[0] / trees.eigenvalues[1], 5.0 * bridge.eigenvalues[0] / bridge.eigenvalues[1]);
}
