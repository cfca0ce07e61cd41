// ROS messages read from their serialised form into plain structs, which the converters
// (rosbag_import, ros_message_conversion) turn into the project's types. Two wire formats, one
// struct per message: ROS 1 serialisation (decodeRos*: little-endian primitives, uint32-length
// strings and arrays, fixed arrays inline) and ROS 2's CDR (decodeCdr*: cdr_reader.hpp; the ROS 2
// definitions of these types have the ROS 1 fields in the same order, less std_msgs/Header's seq).
// Only the types the importer needs; each decoder throws DecodeError naming the field that does
// not fit.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "livo/import/byte_reader.hpp"
#include "livo/import/cdr_reader.hpp"

namespace livo::import {

/// std_msgs/Header.
struct RosHeader {
  uint32_t seq = 0;
  uint32_t sec = 0, nsec = 0;
  std::string frame_id;
  int64_t stampNs() const { return static_cast<int64_t>(sec) * 1000000000LL + nsec; }
};
RosHeader decodeRosHeader(ByteReader& r);
/// std_msgs/msg/Header (ROS 2): builtin_interfaces/Time (int32 sec, uint32 nanosec), frame_id; seq 0.
RosHeader decodeCdrHeader(CdrReader& r);

/// sensor_msgs/Imu.
struct RosImu {
  RosHeader header;
  std::array<double, 4> orientation_xyzw{};
  std::array<double, 3> angular_velocity{};
  std::array<double, 3> linear_acceleration{};
};
RosImu decodeRosImu(ByteReader& r);
RosImu decodeCdrImu(CdrReader& r);

/// sensor_msgs/PointField datatypes.
enum class PointFieldType : uint8_t { kInt8 = 1, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };
int pointFieldSize(uint8_t datatype);  // bytes, 0 if unknown

struct RosPointField {
  std::string name;
  uint32_t offset = 0;
  uint8_t datatype = 0;
  uint32_t count = 0;
};
/// sensor_msgs/PointCloud2 (the point data stays in the bag's buffer).
struct RosPointCloud2 {
  RosHeader header;
  uint32_t height = 0, width = 0;
  std::vector<RosPointField> fields;
  bool is_bigendian = false;
  uint32_t point_step = 0, row_step = 0;
  const uint8_t* data = nullptr;
  size_t data_size = 0;
  bool is_dense = false;
};
RosPointCloud2 decodeRosPointCloud2(ByteReader& r);
RosPointCloud2 decodeCdrPointCloud2(CdrReader& r);

/// sensor_msgs/Image.
struct RosImage {
  RosHeader header;
  uint32_t height = 0, width = 0;
  std::string encoding;
  bool is_bigendian = false;
  uint32_t step = 0;
  const uint8_t* data = nullptr;
  size_t data_size = 0;
};
RosImage decodeRosImage(ByteReader& r);
RosImage decodeCdrImage(CdrReader& r);

/// sensor_msgs/CompressedImage.
struct RosCompressedImage {
  RosHeader header;
  std::string format;
  const uint8_t* data = nullptr;
  size_t data_size = 0;
};
RosCompressedImage decodeRosCompressedImage(ByteReader& r);
RosCompressedImage decodeCdrCompressedImage(CdrReader& r);

/// sensor_msgs/CameraInfo (the calibration; R, P, binning and ROI are read but only binning and
/// ROI are kept, to tell a calibration that does not describe the images as they are).
struct RosCameraInfo {
  RosHeader header;
  uint32_t height = 0, width = 0;
  std::string distortion_model;  // plumb_bob, rational_polynomial, equidistant, ...
  std::vector<double> D;
  std::array<double, 9> K{};  // row-major [fx 0 cx; 0 fy cy; 0 0 1]
  uint32_t binning_x = 0, binning_y = 0;
  uint32_t roi_x_offset = 0, roi_y_offset = 0, roi_height = 0, roi_width = 0;
};
RosCameraInfo decodeRosCameraInfo(ByteReader& r);
RosCameraInfo decodeCdrCameraInfo(CdrReader& r);

/// A stamped position with an optional orientation: nav_msgs/Odometry, geometry_msgs/PoseStamped,
/// PoseWithCovarianceStamped, TransformStamped (orientation) and PointStamped (position only).
struct RosStampedPose {
  RosHeader header;
  std::string child_frame_id;  // Odometry, TransformStamped
  std::array<double, 3> position{};
  std::array<double, 4> orientation_xyzw{0.0, 0.0, 0.0, 1.0};
  bool has_orientation = true;
};
RosStampedPose decodeRosOdometry(ByteReader& r);
RosStampedPose decodeRosPoseStamped(ByteReader& r);
RosStampedPose decodeRosPoseWithCovarianceStamped(ByteReader& r);
RosStampedPose decodeRosTransformStamped(ByteReader& r);
RosStampedPose decodeRosPointStamped(ByteReader& r);
RosStampedPose decodeCdrOdometry(CdrReader& r);
RosStampedPose decodeCdrPoseStamped(CdrReader& r);
RosStampedPose decodeCdrPoseWithCovarianceStamped(CdrReader& r);
RosStampedPose decodeCdrTransformStamped(CdrReader& r);
RosStampedPose decodeCdrPointStamped(CdrReader& r);

/// tf2_msgs/TFMessage: its geometry_msgs/TransformStamped, in order.
std::vector<RosStampedPose> decodeRosTfMessage(ByteReader& r);
std::vector<RosStampedPose> decodeCdrTfMessage(CdrReader& r);

/// The message kinds the importer reads, chosen by type name ("sensor_msgs/Imu", or ROS 2's
/// "sensor_msgs/msg/Imu") and, in ROS 1 bags, checked against the md5sum the connection record
/// carries (a bag with a different definition under the same name is refused).
enum class RosMessageKind { kUnsupported, kImu, kPointCloud2, kImage, kCompressedImage, kCameraInfo, kPose, kTfMessage };
struct RosTypeInfo {
  RosMessageKind kind = RosMessageKind::kUnsupported;
  const char* md5 = "";
  RosStampedPose (*decode_pose)(ByteReader&) = nullptr;
  RosStampedPose (*decode_pose_cdr)(CdrReader&) = nullptr;
};
/// Info for a type name (ROS 1 or ROS 2 spelling), kind kUnsupported if the importer has no
/// decoder for it.
RosTypeInfo rosTypeInfo(const std::string& type);

}  // namespace livo::import
