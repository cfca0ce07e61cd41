// When a node checked its receive queue (progress_t.idle_checked_us), on playback's clock.
//
// The node reads its own CLOCK_MONOTONIC, whose origin is its host's boot: on the playback's host
// the two clocks agree, on another host they differ by an unknown offset (and drift apart by a few
// parts per million). Every report bounds that offset: it was received after it was checked, so
// (received - checked) is the offset plus the delivery time. Per node instance the smallest such
// difference seen is kept, and checked + it is the estimate: never later than the report's receipt,
// and later than the true check by at most the quickest delivery seen from that node (micro- to
// milliseconds on a LAN, against the 3 s of LockstepGateOptions::loss_grace_s). Clock drift only
// makes it earlier (a loss is then found later, never one that is none).
#pragma once

#include <algorithm>
#include <cstdint>
#include <map>
#include <string>
#include <utility>

namespace livo::playback {

class SenderClocks {
 public:
  /// The check at `checked_s` (the sender's clock, seconds) of a report received at `received_s`
  /// (ours), on our clock.
  double toLocal(const std::string& node, int64_t instance, double checked_s, double received_s) {
    const double difference = received_s - checked_s;
    auto [it, is_new] = offset_.try_emplace({node, instance}, difference);
    if (!is_new) it->second = std::min(it->second, difference);
    return checked_s + it->second;
  }

 private:
  std::map<std::pair<std::string, int64_t>, double> offset_;  // (node, instance) -> smallest difference
};

}  // namespace livo::playback
