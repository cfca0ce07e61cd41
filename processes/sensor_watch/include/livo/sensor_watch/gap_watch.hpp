// Dead sensors on a live bus: a channel that has carried messages and then goes silent for
// `gap_s` seconds or more (wall clock) is a gap, from its last message to the next one (or to the
// end of the run). Only arrival times count: nothing here is part of any estimator's input, so the
// pipeline's outputs never depend on the wall clock. The core takes times as arguments (no clock,
// no LCM) and is tested without a network; main.cpp feeds it from the bus.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace livo::sensor_watch {

struct SensorGap {
  std::string channel;
  double from_s = 0.0;       // wall seconds after the watch started: the last message before the gap
  double to_s = 0.0;         // the first message after it, or the end of the watch when `open`
  bool open = false;         // still silent when the watch ended
  bool never = false;        // never heard at all (open, from the watch's start)
  int64_t stamp_before = 0;  // sensor utime of the last message before the gap (0: none in its type)
  int64_t stamp_after = 0;   // of the first message after it (0: none, or open)
  double length() const { return to_s - from_s; }
};

class GapWatch {
 public:
  /// Throws std::invalid_argument for no channels or gap_s <= 0.
  GapWatch(const std::vector<std::string>& channels, double gap_s);

  /// A message on `channel` (ignored if not watched) at `now_s`, stamped `utime` (0: unknown).
  /// Returns the gap it ends, when the channel had been silent for gap_s or longer.
  std::optional<SensorGap> arrived(const std::string& channel, double now_s, int64_t utime);
  /// The channels that have been silent for gap_s or longer at `now_s` and were not returned yet
  /// for this silence (each gap once), as gaps open at now_s.
  std::vector<SensorGap> newlySilent(double now_s);
  /// The gaps still open at `now_s` (the end of the run), with to_s = now_s and open set; a channel
  /// never heard is one from 0 with `never` set too.
  std::vector<SensorGap> finish(double now_s) const;
  double gapSeconds() const { return gap_s_; }

 private:
  struct Channel {
    bool heard = false;
    bool reported = false;  // the current silence was returned by newlySilent()
    double last_s = 0.0;
    int64_t last_stamp = 0;
  };
  double gap_s_;
  std::map<std::string, Channel> channels_;
};

/// The file livo-report reads (processes/report/src/sensor_gaps.cpp): one line per gap,
/// tab-separated: channel, from_s, to_s, length_s, `back`, `open` or `never` (never heard), sensor stamp before and
/// after in seconds (`-` when unknown); lines starting with '#' are comments.
void writeGapLine(std::ostream& os, const SensorGap& gap);

}  // namespace livo::sensor_watch
