#include "livo/import/ros_messages.hpp"

namespace livo::import {

RosHeader decodeRosHeader(ByteReader& r) {
  RosHeader h;
  h.seq = r.u32("header.seq");
  h.sec = r.u32("header.stamp.sec");
  h.nsec = r.u32("header.stamp.nsec");
  h.frame_id = r.string("header.frame_id");
  return h;
}

RosHeader decodeCdrHeader(CdrReader& r) {
  RosHeader h;
  const int32_t sec = r.i32("header.stamp.sec");
  if (sec < 0) r.fail("header.stamp.sec", "negative (" + std::to_string(sec) + ")");
  h.sec = static_cast<uint32_t>(sec);
  h.nsec = r.u32("header.stamp.nanosec");
  h.frame_id = r.string("header.frame_id");
  return h;
}

namespace {
/// "sensor_msgs/msg/Imu" (ROS 2) -> "sensor_msgs/Imu".
std::string ros1TypeName(const std::string& type) {
  const size_t p = type.find("/msg/");
  return p == std::string::npos ? type : type.substr(0, p) + "/" + type.substr(p + 5);
}
}  // namespace

RosTypeInfo rosTypeInfo(const std::string& type_name) {
  const std::string type = ros1TypeName(type_name);
  RosTypeInfo t;
  if (type == "sensor_msgs/Imu") t = {RosMessageKind::kImu, "6a62c6daae103f4ff57a132d6f95cec2", nullptr};
  if (type == "sensor_msgs/PointCloud2")
    t = {RosMessageKind::kPointCloud2, "1158d486dd51d683ce2f1be655c3c181", nullptr};
  if (type == "sensor_msgs/Image") t = {RosMessageKind::kImage, "060021388200f6f0f447d0fcd9c64743", nullptr};
  if (type == "sensor_msgs/CompressedImage")
    t = {RosMessageKind::kCompressedImage, "8f7a12909da2c9d3332d540a0977563f", nullptr};
  if (type == "sensor_msgs/CameraInfo") t = {RosMessageKind::kCameraInfo, "c9a58c1b0b154e0e6da7578cb991d214", nullptr};
  if (type == "nav_msgs/Odometry") t = {RosMessageKind::kPose, "cd5e73d190d741a2f92e81eda573aca7", decodeRosOdometry, decodeCdrOdometry};
  if (type == "geometry_msgs/PoseStamped")
    t = {RosMessageKind::kPose, "d3812c3cbc69362b77dc0b19b345f8f5", decodeRosPoseStamped, decodeCdrPoseStamped};
  if (type == "geometry_msgs/PoseWithCovarianceStamped")
    t = {RosMessageKind::kPose, "953b798c0f514ff060a53a3498ce6246", decodeRosPoseWithCovarianceStamped, decodeCdrPoseWithCovarianceStamped};
  if (type == "geometry_msgs/TransformStamped")
    t = {RosMessageKind::kPose, "b5764a33bfeb3588febc2682852579b0", decodeRosTransformStamped, decodeCdrTransformStamped};
  if (type == "geometry_msgs/PointStamped")
    t = {RosMessageKind::kPose, "c63aecb41bfdfd6b7e1fac37c7cbe7bf", decodeRosPointStamped, decodeCdrPointStamped};
  if (type == "tf2_msgs/TFMessage") t = {RosMessageKind::kTfMessage, "94810edda583a504dfda3829e70d7eec", nullptr};
  return t;
}

}  // namespace livo::import
