// A short simulated run held in memory for the benchmarks (bench_octomap, bench_colour): every
// sweep moved to the world with the true LiDAR pose at each point's firing time (an exact
// stand-in LIO, as in map-bars), the images and the ground-truth poses, in time order.
#pragma once

#include <cmath>
#include <string>
#include <vector>

#include "livo/sim/simulation_setup.hpp"
#include "livo/sim/simulator.hpp"

namespace livo_bench {

struct WorldSweep {
  int64_t cloud_utime = 0, utime = 0;           // start, end
  livo::Pose3 T_W_I = livo::Pose3::Identity();  // at the end
  std::vector<float> x, y, z, time_offset;
};

struct SimRecording {
  // events in time order: 0 pose, 1 sweep, 2 image (index into the matching vector)
  std::vector<std::pair<int, size_t>> events;
  std::vector<livo::sim::PoseReading> poses;
  std::vector<WorldSweep> sweeps;
  std::vector<livo::sim::CameraImage> images;
};

class RecordingSink : public livo::sim::SensorDataSink {
 public:
  RecordingSink(const livo::sim::SimulationSetup& setup, SimRecording* out) : setup_(setup), out_(out) {}
  void write(const livo::sim::ImuReading&) override {}
  void write(const livo::sim::WheelReading&) override {}
  void write(const livo::sim::PoseReading& m) override {
    out_->events.emplace_back(0, out_->poses.size());
    out_->poses.push_back(m);
  }
  void write(const livo::sim::LidarSweep& s) override {
    WorldSweep w;
    w.cloud_utime = s.utime;
    w.utime = s.utime + static_cast<int64_t>(std::llround(s.duration * 1e6));
    w.T_W_I = setup_.trajectory->at(setup_.trajectoryTime(w.utime)).T_W_I;
    for (size_t j = 0; j < s.size(); ++j) {
      const double t = setup_.trajectoryTime(s.utime) + s.time_offset[j];
      const livo::Pose3 T_W_L = setup_.trajectory->at(t).T_W_I * setup_.rig.lidar->T_I_L;
      const Eigen::Vector3d p = T_W_L * Eigen::Vector3d(s.x[j], s.y[j], s.z[j]);
      w.x.push_back(float(p.x())), w.y.push_back(float(p.y())), w.z.push_back(float(p.z()));
      w.time_offset.push_back(s.time_offset[j]);
    }
    out_->events.emplace_back(1, out_->sweeps.size());
    out_->sweeps.push_back(std::move(w));
  }
  void write(const livo::sim::CameraImage& m) override {
    out_->events.emplace_back(2, out_->images.size());
    out_->images.push_back(m);
  }

 private:
  const livo::sim::SimulationSetup& setup_;
  SimRecording* out_;
};

/// config/sim/room.yaml cut to its first 9 s (handheld walk after 2 s still and a 2 s ramp).
inline const livo::sim::SimulationSetup& roomSetup() {
  static const livo::sim::SimulationSetup setup = [] {
    livo::sim::SimOverrides ov;
    ov.duration_s = 9.0;
    return livo::sim::loadSimulation(std::string(LIVO_SOURCE_DIR) + "/config/sim/room.yaml", ov);
  }();
  return setup;
}

/// The run's sweeps, images and poses.
inline const SimRecording& roomRecording() {
  static const SimRecording rec = [] {
    SimRecording r;
    const auto& setup = roomSetup();
    RecordingSink sink(setup, &r);
    livo::sim::Simulator(setup).run(sink);
    return r;
  }();
  return rec;
}

}  // namespace livo_bench
