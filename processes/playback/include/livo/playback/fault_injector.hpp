// Seeded, reproducible faults on a stream of log events, for robustness tests:
//   drop, duplicate, delay (reorders across channels), reorder (swap with the next message of the
//   same channel), corrupt bytes, NaN points in point clouds, a timestamp jump, a sensor cut.
// Each fault is given per channel as text (see parseFault) and applies to a fraction of messages.
#pragma once

#include <cstdint>
#include <map>
#include <queue>
#include <random>
#include <string>
#include <vector>

#include "livo/playback/log_source.hpp"

namespace livo::playback {

struct Fault {
  enum class Kind { kDrop, kDuplicate, kDelay, kReorder, kCorrupt, kNanPoints, kTimeJump, kCut };
  Kind kind = Kind::kDrop;
  std::string channel;    // exact channel name
  double fraction = 0.0;  // of messages on the channel (drop, duplicate, delay, reorder, corrupt, nan)
  double seconds = 0.0;   // delay: how late; time-jump: size of the jump
  double from_s = 0.0;    // time-jump: from this log time on; cut: window start (s from log start)
  double to_s = 0.0;      // cut: window end
};

/// Parses "drop:CH:FRAC", "duplicate:CH:FRAC", "delay:CH:FRAC:SECONDS", "reorder:CH:FRAC",
/// "corrupt:CH:FRAC", "nan:CH:FRAC", "jump:CH:AT_S:JUMP_S", "cut:CH:FROM_S:TO_S".
/// Throws std::invalid_argument with the reason.
Fault parseFault(const std::string& text);
std::string describe(const Fault& f);

struct FaultCounts {
  int64_t dropped = 0, duplicated = 0, delayed = 0, reordered = 0, corrupted = 0, nan_clouds = 0, time_shifted = 0,
          cut = 0;
};

class FaultInjector {
 public:
  FaultInjector(std::vector<Fault> faults, uint64_t seed);

  /// Feeds one event; returns the events to emit now, in order. `t0` is the log's first stamp.
  std::vector<LogEvent> push(LogEvent event, int64_t t0);
  /// Remaining delayed/held events at the end of the stream.
  std::vector<LogEvent> flush();

  const std::map<std::string, FaultCounts>& counts() const { return counts_; }
  bool empty() const { return faults_.empty(); }

 private:
  struct Delayed {
    int64_t release_utime;
    uint64_t order;
    LogEvent event;
    bool operator>(const Delayed& o) const {
      return release_utime != o.release_utime ? release_utime > o.release_utime : order > o.order;
    }
  };
  /// What the faults on a message's channel decided (corrupt, NaN points and time jumps are
  /// applied to the message itself).
  struct FaultDecision {
    bool emit = true;  // false: dropped or cut
    bool duplicate = false;
    bool hold = false;  // reorder: held until the channel's next message
    int64_t delay_us = 0;
  };
  /// Delayed events due at or before `utime`, in release order (taken off the queue).
  std::vector<LogEvent> releaseDelayed(int64_t utime);
  /// Draws every fault of the event's channel (`t`: seconds since the log's start) in order.
  FaultDecision applyFaults(LogEvent& event, double t, FaultCounts& counts);
  /// A cut of `channel` covers log time `t`.
  bool inCut(const std::string& channel, double t) const;
  /// Sends the message (and its duplicate) to the delay queue or the held place of a reorder, or
  /// returns it (with a held one it releases) to be emitted now.
  std::vector<LogEvent> route(std::vector<LogEvent> now, const FaultDecision& decision, FaultCounts& counts);
  bool draw(double fraction);
  void corrupt(LogEvent& e);
  bool makeNanPoints(LogEvent& e);

  std::vector<Fault> faults_;
  std::mt19937_64 rng_;
  std::map<std::string, FaultCounts> counts_;
  std::map<std::string, LogEvent> held_;  // reorder: held until the channel's next message
  std::priority_queue<Delayed, std::vector<Delayed>, std::greater<Delayed>> delayed_;
  uint64_t order_ = 0;
};

/// Adds `delta_us` to the utime of an encoded project message whose first field is utime
/// (imu, point cloud, image, wheel, pose, odometry, ...). False if the type has no leading utime.
bool shiftMessageUtime(std::vector<uint8_t>& data, int64_t delta_us);

}  // namespace livo::playback
