#include "livo/import/ros_messages.hpp"

namespace livo::import {

namespace {
void readPoint(ByteReader& r, RosStampedPose& p, const char* const names[3]) {
  for (int i = 0; i < 3; ++i) p.position[i] = r.f64(names[i]);
}
void readQuaternion(ByteReader& r, RosStampedPose& p, const char* const names[4]) {
  for (int i = 0; i < 4; ++i) p.orientation_xyzw[i] = r.f64(names[i]);
}
const char* const kPosePosition[3] = {"pose.position.x", "pose.position.y", "pose.position.z"};
const char* const kPoseOrientation[4] = {"pose.orientation.x", "pose.orientation.y", "pose.orientation.z",
                                         "pose.orientation.w"};
}  // namespace

RosStampedPose decodeRosOdometry(ByteReader& r) {
  RosStampedPose p;
  p.header = decodeRosHeader(r);
  p.child_frame_id = r.string("child_frame_id");
  readPoint(r, p, kPosePosition);
  readQuaternion(r, p, kPoseOrientation);
  r.skip(36 * 8, "pose.covariance");
  r.skip(6 * 8 + 36 * 8, "twist");
  return p;
}

RosStampedPose decodeRosPoseStamped(ByteReader& r) {
  RosStampedPose p;
  p.header = decodeRosHeader(r);
  readPoint(r, p, kPosePosition);
  readQuaternion(r, p, kPoseOrientation);
  return p;
}

RosStampedPose decodeRosPoseWithCovarianceStamped(ByteReader& r) {
  RosStampedPose p;
  p.header = decodeRosHeader(r);
  readPoint(r, p, kPosePosition);
  readQuaternion(r, p, kPoseOrientation);
  r.skip(36 * 8, "pose.covariance");
  return p;
}

RosStampedPose decodeRosTransformStamped(ByteReader& r) {
  RosStampedPose p;
  p.header = decodeRosHeader(r);
  p.child_frame_id = r.string("child_frame_id");
  const char* const t[3] = {"transform.translation.x", "transform.translation.y", "transform.translation.z"};
  const char* const q[4] = {"transform.rotation.x", "transform.rotation.y", "transform.rotation.z",
                            "transform.rotation.w"};
  readPoint(r, p, t);
  readQuaternion(r, p, q);
  return p;
}

RosStampedPose decodeRosPointStamped(ByteReader& r) {
  RosStampedPose p;
  p.header = decodeRosHeader(r);
  const char* const names[3] = {"point.x", "point.y", "point.z"};
  readPoint(r, p, names);
  p.has_orientation = false;
  return p;
}

}  // namespace livo::import
