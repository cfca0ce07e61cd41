// A recorder that takes part in lockstep replay: it subscribes to named channels through the node
// framework, so playback waits until it has written every message, and nothing is lost however
// busy the machine is (lcm-logger cannot say when it is ready or has caught up). Each event is
// stamped with the message's own utime when its type has one (deterministic logs), else with the
// last such stamp seen.
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

  Node& node_;
  std::string path_;
  std::unique_ptr<lcm::LogFile> log_;
  int64_t written_ = 0;
  int64_t last_utime_ = 0;
};

}  // namespace livo::record
