#include "livo/node.hpp"

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <poll.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#include <cerrno>
#include <cstring>
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "livo/health_t.hpp"
#include "livo/image_t.hpp"
#include "livo/imu_t.hpp"
#include "livo/message_registry.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/pose_t.hpp"
#include "livo/progress_t.hpp"
#include "livo/wheel_odometry_t.hpp"

namespace livo {

namespace {
std::atomic<bool> g_shutdown{false};
extern "C" void onSignal(int) { g_shutdown.store(true); }
}  // namespace

void installSignalHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  sigemptyset(&sa.sa_mask);
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}
void requestShutdown() { g_shutdown.store(true); }
bool shutdownRequested() { return g_shutdown.load(); }

std::map<std::string, std::set<int64_t>> parseDropReceived(const std::string& spec) {
  std::map<std::string, std::set<int64_t>> out;
  std::stringstream ss(spec);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    const size_t colon = item.rfind(':');
    char* end = nullptr;
    const long long n = colon == std::string::npos ? 0 : std::strtoll(item.c_str() + colon + 1, &end, 10);
    if (colon == std::string::npos || colon == 0 || n < 1 || *end != '\0')
      throw std::invalid_argument("LIVO_TEST_DROP_RECEIVED: '" + item + "' is not CHANNEL:N with N >= 1");
    out[item.substr(0, colon)].insert(n);
  }
  return out;
}

int NodeOptions::handlerDelayFromEnvironment() {
  const char* value = std::getenv("LIVO_TEST_HANDLER_DELAY_MS");
  if (!value || !*value) return 0;
  char* end = nullptr;
  const long ms = std::strtol(value, &end, 10);
  if (*end != '\0' || ms < 0 || ms > 10000)
    throw std::invalid_argument(std::string("LIVO_TEST_HANDLER_DELAY_MS='") + value +
                                "': expected whole milliseconds in [0, 10000]");
  return static_cast<int>(ms);
}

void keepLargeBlocksOnHeap() {
#if defined(__GLIBC__)
  // Blocks up to 32 MB (clouds, images, key sets, map arrays) come from the heap and are reused
  // from message to message, and the top of the heap is not given back after every large free:
  // mapping each large block on its own costs fresh zeroed pages, faulted in one by one, for every
  // cloud and image (a fifth of lio's time, a sixth of vio's and colour's). Over an hours-long run
  // of varying sizes the heap fragments instead, and resident memory crept up although nothing
  // was kept (issue 16's soak): Node::tick() hands the free pages back every few seconds.
  mallopt(M_MMAP_THRESHOLD, 32 << 20);
  mallopt(M_TRIM_THRESHOLD, 64 << 20);
#endif
}

Node::Node(lcm::LCM& lcm, NodeOptions options) : lcm_(lcm), options_(std::move(options)) {
  if (options_.name.empty()) throw std::invalid_argument("livo::Node needs a name");
  keepLargeBlocksOnHeap();
  if (options_.handler_delay_max_ms < 0) throw std::invalid_argument("livo::Node: handler_delay_max_ms < 0");
  // FNV-1a of the name: the same delays for the same node in every run (std::hash is not portable)
  uint32_t seed = 2166136261u;
  for (unsigned char ch : options_.name) seed = (seed ^ ch) * 16777619u;
  handler_delay_rng_.seed(seed);
  if (options_.handler_delay_max_ms > 0)
    std::cerr << "[" << options_.name << "] test hook: up to " << options_.handler_delay_max_ms
              << " ms random delay before each handler of another process's message" << std::endl;
  last_health_ = std::chrono::steady_clock::now();
  if (const char* drop = std::getenv("LIVO_TEST_DROP_RECEIVED"); drop && options_.drop_received.empty())
    options_.drop_received = parseDropReceived(drop);
  // Unique per start: wall clock in ns mixed with the process id.
  instance_ = std::chrono::system_clock::now().time_since_epoch().count() ^ (static_cast<int64_t>(getpid()) << 40);
  if (const char* trace = std::getenv("LIVO_LATENCY_TRACE"); trace && *trace) {
    trace_ = std::fopen(trace, "a");  // a restarted process goes on in the same file
    if (!trace_) throw std::runtime_error(std::string("LIVO_LATENCY_TRACE: cannot write ") + trace);
    std::setvbuf(trace_, nullptr, _IOLBF, 0);  // whole lines, even if the process is killed
  }
}

