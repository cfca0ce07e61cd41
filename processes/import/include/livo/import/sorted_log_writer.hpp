// Writes an LCM log whose events are in time order (event timestamp = message utime), whatever
// order the importer produces them in. Ties keep insertion order. Memory is bounded: past
// `max_buffer_bytes` the buffered events are sorted and spilled to a temporary run file next to
// the output, and finish() merges the runs. An observer (optional) sees every message as added.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "livo/image_t.hpp"
#include "livo/imu_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/pose_t.hpp"

namespace livo::import {

/// Sees each converted message with its channel, in the order it was produced (not time order):
/// a SortedLogWriter's observer (RigSurvey measuring rates and sensor facts while the log is
/// written), or where a converter's output goes (LogWriterSink below, livo-ros-bridge's LCM queue).
class MessageObserver {
 public:
  virtual ~MessageObserver() = default;
  virtual void observe(const std::string& channel, const imu_t& msg) = 0;
  virtual void observe(const std::string& channel, const point_cloud_t& msg) = 0;
  virtual void observe(const std::string& channel, const image_t& msg) = 0;
  virtual void observe(const std::string& channel, const pose_t& msg) = 0;
};

struct SortedLogWriterOptions {
  int64_t max_buffer_bytes = 512LL << 20;  // spill to a run file beyond this
};

class SortedLogWriter {
 public:
  explicit SortedLogWriter(std::string path, SortedLogWriterOptions options = {});
  ~SortedLogWriter();  // removes run files if finish() was not called
  SortedLogWriter(const SortedLogWriter&) = delete;
  SortedLogWriter& operator=(const SortedLogWriter&) = delete;

  /// Adds an LCM message (any generated type with utime and encode()).
  template <class Msg>
  void add(const std::string& channel, const Msg& msg) {
    if (observer_) observer_->observe(channel, msg);
    std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
    msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    addEncoded(channel, msg.utime, std::move(bytes));
  }
  void addEncoded(const std::string& channel, int64_t utime, std::vector<uint8_t> bytes);
  /// Shows every message given to add() to `observer` (nullptr: none); not owned.
  void setObserver(MessageObserver* observer) { observer_ = observer; }

  /// Sorts, merges and writes the log. Throws std::runtime_error if it cannot be written.
  void finish();

  /// Messages added per channel.
  const std::map<std::string, int64_t>& counts() const { return counts_; }
  int64_t runFiles() const { return static_cast<int64_t>(runs_.size()); }

 private:
  struct Event {
    int64_t utime;
    std::string channel;
    std::vector<uint8_t> data;
  };
  void spill();
  void removeRuns();

  std::string path_;
  SortedLogWriterOptions options_;
  std::vector<Event> buffer_;
  int64_t buffer_bytes_ = 0;
  std::vector<std::string> runs_;
  std::map<std::string, int64_t> counts_;
  bool finished_ = false;
  MessageObserver* observer_ = nullptr;
};

/// A MessageObserver that adds each message to a SortedLogWriter (a converter's output into the log).
class LogWriterSink : public MessageObserver {
 public:
  explicit LogWriterSink(SortedLogWriter& writer) : writer_(writer) {}
  void observe(const std::string& channel, const imu_t& msg) override { writer_.add(channel, msg); }
  void observe(const std::string& channel, const point_cloud_t& msg) override { writer_.add(channel, msg); }
  void observe(const std::string& channel, const image_t& msg) override { writer_.add(channel, msg); }
  void observe(const std::string& channel, const pose_t& msg) override { writer_.add(channel, msg); }

 private:
  SortedLogWriter& writer_;
};

}  // namespace livo::import
