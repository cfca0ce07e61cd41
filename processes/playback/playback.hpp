// livo-playback: replays an LCM log in real time (any speed) or in lockstep with the pipeline,
// optionally through the fault injector, onto a bus or into another log.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fault_injector.hpp"
#include "log_source.hpp"

namespace lcm {
class LCM;
}

namespace livo {

struct PlaybackOptions {
  std::string log;
  LogSourceOptions source;
  double speed = 1.0;                   // real-time factor; 0 = as fast as possible
  bool lockstep = false;
  std::vector<std::string> consumers;   // nodes to wait for at the start (and, lockstep, always)
  std::string progress_channel = "PROGRESS";
  double stall_timeout_s = 30.0;        // lockstep: no progress for this long = a stalled consumer
  double startup_timeout_s = 30.0;      // lockstep: time for every consumer to report once
  std::vector<Fault> faults;
  uint64_t seed = 1;
  std::string out_log;                  // write the (faulted) stream here instead of publishing
  bool quiet = false;
};

struct PlaybackResult {
  int64_t published = 0;
  double log_seconds = 0.0;
  double wall_seconds = 0.0;
  std::string error;                    // empty on success
};

/// Runs the replay to the end (or until SIGINT/SIGTERM). `lcm` may be null when out_log is set.
PlaybackResult runPlayback(const PlaybackOptions& options, lcm::LCM* lcm);

/// In-process replay for tests on memq://: publishes each event and lets every handler on `lcm`
/// run to completion before the next (lockstep by construction). Returns events published.
int64_t replayInProcess(LogSource& source, lcm::LCM& lcm, FaultInjector* faults = nullptr);

}  // namespace livo
