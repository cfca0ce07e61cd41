#include "livo/sim/log_writer.hpp"

#include <cstring>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

#include "livo/image_t.hpp"
#include "livo/imu_t.hpp"
#include "livo/messages.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/pose_t.hpp"
#include "livo/wheel_odometry_t.hpp"

namespace livo::sim {

point_cloud_t toPointCloud(const LidarSweep& m) {
  point_cloud_t msg;
  msg.utime = m.utime;
  msg.frame = "L";
  msg.pattern = m.solid_state ? point_cloud_t::PATTERN_SOLID_STATE : point_cloud_t::PATTERN_SPINNING;
  msg.num_rings = static_cast<int16_t>(m.num_rings);
  msg.sweep_duration = static_cast<float>(m.duration);
  msg.num_points = static_cast<int32_t>(m.size());
  msg.x = m.x;
  msg.y = m.y;
  msg.z = m.z;
  msg.intensity = m.intensity;
  msg.time_offset = m.time_offset;
  msg.ring = m.ring;
  return msg;
}

LogWriter::LogWriter(const std::string& path, const RigChannels& channels) : channels_(channels), path_(path) {
  log_ = std::make_unique<lcm::LogFile>(path, "w");
  if (!log_->good()) throw std::runtime_error(path + ": cannot create the log file");
}

LogWriter::~LogWriter() = default;

template <class Msg>
void LogWriter::writeEvent(const std::string& channel, int64_t utime, const Msg& msg) {
  const int size = msg.getEncodedSize();
  buffer_.resize(static_cast<size_t>(size));
  if (msg.encode(buffer_.data(), 0, size) != size) throw std::runtime_error("cannot encode a message for " + channel);
  lcm::LogEvent ev;
  ev.eventnum = 0;  // assigned by LogFile
  ev.timestamp = utime;
  ev.channel = channel;
  ev.datalen = size;
  ev.data = buffer_.data();
  if (log_->writeEvent(&ev) != 0) throw std::runtime_error(path_ + ": write failed (disk full?)");
  bytes_ += size;
}

void LogWriter::write(const ImuReading& m) {
  imu_t msg;
  msg.utime = m.utime;
  vec3To(m.angular_velocity, msg.angular_velocity);
  vec3To(m.linear_acceleration, msg.linear_acceleration);
  writeEvent(channels_.imu, m.utime, msg);
}

void LogWriter::write(const PoseReading& m) {
  pose_t msg;
  msg.utime = m.utime;
  msg.parent_frame = "W";
  msg.child_frame = "I";
  poseTo(m.T_W_I, msg.position, msg.orientation);
  writeEvent(channels_.ground_truth, m.utime, msg);
}

void LogWriter::write(const WheelReading& m) {
  wheel_odometry_t msg;
  msg.utime = m.utime;
  msg.left_speed = m.left_speed;
  msg.right_speed = m.right_speed;
  writeEvent(channels_.wheel, m.utime, msg);
}

void LogWriter::write(const LidarSweep& m) { writeEvent(channels_.lidar, m.utime, toPointCloud(m)); }

void LogWriter::write(const CameraImage& m) {
  image_t msg;
  msg.utime = m.utime;
  msg.frame = "C";
  msg.width = m.width;
  msg.height = m.height;
  msg.row_stride = m.width * (m.color ? 3 : 1);
  msg.encoding = m.color ? image_t::ENCODING_RGB8 : image_t::ENCODING_GRAY8;
  msg.exposure_time = m.exposure_time;
  msg.size = static_cast<int32_t>(m.data.size());
  msg.data = m.data;
  writeEvent(channels_.camera, m.log_utime, msg);
}

void LogWriter::write(const DepthImage& m) {
  image_t msg;
  msg.utime = m.utime;
  msg.frame = "C";
  msg.width = m.width;
  msg.height = m.height;
  msg.row_stride = m.width * 2;
  msg.encoding = image_t::ENCODING_DEPTH16;
  msg.exposure_time = 0.0f;
  msg.size = static_cast<int32_t>(m.millimetres.size() * 2);
  msg.data.resize(m.millimetres.size() * 2);
  std::memcpy(msg.data.data(), m.millimetres.data(), msg.data.size());  // little-endian, as image_t says
  writeEvent(channels_.depth, m.log_utime, msg);
}

}  // namespace livo::sim
