// The node framework every process is built on: typed subscriptions that count decode failures
// instead of dying, per-channel processing-time statistics, PROGRESS for lockstep replay, HEALTH,
// and a spin loop with clean shutdown on SIGINT/SIGTERM.
//
// A process is a node class holding a livo::Node; main() parses the command line, builds the
// node on an lcm::LCM (udpm:// on a bus, memq:// in tests) and calls livo::spin().
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <functional>
#include <iosfwd>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "livo/channel_stats_t.hpp"
#include "livo/health_t.hpp"
#include "livo/latency_stats.hpp"

namespace livo {

struct NodeOptions {
  std::string name;  // unique on the bus; PROGRESS and HEALTH carry it
  std::string progress_channel = "PROGRESS";
  std::string health_channel = "HEALTH";
  double health_period_s = 1.0;  // wall-clock period of HEALTH messages; 0 disables
  bool publish_progress = true;  // a PROGRESS message after every handled input
  bool quiet = false;            // no summary on stderr at shutdown
  // Test hook for loss detection: messages on these channels with these 1-based indices are
  // dropped on arrival as if the bus had lost them (never handled, never counted). Filled from
  // LIVO_TEST_DROP_RECEIVED="CHANNEL:N[,CHANNEL:N...]" when the node is made; empty otherwise.
  std::map<std::string, std::set<int64_t>> drop_received = {};
  // Test hook for real-time hand-off tests: before each handler of another process's message (not of
  // sensor input: imu, point cloud, image, wheel, pose), sleep a random 0..N ms (uniform, seeded by the
  // node name). 0 disables it. Default: LIVO_TEST_HANDLER_DELAY_MS (handlerDelayFromEnvironment()).
  int handler_delay_max_ms = handlerDelayFromEnvironment();

  /// LIVO_TEST_HANDLER_DELAY_MS as a number of milliseconds (0 if unset or empty); throws
  /// std::invalid_argument naming the variable for anything but an integer in [0, 10000].
  static int handlerDelayFromEnvironment();
};

/// Parses "CHANNEL:N[,CHANNEL:N...]" (LIVO_TEST_DROP_RECEIVED); throws std::invalid_argument.
std::map<std::string, std::set<int64_t>> parseDropReceived(const std::string& spec);

class Node {
 public:
  Node(lcm::LCM& lcm, NodeOptions options);
  Node(const Node&) = delete;
  Node& operator=(const Node&) = delete;
  ~Node();

  /// Subscribes with a typed handler. A message that fails to decode is counted and reported,
  /// never passed on; an exception from the handler is counted as a rejected message.
  template <class Msg>
  void subscribe(const std::string& channel, std::function<void(const Msg&)> handler) {
    subscribeRaw(channel, [this, channel, handler = std::move(handler)](const void* data, int size) {
      Msg msg;
      if (msg.decode(data, 0, size) != size) {
        decodeFailed(channel, Msg::getTypeName(), size);
        return;
      }
      if constexpr (hasUtime<Msg>(0)) noteSensorTime(msg.utime);
      handler(msg);
    });
  }

  /// Subscribes to raw bytes; processing time and PROGRESS are still accounted.
  void subscribeRaw(const std::string& channel, std::function<void(const void*, int)> handler);

  template <class Msg>
  void publish(const std::string& channel, const Msg& msg) {
    // encoded into a buffer kept between messages, not a fresh one for every cloud
    const int size = msg.getEncodedSize();
    if (publish_buffer_.size() < static_cast<size_t>(size)) publish_buffer_.resize(static_cast<size_t>(size));
    if (msg.encode(publish_buffer_.data(), 0, size) != size) {
      error("cannot encode a " + std::string(Msg::getTypeName()) + " for " + channel + "; not published");
      return;
    }
    publishRaw(channel, publish_buffer_.data(), size);
  }
  void publishRaw(const std::string& channel, const void* data, int size);
  /// Declares an output channel so that PROGRESS lists it (with 0) before its first message.
  void declareOutput(const std::string& channel) { published_.emplace(channel, 0); }

