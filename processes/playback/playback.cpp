#include "playback.hpp"

#include <chrono>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include "livo/node.hpp"
#include "lockstep_gate.hpp"

namespace livo {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Where replayed events go: the bus, or a log file.
class EventSink {
 public:
  EventSink(lcm::LCM* lcm, const std::string& out_log) : lcm_(lcm) {
    if (!out_log.empty()) {
      file_ = std::make_unique<lcm::LogFile>(out_log, "w");
      if (!file_->good()) throw std::runtime_error(out_log + ": cannot write");
    }
  }
  void emit(const LogEvent& e) {
    if (file_) {
      lcm::LogEvent ev;
      ev.timestamp = e.utime;
      ev.channel = e.channel;
      ev.datalen = static_cast<int32_t>(e.data.size());
      ev.data = const_cast<uint8_t*>(e.data.data());
      file_->writeEvent(&ev);
    } else {
      lcm_->publish(e.channel, e.data.data(), static_cast<unsigned int>(e.data.size()));
    }
  }
  bool toFile() const { return file_ != nullptr; }

 private:
  lcm::LCM* lcm_;
  std::unique_ptr<lcm::LogFile> file_;
};

class ProgressLine {
 public:
  explicit ProgressLine(bool quiet) : quiet_(quiet), start_(Clock::now()), last_(start_) {}
  void update(double log_s, double fraction, int64_t published, bool force = false) {
    if (quiet_) return;
    if (!force && secondsSince(last_) < 2.0) return;
    last_ = Clock::now();
    const double wall = secondsSince(start_);
    std::cerr << "[playback] " << std::fixed << std::setprecision(1) << log_s << " s of log, " << std::setprecision(0)
              << fraction * 100 << "% of file, " << published << " messages, " << std::setprecision(2)
              << (wall > 0 ? log_s / wall : 0.0) << "x real time" << std::endl;
  }

 private:
  bool quiet_;
  Clock::time_point start_, last_;
};

}  // namespace

