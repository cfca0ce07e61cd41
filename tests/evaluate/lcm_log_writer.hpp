// Writes LCM log files for the tests (lcm::LogFile only, no network).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

namespace livo {
namespace fixtures {

inline void writeRaw(lcm::LogFile& log, const std::string& channel, int64_t t, const std::vector<uint8_t>& bytes) {
  lcm::LogEvent ev;
  ev.timestamp = t;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(bytes.size());
  ev.data = const_cast<uint8_t*>(bytes.data());
  log.writeEvent(&ev);
}

template <class Message>
void writeMessage(lcm::LogFile& log, const std::string& channel, int64_t t, const Message& m) {
  std::vector<uint8_t> buf(static_cast<size_t>(m.getEncodedSize()));
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  writeRaw(log, channel, t, buf);
}

}  // namespace fixtures
}  // namespace livo
