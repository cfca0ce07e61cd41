// Decides when the pipeline is idle, from the PROGRESS messages of its nodes: for every channel,
// each listed consumer has taken as many messages as were published on it by playback and by
// every node. Knows nothing of LCM or clocks; the caller feeds it progress and asks.
#pragma once

#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "livo/progress_t.hpp"

namespace livo {

class LockstepGate {
 public:
  explicit LockstepGate(std::vector<std::string> consumers);

  /// Records a node's PROGRESS (only the newest sequence of each node counts). Returns true if
  /// it moved anything on (a count changed, or the node is new or finished), false for a
  /// heartbeat that repeats what was known: a stalled node keeps sending those.
  bool onProgress(const progress_t& p);
  /// Playback published one more message on `channel`.
  void onPublished(const std::string& channel) { ++playback_published_[channel]; }

  /// Every consumer has reported at least once.
  bool allPresent() const;
  std::vector<std::string> missing() const;
  /// Consumers that reported `finished` (they exited).
  std::vector<std::string> finished() const;
  /// The pipeline has handled everything published so far.
  bool idle() const;
  /// What the pipeline is still waiting for, e.g. "lio: LIDAR 41/42" (for stall reports).
  std::string pendingDescription() const;

 private:
  struct NodeState {
    int64_t sequence = -1;
    bool finished = false;
    std::map<std::string, int64_t> handled;
    std::map<std::string, int64_t> published;
  };
  int64_t totalPublished(const std::string& channel) const;

  std::vector<std::string> consumers_;
  std::map<std::string, NodeState> nodes_;          // every node seen, listed or not
  std::map<std::string, int64_t> playback_published_;
};

}  // namespace livo