Node::~Node() {
  // Subscriptions point into subs_: unsubscribe before it goes away (the LCM may outlive us).
  for (auto* s : lcm_subs_) lcm_.unsubscribe(s);
  if (peer_sub_) lcm_.unsubscribe(peer_sub_);
  if (trace_) std::fclose(trace_);
}

void Node::watchConsumers(const std::string& channel, double stale_s, const std::string& answer_channel) {
  watched_[channel].stale_s = stale_s;
  watched_[channel].answer_channel = answer_channel;
  if (!peer_sub_) peer_sub_ = lcm_.subscribeFunction(options_.progress_channel, &Node::onPeerProgress, this);
}

void Node::onPeerProgress(const lcm::ReceiveBuffer* rbuf, const std::string&, Node* node) {
  progress_t p;
  if (p.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) != static_cast<int>(rbuf->data_size)) return;
  if (p.node == node->options_.name) return;
  const auto now = std::chrono::steady_clock::now();
  for (auto& [channel, watch] : node->watched_) {
    const bool consumes = std::find(p.input_channel.begin(), p.input_channel.end(), channel) != p.input_channel.end();
    const bool answers = watch.answer_channel.empty() ||
                         std::find(p.output_channel.begin(), p.output_channel.end(), watch.answer_channel) !=
                             p.output_channel.end();
    if (consumes && answers && !p.finished) {
      watch.consumers[p.node] = now;
    } else {
      watch.consumers.erase(p.node);
    }
  }
}

bool Node::hasConsumers(const std::string& channel) const {
  auto it = watched_.find(channel);
  if (it == watched_.end()) return false;
  const auto now = std::chrono::steady_clock::now();
  for (const auto& [name, heard] : it->second.consumers)
    if (std::chrono::duration<double>(now - heard).count() <= it->second.stale_s) return true;
  return false;
}

void Node::subscribeRaw(const std::string& channel, std::function<void(const void*, int)> handler) {
  subs_.push_back(Subscription{this, channel, std::move(handler), {}, 0, 0, 0});
  Subscription* sub = &subs_.back();
  lcm_subs_.push_back(lcm_.subscribeFunction(channel, &Node::dispatch, sub));
}

namespace {
// CLOCK_REALTIME in µs, the clock of LCM's recv_utime.
int64_t wallMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// Whether an encoded message is raw sensor input (its leading 8-byte type fingerprint, big-endian).
// The handler-delay test hook spares these: a node sleeping a mean N/2 ms per 200 Hz IMU message
// could not keep up in real time, and the kernel would drop most of the stream.
bool isSensorMessage(const void* data, size_t size) {
  if (size < 8) return false;
  const auto* b = static_cast<const uint8_t*>(data);
  uint64_t fingerprint = 0;
  for (int i = 0; i < 8; ++i) fingerprint = (fingerprint << 8) | b[i];
  for (int64_t sensor :
       {imu_t::getHash(), point_cloud_t::getHash(), image_t::getHash(), wheel_odometry_t::getHash(), pose_t::getHash()})
    if (fingerprint == static_cast<uint64_t>(sensor)) return true;
  return false;
}
}  // namespace

