// Ray-casts LiDAR sweeps: every beam from the sensor pose at its own firing time (so a moving
// sensor produces real motion distortion), with range noise, dropouts, range limits, and an
// intensity from the surface reflectivity and the incidence angle.
#pragma once

#include "lidar_pattern.hpp"
#include "livo/sensor_rig.hpp"
#include "random.hpp"
#include "scene.hpp"
#include "sensor_data.hpp"
#include "trajectory.hpp"

namespace livo {
namespace sim {

class LidarScanner {
 public:
  LidarScanner(const LidarRig& rig, const LidarPatternOptions& pattern_options);

  /// The sweep that starts at trajectory time `t0` (stamped `utime`); `sensor_time0` is the time
  /// since the sensor started (rosette phase). Noise comes from `rng` only.
  LidarSweep scan(const Scene& scene, const BodyTrajectory& trajectory, double t0, int64_t utime, double sensor_time0,
                  Random rng) const;

  const LidarPattern& pattern() const { return pattern_; }
  const LidarRig& rig() const { return rig_; }

 private:
  LidarRig rig_;
  LidarPattern pattern_;
};

}  // namespace sim
}  // namespace livo
