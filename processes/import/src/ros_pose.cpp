#include "ros_decoding.hpp"

namespace livo::import {

namespace {
template <class Reader>
void readPoint(Reader& r, RosStampedPose& p, const char* const names[3]) {
  for (int i = 0; i < 3; ++i) p.position[i] = r.f64(names[i]);
}
template <class Reader>
void readQuaternion(Reader& r, RosStampedPose& p, const char* const names[4]) {
  for (int i = 0; i < 4; ++i) p.orientation_xyzw[i] = r.f64(names[i]);
}
const char* const kPosePosition[3] = {"pose.position.x", "pose.position.y", "pose.position.z"};
const char* const kPoseOrientation[4] = {"pose.orientation.x", "pose.orientation.y", "pose.orientation.z",
                                         "pose.orientation.w"};

template <class Reader>
RosStampedPose decodeOdometry(Reader& r) {
  RosStampedPose p;
  p.header = detail::decodeHeader(r);
  p.child_frame_id = r.string("child_frame_id");
  readPoint(r, p, kPosePosition);
  readQuaternion(r, p, kPoseOrientation);
  r.skipF64(36, "pose.covariance");
  r.skipF64(6 + 36, "twist");  // Twist (two Vector3) and its covariance, all float64
  return p;
}

template <class Reader>
RosStampedPose decodePoseStamped(Reader& r) {
  RosStampedPose p;
  p.header = detail::decodeHeader(r);
  readPoint(r, p, kPosePosition);
  readQuaternion(r, p, kPoseOrientation);
  return p;
}

template <class Reader>
RosStampedPose decodePoseWithCovarianceStamped(Reader& r) {
  RosStampedPose p;
  p.header = detail::decodeHeader(r);
  readPoint(r, p, kPosePosition);
  readQuaternion(r, p, kPoseOrientation);
  r.skipF64(36, "pose.covariance");
  return p;
}

template <class Reader>
RosStampedPose decodeTransformStamped(Reader& r) {
  RosStampedPose p;
  p.header = detail::decodeHeader(r);
  p.child_frame_id = r.string("child_frame_id");
  const char* const t[3] = {"transform.translation.x", "transform.translation.y", "transform.translation.z"};
  const char* const q[4] = {"transform.rotation.x", "transform.rotation.y", "transform.rotation.z",
                            "transform.rotation.w"};
  readPoint(r, p, t);
  readQuaternion(r, p, q);
  return p;
}

template <class Reader>
RosStampedPose decodePointStamped(Reader& r) {
  RosStampedPose p;
  p.header = detail::decodeHeader(r);
  const char* const names[3] = {"point.x", "point.y", "point.z"};
  readPoint(r, p, names);
  p.has_orientation = false;
  return p;
}

template <class Reader>
std::vector<RosStampedPose> decodeTfMessage(Reader& r) {
  const uint32_t n = r.arrayLength("transforms", 4 + 4 + 4 + 4 + 7 * 8);
  std::vector<RosStampedPose> out;
  out.reserve(n);
  for (uint32_t i = 0; i < n; ++i) out.push_back(decodeTransformStamped(r));
  return out;
}

}  // namespace

std::vector<RosStampedPose> decodeRosTfMessage(ByteReader& r) { return decodeTfMessage(r); }
std::vector<RosStampedPose> decodeCdrTfMessage(CdrReader& r) { return decodeTfMessage(r); }
RosStampedPose decodeRosOdometry(ByteReader& r) { return decodeOdometry(r); }
RosStampedPose decodeCdrOdometry(CdrReader& r) { return decodeOdometry(r); }
RosStampedPose decodeRosPoseStamped(ByteReader& r) { return decodePoseStamped(r); }
RosStampedPose decodeCdrPoseStamped(CdrReader& r) { return decodePoseStamped(r); }
RosStampedPose decodeRosPoseWithCovarianceStamped(ByteReader& r) { return decodePoseWithCovarianceStamped(r); }
RosStampedPose decodeCdrPoseWithCovarianceStamped(CdrReader& r) { return decodePoseWithCovarianceStamped(r); }
RosStampedPose decodeRosTransformStamped(ByteReader& r) { return decodeTransformStamped(r); }
RosStampedPose decodeCdrTransformStamped(CdrReader& r) { return decodeTransformStamped(r); }
RosStampedPose decodeRosPointStamped(ByteReader& r) { return decodePointStamped(r); }
RosStampedPose decodeCdrPointStamped(CdrReader& r) { return decodePointStamped(r); }

}  // namespace livo::import