void Node::dispatch(const lcm::ReceiveBuffer* rbuf, const std::string&, Subscription* sub) {
  Node& node = *sub->node;
  ++sub->arrived;
  if (!node.options_.drop_received.empty()) {
    auto drop = node.options_.drop_received.find(sub->channel);
    if (drop != node.options_.drop_received.end() && drop->second.count(sub->arrived)) {
      std::cerr << "[" << node.options_.name << "] test hook: message " << sub->arrived << " on " << sub->channel
                << " dropped on arrival" << std::endl;
      return;
    }
  }
  if (node.options_.handler_delay_max_ms > 0 && !isSensorMessage(rbuf->data, rbuf->data_size)) {
    std::uniform_int_distribution<int> delay_ms(0, node.options_.handler_delay_max_ms);
    std::this_thread::sleep_for(std::chrono::milliseconds(delay_ms(node.handler_delay_rng_)));
  }
  node.current_ = sub;
  if (node.trace_) {
    node.current_recv_us_ = rbuf->recv_utime;
    node.current_start_us_ = wallMicros();
    if (!messageUtime(rbuf->data, static_cast<int>(rbuf->data_size), &node.current_utime_)) node.current_utime_ = -1;
  }
  const auto t0 = std::chrono::steady_clock::now();
  try {
    sub->handler(rbuf->data, static_cast<int>(rbuf->data_size));
  } catch (const std::exception& e) {
    node.reject(sub->channel, std::string("handler failed: ") + e.what());
  }
  const auto t1 = std::chrono::steady_clock::now();
  sub->latency.add(std::chrono::duration<double>(t1 - t0).count());
  ++sub->handled;
  node.current_ = nullptr;
  if (!node.options_.publish_progress) return;
  ++node.progress_deferred_;
  if (!node.coalesce_progress_ || node.progress_deferred_ >= kMaxProgressDeferred || node.receiveQueueEmpty())
    node.publishProgress(false);
}

void Node::flushProgress() {
  if (progress_deferred_ > 0 && options_.publish_progress && receiveQueueEmpty()) publishProgress(false);
}

void Node::publishRaw(const std::string& channel, const void* data, int size) {
  if (trace_) tracePublish(channel, data, size);
  lcm_.publish(channel, data, static_cast<unsigned int>(size));
  ++published_[channel];
  published_bytes_[channel] += size;
}

void Node::tracePublish(const std::string& channel, const void* data, int size) {
  int64_t utime = -1;
  if (!messageUtime(data, size, &utime)) utime = -1;
  // outside a handler (at shutdown): no input, "-"
  std::fprintf(trace_, "%s\t%lld\t%s\t%lld\t%lld\t%lld\t%lld\n", channel.c_str(), static_cast<long long>(utime),
               current_ ? current_->channel.c_str() : "-", static_cast<long long>(current_ ? current_utime_ : -1),
               static_cast<long long>(current_ ? current_recv_us_ : 0),
               static_cast<long long>(current_ ? current_start_us_ : 0), static_cast<long long>(wallMicros()));
}

Node::Subscription* Node::find(const std::string& channel) const {
  for (const auto& s : subs_)
    if (s.channel == channel) return const_cast<Subscription*>(&s);
  return nullptr;
}

void Node::decodeFailed(const std::string& channel, const char* type, int size) {
  if (Subscription* s = find(channel)) ++s->decode_failures;
  std::ostringstream os;
  os << "message on " << channel << " (" << size << " bytes) does not decode as " << type << "; dropped";
  if (!rateLimited("decode:" + channel)) report(health_t::LEVEL_WARN, os.str());
}

void Node::reject(const std::string& channel, const std::string& why) {
  if (Subscription* s = find(channel)) ++s->rejected;
  if (!rateLimited("reject:" + channel + why)) report(health_t::LEVEL_WARN, channel + ": " + why);
}

void Node::info(const std::string& message) {
  if (!options_.quiet) std::cerr << "[" << options_.name << "] " << message << std::endl;
}
void Node::warn(const std::string& message) { report(health_t::LEVEL_WARN, message); }
void Node::error(const std::string& message) { report(health_t::LEVEL_ERROR, message); }

bool Node::rateLimited(const std::string& key) {
  const auto now = std::chrono::steady_clock::now();
  auto it = last_report_.find(key);
  if (it != last_report_.end() && now - it->second < std::chrono::seconds(1)) return true;
  last_report_[key] = now;
  return false;
}

