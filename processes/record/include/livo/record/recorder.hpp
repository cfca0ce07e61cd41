// A recorder that takes part in lockstep replay: it subscribes to named channels through the node
// framework, so playback waits until it has written every message, and nothing is lost however
// busy the machine is (lcm-logger cannot say when it is ready or has caught up). Each event is
// stamped with the message's own utime when its type has one (deterministic logs), else with the
// last such stamp seen. Events before the first stamp (a node's HEALTH before it has seen any
// sensor time says utime 0) are held and written with it, so a log never starts at time 0 and then
// jumps by decades (its duration, and a real-time replay of it, would be absurd).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "livo/node.hpp"

namespace lcm {
class LogFile;
}

namespace livo::record {

class Recorder {
 public:
  /// Throws std::runtime_error naming the file if it cannot be written.
  Recorder(Node& node, const std::string& out_path, const std::vector<std::string>& channels);
  ~Recorder();
  /// Writes the recorder's own final HEALTH into the log (it cannot receive its own message), then
  /// flushes. Call once at shutdown.
  void finish(const std::string& health_channel = "HEALTH");
  void flush();
  int64_t written() const { return written_; }

 private:
  void write(const std::string& channel, const void* data, int size);
  void writeEvent(const std::string& channel, const void* data, int size, int64_t timestamp);
  void writeHeld();

  struct HeldEvent {
    std::string channel;
    std::vector<uint8_t> data;
  };
  static constexpr size_t kMaxHeld = 1024;  // a log with no stamped type at all is written as it comes

  Node& node_;
  std::string path_;
  std::unique_ptr<lcm::LogFile> log_;
  int64_t written_ = 0;
  int64_t last_utime_ = 0;  // 0: no stamp seen yet
  std::vector<HeldEvent> held_;
};

}  // namespace livo::record