  /// Records the duration of a unit of work that is not one message's handler, e.g. a LiDAR sweep
  /// processed when the IMU watermark passes it. It is reported (HEALTH, timing.json) as the
  /// pseudo-channel "work:<what>", not in PROGRESS.
  void recordWork(const std::string& what, double seconds);

  /// The current message on `channel` was refused (bad stamp, NaN, ...): counted, and reported
  /// on stderr and HEALTH (each distinct reason at most once per second of wall time).
  void reject(const std::string& channel, const std::string& why);
  void info(const std::string& message);
  void warn(const std::string& message);
  void error(const std::string& message);

  /// Watches the other nodes' PROGRESS for subscribers of `channel` (e.g. is a VIO there to answer
  /// STATE_PRIOR?). A node counts from its first PROGRESS (spin() announces at start) until it
  /// finishes or has not been heard for stale_s of wall time (a dead process). Watching does not
  /// count as an input: it adds nothing to this node's PROGRESS. With `answer_channel`, only a node
  /// that also lists it among its outputs counts (lio: a VIO publishes STATE_POSTERIOR, declared at
  /// start; a recorder of STATE_PRIOR answers nothing).
  void watchConsumers(const std::string& channel, double stale_s = 3.0, const std::string& answer_channel = "");
  /// Whether a live node other than this one subscribes to a watched channel (and publishes its
  /// answer channel, if one was given).
  bool hasConsumers(const std::string& channel) const;

  /// A node's promise to lockstep playback (progress_t.quiet_*): messages on `channel` stamped in
  /// [from, before) make it publish nothing, from its current state.
  struct QuietWindow {
    std::string channel;
    int64_t from = 0;
    int64_t before = 0;
    /// Every message on the channel, whatever its stamp and whoever publishes it.
    static QuietWindow always(std::string channel) {
      return {std::move(channel), std::numeric_limits<int64_t>::min(), std::numeric_limits<int64_t>::max()};
    }
  };
  /// Asked for the promises whenever PROGRESS is published (after every handled message), so that
  /// they always match the counts they go out with. None: no promise now.
  void setQuietWindows(std::function<std::vector<QuietWindow>()> promises) { quiet_windows_ = std::move(promises); }

  /// Under spin(): a PROGRESS after a handled input goes out only once nothing more waits in the
  /// receive queue (or after kMaxProgressDeferred inputs), one for a burst instead of one per
  /// message: every process wakes for every datagram on a udpm bus. Off by default (tests that
  /// drive handle() themselves get one PROGRESS per input).
  void setCoalesceProgress(bool on) { coalesce_progress_ = on; }
  /// Publishes a PROGRESS put off by coalescing once the receive queue is empty (spin() calls it).
  void flushProgress();
  static constexpr int kMaxProgressDeferred = 32;

  /// Publishes a PROGRESS with zero counts so lockstep playback knows the node is up and
  /// subscribed; spin() calls it first.
  void announce();
  /// Publishes HEALTH (and a heartbeat PROGRESS) if its period elapsed; spin() calls it.
  void tick();
  /// Publishes HEALTH at once, so that an event a report must not miss (an odometry reset) is not
  /// replaced by a later warning before the next periodic HEALTH.
  void publishHealthNow() { publishHealth(); }
  /// Final PROGRESS (finished = 1) and HEALTH, and the summary on stderr. Idempotent.
  void finish();

  std::vector<channel_stats_t> channelStats() const;
  /// The HEALTH message this node would publish now.
  health_t healthMessage() const;
  void printSummary(std::ostream& os) const;
  int64_t handled(const std::string& channel) const;
  int64_t published(const std::string& channel) const;
  int64_t decodeFailures() const;
  int64_t lastSensorTime() const { return last_utime_; }
  void noteSensorTime(int64_t utime) { last_utime_ = utime; }
  const std::string& name() const { return options_.name; }
  lcm::LCM& lcm() { return lcm_; }

