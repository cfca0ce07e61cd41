// Peak resident memory of every node over sensor time, from the HEALTH messages of a run's
// outputs log (each carries the node's peak RSS so far and the sensor time of its last input).
#pragma once

#include <map>
#include <string>
#include <vector>

namespace livo::report {

struct MemoryProfile {
  double first_seconds = 0.0;  // sensor time of the earliest HEALTH (the run's start)
  double last_seconds = 0.0;   // of the newest
  /// Per node: (sensor seconds since first_seconds, peak RSS MB), in time order.
  std::map<std::string, std::vector<std::pair<double, double>>> samples;
  /// The node's peak RSS reported at or before `seconds` since the start (NaN: no report yet, or
  /// the run ended more than kEndSlack_s before `seconds`).
  double peakAt(const std::string& node, double seconds) const;
  static constexpr double kEndSlack_s = 2.0;  // two health periods
};

/// Reads every HEALTH message (channel `health_channel`); throws std::runtime_error if the log
/// cannot be opened.
MemoryProfile readMemoryProfile(const std::string& log_path, const std::string& health_channel = "HEALTH");

/// A markdown table: per node the peak RSS at each checkpoint (seconds), the ratio of the last
/// checkpoint to the first, and the peak over the whole run.
std::string memoryTable(const MemoryProfile& profile, const std::vector<double>& checkpoints_s);

}  // namespace livo::report
