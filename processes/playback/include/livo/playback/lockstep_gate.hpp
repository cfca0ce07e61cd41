// Decides when the pipeline is idle, from the PROGRESS messages of its nodes: for every channel,
// each listed consumer has taken as many messages as were published on it by playback and by
// every node. Knows nothing of LCM or clocks: the caller feeds it progress with the wall time
// (seconds, any origin) and asks.
//
// Three things a UDP bus and real processes add to that count:
// - A lost message: a consumer that reports itself idle (nothing waiting in its queue) while it
//   still lacks messages published more than `loss_grace_s` ago never got them. They are counted
//   as lost for it (and reported), so the replay goes on instead of waiting for ever.
// - A stall: a (consumer, channel) whose handled count has not moved for a while although it is
//   behind; heartbeats and traffic on other channels do not hide it (stalledFor()).
// - A restart (tolerate_restarts): a consumer that exits or goes silent is not waited for until a
//   new instance of it reports; messages published while it was away are lost to it.
//
// Quiet promises (progress_t.quiet_*): a consumer may promise that messages on a channel stamped
// in a window make it publish nothing (lio: IMU samples before its next sweep end or image time),
// or any message on it (vio: REGISTERED_SCAN; CAMERA while no prior waits for an image).
// Playback then sends such messages without waiting for it: it handles them in order and nobody
// waits for an output of them, so every node sees what the serial replay shows it.
//
// Lagging consumers (options.may_lag): waiting for the whole pipeline after every message runs the
// processes one after another. A consumer whose outputs no other consumer acts on (colour, octomap,
// the recorder) may instead fall up to max_lag_messages behind while the others handle the next
// messages, on the second core. Its input order is unchanged: everything it takes comes from
// playback and from consumers that are kept in step, which publish in the one order of the serial
// replay, and the bus delivers each sender's messages in order. So its outputs are the serial
// replay's. Which may lag is decided from the PROGRESS topology, not trusted: a listed consumer
// whose declared outputs another consumer takes is kept in step (one taking its channel would see
// them at positions that depend on timing), except where the taker is a recorder (a consumer that
// publishes nothing: it keeps each channel's order, not the interleaving across channels).
#pragma once

#include <cmath>
#include <cstdint>
#include <deque>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "livo/progress_t.hpp"

namespace livo::playback {

struct LockstepGateOptions {
  double loss_grace_s = 3.0;          // an idle consumer still lacking a message this old lost it
  bool tolerate_restarts = false;     // consumers may exit and come back (supervised runs)
  double silent_after_s = 5.0;        // tolerate_restarts: a consumer not heard for this long is away
  double restart_wait_s = 30.0;       // tolerate_restarts: how long a consumer away is waited for
  bool honour_quiet_promises = true;  // false: wait for every consumer after every message
  std::vector<std::string> may_lag;   // consumers that may fall behind (see above)
  int max_lag_messages = 16;          // how far (messages not yet handled, all channels) they may,
  int64_t max_lag_bytes = 16 << 20;   // and in bytes (estimated from each channel's mean size): what
                                      // a sink's LCM receive thread queues for it (a 64-beam cloud
                                      // is ~3 MB, an RGB image ~1 MB)
};

class LockstepGate {
 public:
  explicit LockstepGate(std::vector<std::string> consumers, LockstepGateOptions options = {});

  /// Records a node's PROGRESS received at `now_s` (only the newest sequence of each instance
  /// counts). `idle_checked_s` is when the node checked its queue (progress_t.idle_checked_us on the
  /// caller's clock; NaN: unknown, taken as now_s): a report checked before a message was published
  /// says nothing about that message, however late it is received. Returns true if it moved
  /// anything on (a count changed, or the node is new, restarted or finished), false for a
  /// heartbeat that repeats what was known.
  bool onProgress(const progress_t& p, double now_s = 0.0, double idle_checked_s = std::nan(""));
  /// Playback published one more message on `channel` at `now_s`, stamped `utime` (the message's
  /// own; kNoUtime: unknown, never covered by a quiet promise), of `bytes`.
  static constexpr int64_t kNoUtime = INT64_MIN;
  void onPublished(const std::string& channel, double now_s = 0.0, int64_t utime = kNoUtime, int64_t bytes = 0);
  /// tolerate_restarts: marks consumers not heard for silent_after_s as away (call periodically).
  void checkSilent(double now_s);

  /// Every consumer has reported at least once.
  bool allPresent() const;
  std::vector<std::string> missing() const;
  /// Consumers that reported `finished` (they exited) and have not come back.
  std::vector<std::string> finished() const;
  /// The pipeline has handled everything published so far (consumers away are not waited for).
  bool idle() const;
  /// The next message may go out: every consumer kept in step has handled everything but messages
  /// its quiet promise covers, and every lagging one is at most max_lag_messages behind.
  bool caughtUp() const;
  /// Whether the next message, on `channel` and stamped `utime`, may go out now. As caughtUp(),
  /// with two refinements that need to know the message:
  /// - A message that is not quiet for a consumer waits until it has handled what nodes published
  ///   to it (those arrive from other senders, so in no fixed order with the message).
  /// - An answer in flight: a consumer still working on messages that are not quiet (vio on a
  ///   STATE_PRIOR) need not be waited for while (1) it does not take the message, (2) the
  ///   message is quiet for every consumer in step that takes it (it makes nobody publish), and
  ///   (3) every consumer that takes one of its outputs is a recorder or a consumer in step,
  ///   itself not working on anything but quiet messages, that promises that output quiet for
  ///   any stamp (lio, while it waits for a posterior, promises STATE_POSTERIOR: it only adopts
  ///   it; its effect commutes with the quiet IMU samples around it). While an answer is in flight
  ///   nothing but it is published, so every consumer sees its inputs in the serial replay's order
  ///   (the answer's place among quiet messages aside, which its takers promised not to matter).
  bool mayPublish(const std::string& channel, int64_t utime) const;
  /// The consumers allowed to lag now: listed in may_lag, reported, and whose outputs are taken by
  /// no consumer but recorders.
  const std::vector<std::string>& lagging() const { return lagging_; }
  /// tolerate_restarts: a consumer went away less than restart_wait_s ago and has not come back
  /// (lockstep holds the replay so that it misses as little as possible).
  bool awaitingRestart(double now_s) const;
  /// What the pipeline is still waiting for, e.g. "lio: LIDAR 41/42" (for stall reports).
  std::string pendingDescription() const;
  /// The longest time a consumer has been behind on a channel without its count moving.
  double stalledFor(double now_s) const;

