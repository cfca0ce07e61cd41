// What the messages of an import show of the sensors, measured while the log is written (a
// SortedLogWriter observer): each sensor's rate from its stamps (1 / the median interval, so a
// few gaps or duplicates do not move it), the IMU's specific force over its first second (at rest:
// the local gravity plus the accelerometer bias), the LiDAR's rings, scan pattern, sweep length
// and whether its points carry times, the camera's size and colour. Formats need nothing of
// their own for this: it is the log's content. A starter rig (starter_rig_config.hpp) and the rig
// check (rig_check.hpp) read it; the sidecar repeats it (addSurveyMetadata).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "livo/import/channel_names.hpp"
#include "livo/import/import_report.hpp"
#include "livo/import/sorted_log_writer.hpp"

namespace livo::import {

struct MeasuredRate {
  int64_t messages = 0;
  double hz = 0.0;  // 1 / the median interval of the sorted stamps; 0 with fewer than two
};

struct ImuSurvey {
  MeasuredRate rate;
  int64_t first_second_samples = 0;      // samples within 1 s of the first
  double first_second_accel_norm = 0.0;  // mean |linear_acceleration| over them, m/s^2
  double first_second_accel_std = 0.0;   // its standard deviation (small: the sensor was at rest)
};

struct LidarSurvey {
  MeasuredRate rate;
  int rings = 0;                  // the largest num_rings of a sweep (else the largest ring + 1)
  bool solid_state = false;       // any sweep marked PATTERN_SOLID_STATE
  double sweep_duration_s = 0.0;  // median sweep_duration
  bool point_times = false;       // some point has a time offset > 0
  int64_t median_points = 0;
};

struct CameraSurvey {
  MeasuredRate rate;
  int width = 0, height = 0;  // of the first image
  int other_sizes = 0;        // images of another size than the first
  std::string encoding;       // GRAY8, RGB8, BGR8, JPEG, PNG
  int channels = 0;           // 1 grey, 3 colour, 0 unknown (a compressed header cut short)
};

struct SensorSurvey {
  std::optional<ImuSurvey> imu;
  std::optional<LidarSurvey> lidar;
  std::optional<CameraSurvey> camera;
  int64_t depth_images = 0;
  int64_t ground_truth_poses = 0;
};

class RigSurvey : public MessageObserver {
 public:
  explicit RigSurvey(ChannelNames channels) : channels_(std::move(channels)) {}

  void observe(const std::string& channel, const imu_t& msg) override;
  void observe(const std::string& channel, const point_cloud_t& msg) override;
  void observe(const std::string& channel, const image_t& msg) override;
  void observe(const std::string& channel, const pose_t& msg) override;

  SensorSurvey result() const;

 private:
  ChannelNames channels_;
  std::vector<int64_t> imu_stamps_, lidar_stamps_, camera_stamps_;
  std::vector<std::pair<int64_t, float>> imu_accel_norms_;  // (utime, |a|)
  int lidar_rings_ = 0;
  bool lidar_solid_state_ = false, lidar_point_times_ = false;
  std::vector<float> sweep_durations_;
  std::vector<int32_t> sweep_points_;
  std::optional<CameraSurvey> camera_;
  int64_t depth_images_ = 0, ground_truth_poses_ = 0;
};

/// 1 / the median interval of `stamps` (microseconds, any order).
MeasuredRate measureRate(std::vector<int64_t> stamps);

/// The survey as sidecar metadata: measured_rate_hz {IMU: .., LIDAR: .., CAMERA: ..},
/// lidar_rings, lidar_sweep_duration, camera_resolution [w, h], camera_color, imu_first_second_accel_norm.
void addSurveyMetadata(const SensorSurvey& survey, const ChannelNames& channels, ImportReport& report);

}  // namespace livo::import
