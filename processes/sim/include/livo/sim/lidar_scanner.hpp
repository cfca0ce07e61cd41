// Ray-casts LiDAR sweeps: every beam from the sensor pose at its own firing time (so a moving
// sensor produces real motion distortion), with range noise, dropouts, range limits, and an
// intensity from the surface reflectivity and the incidence angle; optionally the receiver
// effects of lidar_effects.hpp (range- and reflectivity-dependent noise and detection, beam
// footprint with mixed pixels).
#pragma once

#include "livo/sensor_rig.hpp"
#include "livo/sim/lidar_effects.hpp"
#include "livo/sim/lidar_pattern.hpp"
#include "livo/sim/random.hpp"
#include "livo/sim/scene.hpp"
#include "livo/sim/sensor_data.hpp"
#include "livo/sim/trajectory.hpp"

namespace livo::sim {

class LidarScanner {
 public:
  LidarScanner(const LidarRig& rig, const LidarPatternOptions& pattern_options, const LidarEffects& effects = {});

  /// The sweep that starts at trajectory time `t0` (stamped `utime`); `sensor_time0` is the time
  /// since the sensor started (rosette phase). Noise comes from `rng` only.
  LidarSweep scan(const Scene& scene, const BodyTrajectory& trajectory, double t0, int64_t utime, double sensor_time0,
                  Random rng) const;

  const LidarPattern& pattern() const { return pattern_; }
  const LidarRig& rig() const { return rig_; }
  const LidarEffects& effects() const { return effects_; }

 private:
  /// The return of a single ray along the beam axis.
  Echo axisEcho(const Scene& scene, const Ray& ray, const CastContext& context) const;
  /// The strongest return of the beam footprint around `ray`; `up` is the sensor's z axis (the
  /// footprint's vertical); `hits` is scratch space.
  Echo footprintEcho(const Scene& scene, const Ray& ray, const Vec3& up, const CastContext& context,
                     std::vector<SubRayHit>* hits) const;

  LidarRig rig_;
  LidarPattern pattern_;
  LidarEffects effects_;
  std::vector<SubRay> sub_rays_;  // empty without a footprint
};

}  // namespace livo::sim
