// A recorder that takes part in lockstep replay: it subscribes to named channels through the node
// framework, so playback waits until it has written every message, and nothing is lost however
// busy the machine is (lcm-logger cannot say when it is ready or has caught up). Each event is
// stamped with the message's own utime when its type has one (deterministic logs), else with the
// last such stamp seen. Events before the first stamp (a node's HEALTH before it has seen any
// sensor time says utime 0) are held and written with it, so a log never starts at time 0 and then
// jumps by decades (its duration, and a real-time replay of it, would be absurd).
#pragma once

#include <atomic>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "livo/node.hpp"

namespace lcm {
class LogFile;
}

namespace livo::record {

/// Arrival times for real-time latency (livo-report's "Latency"): a line per message received on
/// any channel of the bus but `skip` (PROGRESS: every node's, after every message),
/// `channel  type  utime  end_utime  arrival_us`, where arrival_us is LCM's recv_utime (wall clock,
/// µs, taken by its receive thread: no wait behind the recorder's own writes), type the LCM type
/// name ("-" if unknown), utime the message's stamp (-1 if it has none) and end_utime the end of a
/// LiDAR sweep (utime + sweep_duration; utime for other types). The subscription goes past the
/// node, so it adds nothing to PROGRESS: lockstep does not wait for it and the log is unchanged.
class ArrivalLog {
 public:
  /// Throws std::runtime_error naming the file if it cannot be written. Appends (a restarted
  /// recorder goes on in the same file).
  ArrivalLog(lcm::LCM& lcm, const std::string& path, std::string skip = "PROGRESS");
  ~ArrivalLog();
  ArrivalLog(const ArrivalLog&) = delete;
  ArrivalLog& operator=(const ArrivalLog&) = delete;
  void flush();
  int64_t written() const { return written_; }

 private:
  static void onMessage(const lcm::ReceiveBuffer* rbuf, const std::string& channel, ArrivalLog* self);

  lcm::LCM& lcm_;
  std::string skip_;
  std::FILE* file_ = nullptr;
  lcm::Subscription* sub_ = nullptr;
  int64_t written_ = 0;
};

/// An ArrivalLog on an LCM instance of its own, handled by a thread of its own: the node's
/// handler thread may be niced or slow (a test's handler delay), and LCM drops messages once too
/// many wait to be handled, the more so for the large clouds and images timed here.
class ArrivalThread {
 public:
  /// Throws std::runtime_error if the bus or the file cannot be opened.
  ArrivalThread(const std::string& lcm_url, const std::string& path);
  ~ArrivalThread();  // stops the thread and flushes the file
  ArrivalThread(const ArrivalThread&) = delete;
  ArrivalThread& operator=(const ArrivalThread&) = delete;

 private:
  std::unique_ptr<lcm::LCM> lcm_;
  std::unique_ptr<ArrivalLog> log_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

/// The header and one line of an arrival log (ArrivalLog), for writers and readers of the format.
std::string arrivalHeader();
std::string arrivalLine(const std::string& channel, const void* data, int size, int64_t arrival_us);

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
