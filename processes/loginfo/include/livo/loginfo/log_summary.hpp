// Summary of an LCM log file, per channel: type, count, rate, bytes (like `rosbag info`).
#pragma once

#include <cstdint>
#include <iosfwd>
#include <map>
#include <string>

namespace livo::loginfo {

struct ChannelSummary {
  std::string type;  // project type name, "unknown (0x…)" or "mixed"
  int64_t count = 0;
  int64_t bytes = 0;
  int64_t first_utime = 0;  // event timestamps (log time)
  int64_t last_utime = 0;
  int64_t out_of_order = 0;         // events stamped earlier than the previous one on this channel
  uint64_t digest = 0;              // FNV-1a over the payloads in log order (determinism checks)
  int64_t non_finite_messages = 0;  // messages holding a NaN or an infinity (countNonFinite)
  int64_t non_finite_values = 0;
  double rateHz() const;
};

struct LogSummary {
  std::string path;
  int64_t file_bytes = 0;
  int64_t events = 0;
  int64_t first_utime = 0;
  int64_t last_utime = 0;
  int64_t trailing_bytes = 0;  // bytes after the last readable event (truncated or corrupt tail)
  std::map<std::string, ChannelSummary> channels;
  double durationS() const { return events ? (last_utime - first_utime) * 1e-6 : 0.0; }
};

/// Reads the whole log; throws std::runtime_error if it cannot be opened.
LogSummary summarizeLog(const std::string& path);

/// `with_digest` adds a column with each channel's payload digest; `with_non_finite` one with the
/// number of messages that hold a NaN or an infinity in a floating-point field.
void printLogSummary(const LogSummary& s, std::ostream& os, bool with_digest = false, bool with_non_finite = false);

}  // namespace livo::loginfo
