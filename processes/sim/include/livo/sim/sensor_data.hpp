// What the simulated sensors produce, as plain structs (no middleware), and the sink the
// simulator hands them to in time order.
#pragma once

#include <cstdint>
#include <vector>

#include "livo/so3.hpp"

namespace livo::sim {

struct ImuReading {
  int64_t utime = 0;
  Vec3 angular_velocity = Vec3::Zero();     // rad/s, frame I
  Vec3 linear_acceleration = Vec3::Zero();  // specific force, m/s^2, frame I
};

struct PoseReading {
  int64_t utime = 0;
  Pose3 T_W_I = Pose3::Identity();
};

struct WheelReading {
  int64_t utime = 0;
  double left_speed = 0.0, right_speed = 0.0;  // m/s
};

/// One LiDAR sweep in the sensor frame L at each point's own firing time.
struct LidarSweep {
  int64_t utime = 0;      // sweep start
  double duration = 0.1;  // s
  bool solid_state = false;
  int num_rings = 0;
  std::vector<float> x, y, z, intensity, time_offset;
  std::vector<int16_t> ring;
  size_t size() const { return x.size(); }
};

struct CameraImage {
  int64_t utime = 0;      // mid-exposure, on the camera's clock
  int64_t log_utime = 0;  // the same instant on the IMU clock: the log event's time
  int width = 0, height = 0;
  bool color = false;          // RGB8 if true, GRAY8 otherwise
  float exposure_time = 0.0f;  // s
  std::vector<uint8_t> data;
};

/// The depth image registered to a CameraImage (rig.camera.depth): the same size and stamps.
struct DepthImage {
  int64_t utime = 0;  // the colour image's
  int64_t log_utime = 0;
  int width = 0, height = 0;
  std::vector<uint16_t> millimetres;  // z along the optical axis per pixel, row-major; 0: no depth
};

class SensorDataSink {
 public:
  virtual ~SensorDataSink() = default;
  virtual void write(const ImuReading& m) = 0;
  virtual void write(const PoseReading& m) = 0;
  virtual void write(const WheelReading& m) = 0;
  virtual void write(const LidarSweep& m) = 0;
  virtual void write(const CameraImage& m) = 0;
  /// Only with rig.camera.depth; a sink that has no use for depth need not take it.
  virtual void write(const DepthImage&) {}
};

}  // namespace livo::sim
