// livo-playback: replays an LCM log in real time (any speed) or in lockstep with the pipeline,
// optionally through the fault injector, onto a bus or into another log.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "livo/playback/fault_injector.hpp"
#include "livo/playback/log_source.hpp"

namespace lcm {
class LCM;
}

namespace livo::playback {

struct PlaybackOptions {
  std::string log;
  LogSourceOptions source;
  double speed = 1.0;  // real-time factor; 0 = as fast as possible
  bool lockstep = false;
  std::vector<std::string> consumers;  // nodes to wait for at the start (and, lockstep, always)
  std::string progress_channel = "PROGRESS";
  double stall_timeout_s = 30.0;     // lockstep: a consumer behind on a channel whose count has
                                     // not moved for this long = a stall (heartbeats do not count)
  double loss_grace_s = 3.0;         // lockstep: an idle consumer lacking a message published this
                                     // long ago lost it on the bus (reported, then not waited for)
  bool respawn = false;              // lockstep: consumers may exit and be restarted (supervised
                                     // runs); not waited for while away
  double startup_timeout_s = 30.0;   // lockstep: time for every consumer to report once
  bool serial = false;               // lockstep: wait for every consumer after every message (no
                                     // quiet promises, nothing lags): the reference order
  std::vector<std::string> may_lag;  // lockstep: consumers that may fall behind by up to max_lag
  int max_lag_messages = 16;         // messages, while the rest handle the next ones (lockstep_gate.hpp)
  int64_t max_lag_bytes = 16 << 20;  // and bytes (at each channel's mean message size)
  std::vector<Fault> faults;
  uint64_t seed = 1;
  std::string out_log;     // write the (faulted) stream here instead of publishing
  std::string clock_file;  // keep the log seconds replayed so far in this file (supervisors)
  bool quiet = false;
};

/// Lockstep: the wall time playback spent waiting after the messages of one channel, and which
/// consumer's PROGRESS ended each wait (the one the replay was waiting for last): where the
/// critical path of a lockstep replay runs.
struct LockstepWaits {
  int64_t messages = 0;  // published on the channel
  int64_t waited = 0;    // after which playback had to wait
  double seconds = 0.0;
  std::map<std::string, double> seconds_by_last;  // consumer whose report ended the wait -> seconds
};

struct PlaybackResult {
  int64_t published = 0;
  double log_seconds = 0.0;
  double wall_seconds = 0.0;
  std::string error;                           // empty on success
  int64_t lost = 0;                            // lockstep: messages consumers never received (bus losses)
  int restarts = 0;                            // lockstep with respawn: consumers that came back
  int64_t not_waited = 0;                      // lockstep: messages after which the next went out at once
                                               // (quiet promises, lagging consumers), not after the whole
                                               // pipeline had handled them
  std::map<std::string, LockstepWaits> waits;  // lockstep: per channel
};

/// One line per channel, longest wait first ("LIDAR: 300 of 300 waited for, 2.10 s (lio 1.80,
/// vio 0.30)"); at most `max_lines`.
std::vector<std::string> describeWaits(const std::map<std::string, LockstepWaits>& waits, size_t max_lines = 8);

/// Runs the replay to the end (or until SIGINT/SIGTERM). `lcm` may be null when out_log is set.
PlaybackResult runPlayback(const PlaybackOptions& options, lcm::LCM* lcm);

/// In-process replay for tests on memq://: publishes each event and lets every handler on `lcm`
/// run to completion before the next (lockstep by construction). Returns events published.
int64_t replayInProcess(LogSource& source, lcm::LCM& lcm, FaultInjector* faults = nullptr);

}  // namespace livo::playback