  /// Events worth telling the user (losses, consumers away and back), oldest first; taking them
  /// empties the list.
  std::vector<std::string> takeEvents();
  /// Messages counted as lost, per "consumer: channel".
  const std::map<std::string, int64_t>& lost() const { return lost_total_; }
  int64_t lostMessages() const;
  int restarts() const { return restarts_; }

 private:
  struct NodeState {
    int64_t instance = 0;
    int64_t sequence = -1;
    bool finished = false;
    bool away = false;  // exited or silent, waiting for a new instance
    double away_since_s = 0.0;
    double last_heard_s = 0.0;
    std::map<std::string, int64_t> handled;
    std::map<std::string, int64_t> published;
    std::map<std::string, int64_t> published_bytes;
    std::map<std::string, int64_t> published_before;  // by earlier instances of this node
    std::map<std::string, int64_t> published_bytes_before;
    std::map<std::string, int64_t> offset;                     // counted as handled: lost, or published while away
    std::map<std::string, std::pair<int64_t, int64_t>> quiet;  // the newest PROGRESS's promises
  };
  struct Waiting {
    int64_t handled = 0;
    double since_s = 0.0;
  };
  /// A new instance of a known node (it restarted): its counts start again, what was published
  /// while it was away is counted as lost to it.
  void startNewInstance(const progress_t& p, NodeState& n);
  /// Takes the report's quiet promises and counts; true if a count changed.
  bool recordCounts(const progress_t& p, NodeState& n, double now_s);
  /// The node exited (tolerate_restarts: a consumer is away until a new instance reports).
  void noteFinished(const std::string& node, NodeState& n, double now_s);
  int64_t totalPublished(const std::string& channel) const;  // known_total_: kept up to date
  int64_t countPublished(const std::string& channel) const;  // summed over playback and the nodes
  /// Messages on `channel` published at or before `t_s`.
  int64_t publishedBy(const std::string& channel, double t_s) const;
  int64_t deficit(const NodeState& n, const std::string& channel) const;
  void notePublished(const std::string& channel, double now_s);
  void detectLosses(const std::string& node, NodeState& n, double idle_at_s);
  void updateWaiting(double now_s);
  bool isConsumer(const std::string& node) const;
  /// Why a consumer listed in may_lag is kept in step ("" if it may lag).
  std::string keptInStepBecause(const std::string& node) const;
  int64_t behind(const NodeState& n) const;       // messages not yet handled, all channels
  int64_t behindBytes(const NodeState& n) const;  // their bytes, at each channel's mean size
  /// The consumer's unhandled messages on `channel` are all playback's and inside its promise.
  bool promisedQuiet(const NodeState& n, const std::string& channel) const;
  /// It has unhandled messages no promise covers (it is working on something that may publish).
  bool busyLoudly(const NodeState& n) const;
  /// Its promise covers a message on `channel` stamped `utime` (any stamp: a whole-channel promise).
  bool quietFor(const NodeState& n, const std::string& channel, int64_t utime, bool whole_channel = false) const;
  /// It has unhandled messages on a channel nodes publish (they race with playback's messages).
  bool awaitsNodeMessages(const NodeState& n) const;
  bool isLagging(const std::string& node) const;
  /// mayPublish's answer-in-flight rule for consumer `c` (see there).
  bool answerMayBeInFlight(const std::string& c, const NodeState& n, const std::string& channel, int64_t utime) const;
  void noteLagDecisions();

  std::vector<std::string> consumers_;
  LockstepGateOptions options_;
  std::map<std::string, NodeState> nodes_;  // every node seen, listed or not
  std::map<std::string, int64_t> playback_published_;
  std::map<std::string, int64_t> playback_bytes_;
  std::map<std::string, std::deque<std::pair<int64_t, int64_t>>> playback_utimes_;  // channel -> (index, utime), newest
  std::map<std::string, int64_t> known_total_;                                      // channel -> total seen so far
  std::map<std::string, std::deque<std::pair<int64_t, double>>> reached_at_;        // channel -> (total, time)
  std::map<std::pair<std::string, std::string>, Waiting> waiting_;                  // (consumer, channel)
  std::map<std::string, int64_t> lost_total_;
  std::vector<std::string> events_;
  std::vector<std::string> lagging_;                 // lagging(), worked out when the topology changes
  std::map<std::string, std::string> lag_decision_;  // may_lag consumer -> "" or why in step (last told)
  int restarts_ = 0;
};

}  // namespace livo::playback
