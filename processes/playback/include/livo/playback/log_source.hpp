// Events of an LCM log in file order, filtered by channel pattern and a time window.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <regex>
#include <string>
#include <unordered_map>
#include <vector>

namespace lcm {
class LogFile;
}

namespace livo::playback {

struct LogEvent {
  int64_t utime = 0;  // the log event's timestamp (sensor time for logs made here)
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
  int64_t firstUtime() const { return first_utime_; }
  double fractionRead() const;

 private:
  std::string path_;
  LogSourceOptions options_;
  std::regex pattern_;
  std::unordered_map<std::string, bool> matches_;  // channel -> pattern_ matches it (a regex per event is slow)
  std::unique_ptr<lcm::LogFile> log_;
  int64_t file_bytes_ = 0;
  int64_t first_utime_ = -1;
  int64_t trailing_bytes_ = 0;
  int64_t last_good_pos_ = 0;
  bool done_ = false;
};

}  // namespace livo::playback
