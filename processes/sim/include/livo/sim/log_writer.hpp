// Writes simulated sensor data to an LCM log file (lcm::LogFile, no bus): each event stamped with
// its message's utime. The only part of the simulator that knows LCM.
#pragma once

#include <memory>
#include <string>

#include "livo/point_cloud_t.hpp"
#include "livo/sensor_rig.hpp"
#include "livo/sim/sensor_data.hpp"

namespace lcm {
class LogFile;
}

namespace livo::sim {

/// The point_cloud_t the log holds for a sweep (what livo-lio reads), in the LiDAR frame "L".
point_cloud_t toPointCloud(const LidarSweep& m);

class LogWriter : public SensorDataSink {
 public:
  /// Creates (truncates) `path`; throws std::runtime_error if it cannot.
  LogWriter(const std::string& path, const RigChannels& channels);
  ~LogWriter() override;

  void write(const ImuReading& m) override;
  void write(const PoseReading& m) override;
  void write(const WheelReading& m) override;
  void write(const LidarSweep& m) override;
  void write(const CameraImage& m) override;
  void write(const DepthImage& m) override;

  int64_t bytesWritten() const { return bytes_; }

 private:
  template <class Msg>
  void writeEvent(const std::string& channel, int64_t utime, const Msg& msg);

  std::unique_ptr<lcm::LogFile> log_;
  RigChannels channels_;
  std::string path_;
  int64_t bytes_ = 0;
  std::vector<uint8_t> buffer_;
};

}  // namespace livo::sim
