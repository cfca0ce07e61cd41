#include "livo/evaluate/scan_log.hpp"

#include <map>

#include <lcm/lcm-cpp.hpp>

#include "livo/evaluate/pose_log.hpp"
#include "livo/evaluate/trajectory_input.hpp"
#include "livo/message_checks.hpp"
#include "livo/message_registry.hpp"
#include "livo/registered_scan_t.hpp"

namespace livo::evaluate {

namespace {
constexpr const char* kScanType = "livo.registered_scan_t";

std::string channelList(const std::map<std::string, size_t>& channels) {
  std::string present;
  for (const auto& [name, count] : channels)
    present += (present.empty() ? "" : ", ") + name + " (" + std::to_string(count) + ")";
  return present.empty() ? std::string("none") : present;
}

/// The message of one event on the channel, checked; `where` names the event in errors.
registered_scan_t decodeScan(const lcm::LogEvent& ev, const std::string& where) {
  const MessageType* type = identifyMessage(ev.data, static_cast<int>(ev.datalen));
  const std::string type_name = type ? type->name : "an unknown type";
  if (type_name != kScanType) throw ScanLogError(where + ": is " + type_name + ", expected " + kScanType);
  registered_scan_t m;
  if (m.decode(ev.data, 0, static_cast<int>(ev.datalen)) < 0)
    throw ScanLogError(where + ": does not decode as " + kScanType);
  if (m.cloud.num_points == 0) return m;  // empty: the thickness counts it as skipped
  const std::string problem = registeredScanProblem(m);
  if (!problem.empty()) throw ScanLogError(where + ": " + problem);
  return m;
}

GroundScan groundScanOf(const registered_scan_t& m, const std::string& where) {
  GroundScan s;
  s.utime = m.utime;
  s.epoch = m.epoch;
  s.size = static_cast<size_t>(m.cloud.num_points);
  if (s.size == 0) return s;
  s.T_W_I = stampedPoseOf(m.utime, m.position, m.orientation, where).pose;
  s.x = m.cloud.x.data();
  s.y = m.cloud.y.data();
  s.z = m.cloud.z.data();
  return s;
}

void readScans(const ScanLogInput& in, const GroundScanVisitor& visit) {
  lcm::LogFile log(in.path, "r");
  if (!log.good()) throw ScanLogError(in.path + ": cannot open as an LCM log");
  std::map<std::string, size_t> channels;
  size_t event_no = 0, scans = 0;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    ++event_no;
    ++channels[ev->channel];
    if (ev->channel != in.channel) continue;
    const std::string where = in.path + ": event " + std::to_string(event_no) + " on " + in.channel;
    const registered_scan_t m = decodeScan(*ev, where);
    visit(groundScanOf(m, where));
    ++scans;
  }
  if (scans == 0)
    throw ScanLogError(in.path + ": no messages on channel " + in.channel +
                       " (channels in the log: " + channelList(channels) + ")");
}
}  // namespace

ScanLogInput scanLogInput(const std::string& spec, const std::string& default_channel) {
  const LogSpec named = splitLogSpec(spec);
  if (!isLcmLog(named.path))
    throw InputError(spec + ": not an LCM log (the ground map reads " + kScanType + " messages from a log)");
  return ScanLogInput{spec, named.path, named.channel.empty() ? default_channel : named.channel};
}

GroundScanSource registeredScanSource(const ScanLogInput& input) {
  return [input](const GroundScanVisitor& visit) { readScans(input, visit); };
}

}  // namespace livo::evaluate
