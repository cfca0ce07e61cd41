// Runs a simulation: steps through sim time in chunks, computes every sensor's messages for the
// chunk (heavy ones, LiDAR sweeps and camera images, on worker threads; each message from its own
// random stream, so the output does not depend on the thread count) and hands them to a sink in
// time order, ties in the fixed order IMU, WHEEL, GROUND_TRUTH, LIDAR, CAMERA.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "livo/sim/sensor_data.hpp"
#include "livo/sim/simulation_setup.hpp"

namespace livo::sim {

struct SimulationStats {
  std::map<std::string, int64_t> messages;  // per channel
  int64_t lidar_points = 0;
  int64_t wheel_slip_episodes = 0;  // sim.wheel.slip episodes begun among the wheel samples so far
  double sim_seconds = 0.0;
  double wall_seconds = 0.0;
};

class Simulator {
 public:
  explicit Simulator(const SimulationSetup& setup);

  /// progress(done_s, total_s) is called after each chunk of sim time.
  using Progress = std::function<void(double done_s, double total_s, const SimulationStats& so_far)>;
  SimulationStats run(SensorDataSink& sink, const Progress& progress = {});

 private:
  const SimulationSetup& setup_;
};

}  // namespace livo::sim
