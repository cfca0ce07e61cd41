#include "livo/evaluate/pose_log.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <map>

#include <lcm/lcm-cpp.hpp>

#include "livo/message_registry.hpp"
#include "livo/messages.hpp"
#include "livo/odometry_t.hpp"
#include "livo/pose_t.hpp"
#include "livo/time.hpp"

namespace livo::evaluate {

namespace {
constexpr uint8_t kSyncWord[4] = {0xED, 0xA1, 0xDA, 0x01};  // big-endian 0xEDA1DA01

template <class Message>
Message decodeOrThrow(const lcm::LogEvent& ev, const std::string& where) {
  Message m;
  if (m.decode(ev.data, 0, static_cast<int>(ev.datalen)) < 0)
    throw PoseLogError(where + ": does not decode as livo." + Message::getTypeName());
  return m;
}
}  // namespace

StampedPose stampedPoseOf(int64_t utime, const double position[3], const double orientation[4],
                          const std::string& where) {
  if (!allFinite(position, 3) || !allFinite(orientation, 4)) throw PoseLogError(where + ": pose is not finite");
  const double qn = std::sqrt(orientation[0] * orientation[0] + orientation[1] * orientation[1] +
                              orientation[2] * orientation[2] + orientation[3] * orientation[3]);
  if (!(qn > 0.5 && qn < 1.5))
    throw PoseLogError(where + ": orientation quaternion has norm " + std::to_string(qn) + ", not 1");
  return StampedPose{toSeconds(utime), poseFrom(position, orientation)};
}

bool isLcmLog(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  uint8_t head[4] = {0, 0, 0, 0};
  if (!in.read(reinterpret_cast<char*>(head), 4)) return false;
  return std::equal(head, head + 4, kSyncWord);
}

PoseLog readPoseLog(const std::string& path, const std::string& channel) {
  lcm::LogFile log(path, "r");
  if (!log.good()) throw PoseLogError(path + ": cannot open as an LCM log");
  PoseLog out;
  std::map<std::string, size_t> channels;
  size_t event_no = 0;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    ++event_no;
    ++channels[ev->channel];
    if (ev->channel != channel) continue;
    const std::string where = path + ": event " + std::to_string(event_no) + " on " + channel;
    const MessageType* type = identifyMessage(ev->data, static_cast<int>(ev->datalen));
    const std::string type_name = type ? type->name : "an unknown type";
    if (type_name != "livo.pose_t" && type_name != "livo.odometry_t")
      throw PoseLogError(where + ": is " + type_name + ", expected livo.pose_t or livo.odometry_t");
    if (out.type_name.empty()) out.type_name = type_name;
    if (type_name != out.type_name)
      throw PoseLogError(where + ": is " + type_name + " but earlier messages on the channel are " + out.type_name);
    StampedPose s;
    if (type_name == "livo.pose_t") {
      const auto m = decodeOrThrow<pose_t>(*ev, where);
      s = stampedPoseOf(m.utime, m.position, m.orientation, where);
    } else {
      const auto m = decodeOrThrow<odometry_t>(*ev, where);
      s = stampedPoseOf(m.utime, m.position, m.orientation, where);
    }
    out.poses.push_back(s);
  }
  if (out.poses.empty()) {
    std::string present;
    for (const auto& [name, count] : channels)
      present += (present.empty() ? "" : ", ") + name + " (" + std::to_string(count) + ")";
    throw PoseLogError(path + ": no messages on channel " + channel +
                       " (channels in the log: " + (present.empty() ? std::string("none") : present) + ")");
  }
  std::stable_sort(out.poses.begin(), out.poses.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
  return out;
}

}  // namespace livo::evaluate