 private:
  struct Subscription {
    Node* node;
    std::string channel;
    std::function<void(const void*, int)> handler;
    LatencyStats latency;
    int64_t handled = 0;
    int64_t arrived = 0;  // including messages dropped by the drop_received test hook
    int64_t decode_failures = 0;
    int64_t rejected = 0;
  };
  static void dispatch(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Subscription* sub);
  static void onPeerProgress(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Node* node);
  template <class M>
  static constexpr auto hasUtime(int) -> decltype(std::declval<M>().utime, bool()) {
    return true;
  }
  template <class M>
  static constexpr bool hasUtime(...) {
    return false;
  }

  void decodeFailed(const std::string& channel, const char* type, int size);
  void report(int8_t level, const std::string& message);
  bool rateLimited(const std::string& key);
  void publishProgress(bool finished);
  void publishHealth();
  Subscription* find(const std::string& channel) const;

  lcm::LCM& lcm_;
  NodeOptions options_;
  std::deque<Subscription> subs_;  // stable addresses for LCM's callbacks
  std::vector<lcm::Subscription*> lcm_subs_;
  std::map<std::string, int64_t> published_;
  std::map<std::string, int64_t> published_bytes_;
  std::vector<uint8_t> publish_buffer_;
  std::chrono::steady_clock::time_point last_trim_ = std::chrono::steady_clock::now();
  std::map<std::string, LatencyStats> work_;
  /// Nothing is waiting in the LCM receive queue (the provider's descriptor is not readable).
  bool receiveQueueEmpty();

  int64_t progress_sequence_ = 0;
  bool coalesce_progress_ = false;
  int progress_deferred_ = 0;  // inputs handled since the last PROGRESS
  std::function<std::vector<QuietWindow>()> quiet_windows_;
  int64_t instance_ = 0;  // this start of the node (progress_t.instance)
  int64_t last_utime_ = 0;
  int8_t level_ = 0;
  std::string last_event_;
  std::map<std::string, std::chrono::steady_clock::time_point> last_report_;
  std::chrono::steady_clock::time_point last_health_;
  bool finished_ = false;
  Subscription* current_ = nullptr;  // subscription whose handler is running
  struct Watch {
    double stale_s;
    std::string answer_channel;  // empty: any subscriber counts
    std::map<std::string, std::chrono::steady_clock::time_point> consumers;  // node -> last heard
  };
  std::map<std::string, Watch> watched_;  // channel -> its consumers
  lcm::Subscription* peer_sub_ = nullptr;
  std::mt19937 handler_delay_rng_;  // seeded by the node name (handler_delay_max_ms)
  // LIVO_LATENCY_TRACE=FILE (real-time runs, livo-report's latency): a line per published message
  // with its stamp, the input whose handler published it, when that input was received (LCM's
  // recv_utime), when its handler started and when the message went out (wall clock, µs).
  std::FILE* trace_ = nullptr;
  int64_t current_recv_us_ = 0, current_start_us_ = 0, current_utime_ = -1;
  void tracePublish(const std::string& channel, const void* data, int size);
};

/// Sets the shutdown flag on SIGINT/SIGTERM (idempotent).
void installSignalHandlers();
void requestShutdown();
bool shutdownRequested();

/// Handles messages until shutdown is requested or `done()` returns true, calling node.tick()
/// between messages; then calls `on_shutdown` (flush outputs) and node.finish().
/// Returns 0, or 1 if the LCM provider failed.
int spin(lcm::LCM& lcm, Node& node, const std::function<void()>& on_shutdown = {},
         const std::function<bool()>& done = {});

/// glibc: large blocks (clouds, images) from the heap, reused between messages, instead of fresh
/// mapped pages for each (node.cpp says why, and how memory is still given back). Every Node does
/// it; a process without one (livo-playback) calls it at its start.
void keepLargeBlocksOnHeap();

/// Creates an LCM instance on `url` (empty: LCM_DEFAULT_URL or LCM's default) or throws.
std::unique_ptr<lcm::LCM> makeLcm(const std::string& url);

}  // namespace livo
