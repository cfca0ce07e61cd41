// Reads an LCM log back for the import tests.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace livo::test {

struct LoggedEvent {
  int64_t timestamp;
  std::string channel;
  std::vector<uint8_t> data;
};

std::vector<LoggedEvent> readLog(const std::string& path);

/// Messages of `channel` decoded as Msg, in log order; decoding failures fail the test.
template <class Msg>
std::vector<Msg> messagesOn(const std::vector<LoggedEvent>& events, const std::string& channel) {
  std::vector<Msg> out;
  for (const LoggedEvent& e : events) {
    if (e.channel != channel) continue;
    Msg m;
    EXPECT_EQ(m.decode(e.data.data(), 0, static_cast<int>(e.data.size())), static_cast<int>(e.data.size()));
    EXPECT_EQ(e.timestamp, m.utime) << "event timestamp must equal the message utime";
    out.push_back(m);
  }
  return out;
}

/// Every event's timestamp is >= the previous one's.
bool inTimeOrder(const std::vector<LoggedEvent>& events);

/// A fresh empty folder under the test build folder.
std::string freshTempDir(const std::string& name);

}  // namespace livo::test
