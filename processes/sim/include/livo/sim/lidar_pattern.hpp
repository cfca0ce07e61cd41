// LiDAR firing schedules. A sweep is `columns` firings; at each firing every beam fires once,
// beam b `firing_offset[b]` seconds after the column time. A spinning head (beam table of VLP-16,
// OS1-16, OS1-64, HDL-64E) turns clockwise seen from above, so a beam's azimuth is set by its own
// firing time; a Livox-style head traces a non-repetitive rosette (two counter-rotating prisms)
// whose phase runs on across sweeps.
#pragma once

#include <string>
#include <vector>

#include "livo/so3.hpp"

namespace livo::sim {

struct LidarPatternOptions {
  int columns = 0;                   // firings per sweep; 0: the model's own
  double start_azimuth_deg = 180.0;  // spinning: azimuth (from +x, counter-clockwise) at the sweep start
};

class LidarPattern {
 public:
  /// The models with a firing schedule here (a subset of livo::kLidarModels, which also names
  /// real sensors the simulator cannot simulate).
  static const std::vector<std::string>& models();

  /// One of models() at `rate_hz`; throws std::invalid_argument for any other model.
  LidarPattern(const std::string& model, double rate_hz, const LidarPatternOptions& options = {});

  bool solidState() const { return solid_state_; }
  int columns() const { return columns_; }
  int beams() const { return static_cast<int>(beams_.size()); }
  double sweepDuration() const { return sweep_duration_; }
  double columnPeriod() const { return sweep_duration_ / columns_; }

  /// Seconds after the sweep start at which beam b of column c fires.
  double firingTime(int column, int beam) const { return column * columnPeriod() + beams_[beam].firing_offset; }
  /// Ring reported for beam b (0 = lowest beam for spinning heads).
  int ring(int beam) const { return beams_[beam].ring; }
  /// Unit beam direction in the sensor frame L (x forward, z up) when beam b fires at
  /// `sweep_time` seconds after its sweep start; `sensor_time` is seconds since the sensor
  /// started (the rosette phase).
  Vec3 direction(int beam, double sweep_time, double sensor_time) const;

  /// Nominal elevation of beam b (spinning), radians.
  double elevation(int beam) const { return beams_[beam].elevation; }
  double azimuthOffset(int beam) const { return beams_[beam].azimuth_offset; }
  double startAzimuth() const { return start_azimuth_; }

 private:
  struct Beam {
    double elevation = 0.0;       // rad (spinning) / vertical offset (solid state)
    double azimuth_offset = 0.0;  // rad
    double firing_offset = 0.0;   // s after the column time
    int ring = 0;
  };
  std::vector<Beam> beams_;
  bool solid_state_ = false;
  int columns_ = 0;
  double sweep_duration_ = 0.1;
  double start_azimuth_ = M_PI;
};

}  // namespace livo::sim
