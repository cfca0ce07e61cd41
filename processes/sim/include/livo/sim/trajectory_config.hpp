// Reads `sim.trajectory` (handheld | car | uav | recorded) into a BodyTrajectory.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "livo/asl_dataset.hpp"
#include "livo/config.hpp"
#include "livo/sim/terrain.hpp"
#include "livo/sim/trajectory.hpp"

namespace livo::sim {

struct TrajectoryConfig {
  std::unique_ptr<BodyTrajectory> trajectory;
  std::string description;
  bool recorded = false;
  double recorded_start_stamp = 0.0;       // s, first ground-truth stamp
  double recorded_start_offset_s = 0.0;    // recorded: the run starts this long after the default start
  std::vector<AslImuSample> recorded_imu;  // recorded: the real IMU samples (none: synthesised from the motion)
};

/// `gravity` is used by the thrust-aligned (uav) attitude; `base_dir` resolves relative paths;
/// `T_I_rear_axle` is where a car's rear axle is, the TRUE wheel base frame (identity: at the body
/// origin, for a rig without wheel encoder). A car drives on `ground` when there is one (the scene's
/// terrain), its wheels `track_width` apart unless the trajectory says otherwise.
TrajectoryConfig readTrajectoryConfig(const Config& c, double gravity, const std::string& base_dir,
                                      const Pose3& T_I_rear_axle = Pose3::Identity(),
                                      std::shared_ptr<const Terrain> ground = nullptr, double track_width = 1.6);

}  // namespace livo::sim