PlaybackResult runPlayback(const PlaybackOptions& options, lcm::LCM* lcm) {
  PlaybackResult result;
  const auto wall_start = Clock::now();
  LogSource source(options.log, options.source);
  FaultInjector faults(options.faults, options.seed);
  EventSink sink(lcm, options.out_log);
  if (!sink.toFile() && !lcm) throw std::invalid_argument("runPlayback: no bus and no output log");
  const bool lockstep = options.lockstep && !sink.toFile();
  if (options.lockstep && options.consumers.empty())
    throw std::invalid_argument("--lockstep needs the consumer node names (--consumers a,b,...)");

  LockstepGateOptions gate_options;
  gate_options.loss_grace_s = options.loss_grace_s;
  gate_options.tolerate_restarts = options.respawn;
  LockstepGate gate(options.consumers, gate_options);
  struct ProgressContext {
    LockstepGate* gate;
    Clock::time_point start;
  } ctx{&gate, wall_start};
  auto now_s = [&] { return std::chrono::duration<double>(Clock::now() - wall_start).count(); };
  // Consumers are waited for at the start in any mode; lockstep also waits after every message.
  const bool watch_progress = !sink.toFile() && !options.consumers.empty();
  lcm::Subscription* sub = nullptr;
  if (watch_progress) {
    sub = lcm->subscribeFunction(
        options.progress_channel,
        +[](const lcm::ReceiveBuffer* rbuf, const std::string&, ProgressContext* c) {
          progress_t p;
          if (p.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) != static_cast<int>(rbuf->data_size)) return;
          // the node's monotonic clock is this process's steady clock (one host)
          const double idle_checked_s =
              p.idle_checked_us > 0
                  ? p.idle_checked_us * 1e-6 - std::chrono::duration<double>(c->start.time_since_epoch()).count()
                  : std::nan("");
          c->gate->onProgress(p, std::chrono::duration<double>(Clock::now() - c->start).count(), idle_checked_s);
        },
        &ctx);
  }
  struct Unsubscribe {
    lcm::LCM* lcm;
    lcm::Subscription* sub;
    ~Unsubscribe() {
      if (lcm && sub) lcm->unsubscribe(sub);
    }
  } unsubscribe{lcm, sub};
  auto tellEvents = [&] {
    for (const std::string& e : gate.takeEvents())
      if (!options.quiet) std::cerr << "[playback] lockstep: " << e << std::endl;
    result.lost = gate.lostMessages();
    result.restarts = gate.restarts();
  };
  auto fail = [&](const std::string& why) {
    tellEvents();
    result.error = why;
    result.wall_seconds = secondsSince(wall_start);
    return result;
  };

  if (watch_progress) {
    const auto t0 = Clock::now();
    while (!gate.allPresent()) {
      if (shutdownRequested()) return fail("interrupted");
      if (secondsSince(t0) > options.startup_timeout_s) {
        std::string m;
        for (const auto& c : gate.missing()) m += (m.empty() ? "" : ", ") + c;
        return fail("lockstep: no PROGRESS from " + m + " within " + std::to_string(options.startup_timeout_s) + " s");
      }
      lcm->handleTimeout(50);
    }
  }

  ProgressLine progress(options.quiet);
  const auto pace_start = Clock::now();  // real-time pacing starts once the consumers are up
  int64_t first = -1;
  auto publishOne = [&](const LogEvent& e) -> std::string {
    if (!lockstep && !sink.toFile() && options.speed > 0.0) {
      const auto target = pace_start + std::chrono::microseconds(static_cast<int64_t>((e.utime - first) / options.speed));
      std::this_thread::sleep_until(target);
    }
    sink.emit(e);
    ++result.published;
    if (!lockstep) return "";
    gate.onPublished(e.channel, now_s());
    while (!gate.idle() || gate.awaitingRestart(now_s())) {
      if (shutdownRequested()) return "interrupted";
      gate.checkSilent(now_s());
      tellEvents();
      const auto dead = gate.finished();
      if (!options.respawn && !dead.empty())
        return "lockstep: consumer " + dead.front() + " exited; still waiting for: " + gate.pendingDescription();
      if (gate.stalledFor(now_s()) > options.stall_timeout_s) {
        std::ostringstream os;
        os << "lockstep: stalled: no progress for " << options.stall_timeout_s << " s on what is awaited after message "
           << result.published << " (" << e.channel << " at " << std::fixed << std::setprecision(3)
           << result.log_seconds << " s of log); waiting for: " << gate.pendingDescription();
        return os.str();
      }
      if (lcm->handleTimeout(100) < 0) {
        if (shutdownRequested()) return "interrupted";
        return "lockstep: LCM provider failed";
      }
    }
    tellEvents();
    return "";
  };

  while (auto e = source.next()) {
    if (shutdownRequested()) break;
    if (first < 0) first = e->utime;
    result.log_seconds = (e->utime - first) * 1e-6;
    for (const LogEvent& out : faults.push(std::move(*e), first)) {
      const std::string err = publishOne(out);
      if (!err.empty()) return fail(err);
    }
    progress.update(result.log_seconds, source.fractionRead(), result.published);
  }
  for (const LogEvent& out : faults.flush()) {
    const std::string err = publishOne(out);
    if (!err.empty()) return fail(err);
  }
  progress.update(result.log_seconds, 1.0, result.published, true);
  if (source.trailingBytes() > 0 && !options.quiet)
    std::cerr << "[playback] warning: " << source.trailingBytes() << " unreadable bytes at the end of " << options.log
              << " (truncated log?)" << std::endl;
  if (!options.quiet && !faults.empty()) {
    for (const auto& [ch, c] : faults.counts())
      std::cerr << "[playback] faults on " << ch << ": dropped " << c.dropped << ", cut " << c.cut << ", duplicated "
                << c.duplicated << ", delayed " << c.delayed << ", reordered " << c.reordered << ", corrupted "
                << c.corrupted << ", NaN clouds " << c.nan_clouds << ", time-shifted " << c.time_shifted << std::endl;
  }
  tellEvents();
  if (!options.quiet && result.lost > 0) {
    std::cerr << "[playback] lockstep: " << result.lost << " messages lost on the bus:";
    for (const auto& [where, n] : gate.lost()) std::cerr << " " << where << " " << n << ";";
    std::cerr << " this run is not reproducible" << std::endl;
  }
  result.wall_seconds = secondsSince(wall_start);
  if (shutdownRequested()) result.error = "interrupted";
  return result;
}

int64_t replayInProcess(LogSource& source, lcm::LCM& lcm, FaultInjector* faults) {
  int64_t n = 0;
  int64_t first = -1;
  auto publish = [&](const LogEvent& e) {
    lcm.publish(e.channel, e.data.data(), static_cast<unsigned int>(e.data.size()));
    ++n;
    while (lcm.handleTimeout(0) > 0) {
    }
  };
  while (auto e = source.next()) {
    if (first < 0) first = e->utime;
    if (faults) {
      for (const LogEvent& out : faults->push(std::move(*e), first)) publish(out);
    } else {
      publish(*e);
    }
  }
  if (faults)
    for (const LogEvent& out : faults->flush()) publish(out);
  return n;
}

}  // namespace livo