void Node::report(int8_t level, const std::string& message) {
  std::cerr << "[" << options_.name << "] " << (level == health_t::LEVEL_ERROR ? "error: " : "warning: ") << message
            << std::endl;
  level_ = std::max(level_, level);
  last_event_ = message;
}

void Node::publishProgress(bool finished) {
  progress_t p;
  p.utime = last_utime_;
  p.node = options_.name;
  p.sequence = progress_sequence_++;
  progress_deferred_ = 0;
  p.finished = finished ? 1 : 0;
  p.instance = instance_;
  p.idle = !finished && receiveQueueEmpty() ? 1 : 0;
  p.idle_checked_us =
      std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now().time_since_epoch())
          .count();
  for (const auto& s : subs_) {
    p.input_channel.push_back(s.channel);
    p.handled.push_back(s.handled);
  }
  p.num_inputs = static_cast<int32_t>(p.input_channel.size());
  for (const auto& [ch, n] : published_) {
    p.output_channel.push_back(ch);
    p.published.push_back(n);
    auto b = published_bytes_.find(ch);
    p.published_bytes.push_back(b == published_bytes_.end() ? 0 : b->second);
  }
  p.num_outputs = static_cast<int32_t>(p.output_channel.size());
  if (quiet_windows_ && !finished) {
    for (const QuietWindow& w : quiet_windows_()) {
      if (w.before <= w.from) continue;
      p.quiet_channel.push_back(w.channel);
      p.quiet_from.push_back(w.from);
      p.quiet_before.push_back(w.before);
    }
  }
  p.num_quiet = static_cast<int32_t>(p.quiet_channel.size());
  lcm_.publish(options_.progress_channel, &p);
}

bool Node::receiveQueueEmpty() {
  const int fd = lcm_.getFileno();
  if (fd < 0) return false;
  pollfd pfd{fd, POLLIN, 0};
  return ::poll(&pfd, 1, 0) == 0;
}

void Node::recordWork(const std::string& what, double seconds) { work_["work:" + what].add(seconds); }

std::vector<channel_stats_t> Node::channelStats() const {
  std::vector<channel_stats_t> out;
  for (const auto& [name, stats] : work_) {
    channel_stats_t c;
    c.channel = name;
    c.messages = stats.count();
    c.decode_failures = 0;
    c.rejected = 0;
    c.median_ms = stats.medianMs();
    c.p90_ms = stats.p90Ms();
    c.max_ms = stats.maxMs();
    out.push_back(c);
  }
  for (const auto& s : subs_) {
    channel_stats_t c;
    c.channel = s.channel;
    c.messages = s.handled;
    c.decode_failures = s.decode_failures;
    c.rejected = s.rejected;
    c.median_ms = s.latency.medianMs();
    c.p90_ms = s.latency.p90Ms();
    c.max_ms = s.latency.maxMs();
    out.push_back(c);
  }
  return out;
}

health_t Node::healthMessage() const {
  health_t h;
  h.utime = last_utime_;
  h.node = options_.name;
  h.level = level_;
  h.message = last_event_;
  h.peak_rss_mb = peakRssMb();
  h.channels = channelStats();
  h.num_channels = static_cast<int32_t>(h.channels.size());
  return h;
}

void Node::publishHealth() {
  const health_t h = healthMessage();
  lcm_.publish(options_.health_channel, &h);
  level_ = health_t::LEVEL_OK;
  last_event_.clear();
}

void Node::tick() {
  const auto now = std::chrono::steady_clock::now();
#if defined(__GLIBC__)
  if (now - last_trim_ >= std::chrono::seconds(2)) {  // the free pages back to the system (constructor)
    last_trim_ = now;
    malloc_trim(0);
  }
#endif
  if (options_.health_period_s <= 0.0) return;
  if (std::chrono::duration<double>(now - last_health_).count() >= options_.health_period_s) {
    last_health_ = now;
    publishHealth();
    if (options_.publish_progress) publishProgress(false);  // heartbeat: lockstep sees we are alive
  }
}

