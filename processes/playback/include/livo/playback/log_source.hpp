// Events of an LCM log in file order, filtered by channel pattern and a time window.
#pragma once

#include <cstdint>
#include <optional>
#include <regex>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace livo::playback {

struct LogEvent {
  int64_t utime = 0;          // the log event's timestamp (sensor time for logs made here)
  std::string channel;
  std::vector<uint8_t> data;
};

struct LogSourceOptions {
  std::string channels = ".*";  // ECMAScript regex, whole-name match
  double start_s = 0.0;         // skip this much from the first event
  double duration_s = 0.0;      // 0: to the end
};

class LogSource {
 public:
  /// Throws std::runtime_error naming the file if it cannot be opened or the pattern is invalid.
  LogSource(const std::string& path, LogSourceOptions options);
  ~LogSource();

  /// The next event that passes the filters, or nullopt at the end of the log (or of the window).
  std::optional<LogEvent> next();
  /// Bytes after the last readable event once next() returned nullopt (a truncated tail).
  int64_t trailingBytes() const { return trailing_bytes_; }
  /// Bytes skipped between events so far (damage: they do not start with the sync word).
  int64_t skippedBytes() const { return skipped_bytes_; }
  int64_t firstUtime() const { return first_utime_; }
  double fractionRead() const;

 private:
  /// The next event in the file (any channel); false at the end of the readable events.
  bool readEvent(int64_t* utime, std::string_view* channel, const uint8_t** data, int64_t* size);

  std::string path_;
  LogSourceOptions options_;
  std::regex pattern_;
  std::unordered_map<std::string, bool> matches_;  // channel -> pattern_ matches it (a regex per event is slow)
  // The file mapped whole (read in place: no copy into a stream buffer and another into each
  // event, as lcm::LogFile does); the events are parsed as lcm_eventlog reads them.
  const uint8_t* map_ = nullptr;
  int64_t pos_ = 0;  // the next byte to parse
  int64_t file_bytes_ = 0;
  int64_t first_utime_ = -1;
  int64_t trailing_bytes_ = 0;
  int64_t skipped_bytes_ = 0;
  bool done_ = false;
};

}  // namespace livo::playback
