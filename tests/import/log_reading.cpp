#include "log_reading.hpp"

#include <cstdlib>

#include <lcm/lcm-cpp.hpp>

namespace livo::test {

std::vector<LoggedEvent> readLog(const std::string& path) {
  std::vector<LoggedEvent> out;
  lcm::LogFile log(path, "r");
  EXPECT_TRUE(log.good()) << path;
  if (!log.good()) return out;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    const auto* d = static_cast<const uint8_t*>(ev->data);
    out.push_back({ev->timestamp, ev->channel, std::vector<uint8_t>(d, d + ev->datalen)});
  }
  return out;
}

bool inTimeOrder(const std::vector<LoggedEvent>& events) {
  for (size_t i = 1; i < events.size(); ++i)
    if (events[i].timestamp < events[i - 1].timestamp) return false;
  return true;
}

std::string freshTempDir(const std::string& name) {
  const std::string dir = std::string(LIVO_IMPORT_TEST_TMP) + "/" + name;
  const std::string cmd = "rm -rf '" + dir + "' && mkdir -p '" + dir + "'";
  EXPECT_EQ(std::system(cmd.c_str()), 0);
  return dir;
}

}  // namespace livo::test