void Node::announce() {
  if (options_.publish_progress) publishProgress(false);
}

void Node::finish() {
  if (finished_) return;
  finished_ = true;
  publishProgress(true);
  publishHealth();
  if (!options_.quiet) printSummary(std::cerr);
}

int64_t Node::handled(const std::string& channel) const {
  const Subscription* s = find(channel);
  return s ? s->handled : 0;
}
int64_t Node::published(const std::string& channel) const {
  auto it = published_.find(channel);
  return it == published_.end() ? 0 : it->second;
}
int64_t Node::decodeFailures() const {
  int64_t n = 0;
  for (const auto& s : subs_) n += s.decode_failures;
  return n;
}

void Node::printSummary(std::ostream& os) const {
  os << "[" << options_.name << "] processing time per message (peak RSS " << std::fixed << std::setprecision(1)
     << peakRssMb() << " MB, CPU " << std::setprecision(2) << cpuSeconds() << " s):\n";
  os << "  " << std::left << std::setw(22) << "channel" << std::right << std::setw(9) << "messages" << std::setw(11)
     << "median ms" << std::setw(9) << "p90 ms" << std::setw(9) << "max ms" << std::setw(9) << "decode!"
     << std::setw(10) << "rejected"
     << "\n";
  for (const auto& c : channelStats()) {
    os << "  " << std::left << std::setw(22) << c.channel << std::right << std::setw(9) << c.messages
       << std::setprecision(3) << std::setw(11) << c.median_ms << std::setw(9) << c.p90_ms << std::setw(9) << c.max_ms
       << std::setw(9) << c.decode_failures << std::setw(10) << c.rejected << "\n";
  }
  for (const auto& [ch, n] : published_) os << "  published " << ch << ": " << n << "\n";
  os << "  published " << options_.progress_channel << ": " << progress_sequence_ << "\n";
  os.flush();
}

namespace {
// LIVO_HANDLER_NICE=N: the thread that handles messages runs at niceness N, while LCM's receive
// thread (started with the first subscription) keeps the process's own. A lagging sink niced as a
// whole lets the bus fill its socket while it waits for a core, and the kernel then drops what the
// pipeline sends; niced this way it still drains the socket at once and only its work waits.
void niceTheHandlerThread(Node& node) {
  const char* value = std::getenv("LIVO_HANDLER_NICE");
  if (!value || !*value) return;
  char* end = nullptr;
  const long n = std::strtol(value, &end, 10);
  if (*end != '\0' || n < 0 || n > 19) {
    node.warn(std::string("LIVO_HANDLER_NICE='") + value + "': expected 0 to 19; ignored");
    return;
  }
  // on Linux the nice value belongs to the thread: this one only
  if (setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), static_cast<int>(n)) != 0)
    node.warn(std::string("LIVO_HANDLER_NICE: setpriority failed: ") + std::strerror(errno));
}
}  // namespace

int spin(lcm::LCM& lcm, Node& node, const std::function<void()>& on_shutdown, const std::function<bool()>& done) {
  installSignalHandlers();
  niceTheHandlerThread(node);
  node.setCoalesceProgress(true);
  node.announce();
  int rc = 0;
  while (!shutdownRequested() && !(done && done())) {
    const int r = lcm.handleTimeout(100);
    if (r < 0 && shutdownRequested()) break;  // a signal interrupted the wait
    if (r < 0) {
      node.error("LCM provider failed; shutting down");
      rc = 1;
      break;
    }
    node.flushProgress();
    node.tick();
  }
  if (on_shutdown) on_shutdown();
  node.finish();
  return rc;
}

std::unique_ptr<lcm::LCM> makeLcm(const std::string& url) {
  auto lcm = std::make_unique<lcm::LCM>(url);
  if (!lcm->good()) {
    throw std::runtime_error("cannot open the LCM bus '" + (url.empty() ? std::string("$LCM_DEFAULT_URL") : url) +
                             "' (on a machine without multicast routing use scripts/private_bus.sh)");
  }
  return lcm;
}

}  // namespace livo
