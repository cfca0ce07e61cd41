#include "livo/playback/playback.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <lcm/lcm-cpp.hpp>

#include "livo/message_registry.hpp"
#include "livo/node.hpp"
#include "livo/playback/lockstep_gate.hpp"
#include "livo/playback/sender_clocks.hpp"

namespace livo::playback {

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

// --clock-file: the log seconds replayed so far, for a supervisor that acts at log times (the
// --kill of run_pipeline.sh). Rewritten at most every 20 ms of wall time and at the end; written
// to FILE.tmp and renamed, so a reader never sees half a number.
class LogClockFile {
 public:
  explicit LogClockFile(std::string path) : path_(std::move(path)) {}
  void update(double log_s, bool force = false) {
    if (path_.empty() || (!force && written_ && secondsSince(last_) < 0.02)) return;
    written_ = true;
    last_ = Clock::now();
    const std::string tmp = path_ + ".tmp";
    {
      std::ofstream f(tmp, std::ios::trunc);
      f << std::fixed << std::setprecision(3) << log_s << "\n";
      if (!f) throw std::runtime_error("--clock-file: cannot write " + tmp);
    }
    if (std::rename(tmp.c_str(), path_.c_str()) != 0)
      throw std::runtime_error("--clock-file: cannot rename " + tmp + " to " + path_);
  }

 private:
  std::string path_;
  bool written_ = false;
  Clock::time_point last_;
};

// One replay: the log, the fault injector, where events go and, with consumers, the lockstep gate
// fed by their PROGRESS messages.
class PlaybackRun {
 public:
  PlaybackRun(const PlaybackOptions& options, lcm::LCM* lcm)
      : options_(options),
        lcm_(lcm),
        wall_start_(Clock::now()),
        source_(options.log, options.source),
        faults_(options.faults, options.seed),
        sink_(lcm, options.out_log),
        gate_(options.consumers, gateOptions(options)),
        context_{&gate_, wall_start_, {}, {}} {
    if (!sink_.toFile() && !lcm) throw std::invalid_argument("runPlayback: no bus and no output log");
    if (options.lockstep && options.consumers.empty())
      throw std::invalid_argument("--lockstep needs the consumer node names (--consumers a,b,...)");
    lockstep_ = options.lockstep && !sink_.toFile();
    // Consumers are waited for at the start in any mode; lockstep also waits after every message.
    watch_progress_ = !sink_.toFile() && !options.consumers.empty();
    if (watch_progress_) subscribeProgress();
  }
  ~PlaybackRun() {
    if (lcm_ && subscription_) lcm_->unsubscribe(subscription_);
  }
  PlaybackRun(const PlaybackRun&) = delete;
  PlaybackRun& operator=(const PlaybackRun&) = delete;

  /// Waits until every consumer has reported once (only when there are consumers to watch).
  std::string waitForConsumers() {
    if (!watch_progress_) return "";
    const auto t0 = Clock::now();
    while (!gate_.allPresent()) {
      if (shutdownRequested()) return "interrupted";
      if (secondsSince(t0) > options_.startup_timeout_s) {
        std::string m;
        for (const auto& c : gate_.missing()) m += (m.empty() ? "" : ", ") + c;
        return "lockstep: no PROGRESS from " + m + " within " + std::to_string(options_.startup_timeout_s) + " s";
      }
      lcm_->handleTimeout(50);
    }
    return "";
  }

  /// Replays the log through the fault injector to the end (or a shutdown request).
  std::string replay() {
    pace_start_ = Clock::now();  // real-time pacing (and the progress line) start once the consumers are up
    progress_line_.emplace(options_.quiet);
    tellLagging();
    while (auto e = source_.next()) {
      if (shutdownRequested()) break;
      if (first_ < 0) first_ = e->utime;
      result_.log_seconds = (e->utime - first_) * 1e-6;
      for (const LogEvent& out : faults_.push(std::move(*e), first_)) {
        const std::string err = publish(out);
        if (!err.empty()) return err;
      }
      progress_line_->update(result_.log_seconds, source_.fractionRead(), result_.published);
      clock_file_.update(result_.log_seconds);
    }
    for (const LogEvent& out : faults_.flush()) {
      const std::string err = publish(out);
      if (!err.empty()) return err;
    }
    if (lockstep_ && result_.published > 0) {  // the lagging consumers finish too
      const Clock::time_point t0 = Clock::now();
      const std::string err = waitUntilCaughtUp(nullptr, LockstepGate::kNoUtime);
      if (!err.empty()) return err;
      LockstepWaits& waits = result_.waits["(end of log)"];
      waits.messages = waits.waited = 1;
      waits.seconds = secondsSince(t0);
      waits.seconds_by_last[context_.last_mover] = waits.seconds;
    }
    progress_line_->update(result_.log_seconds, 1.0, result_.published, true);
    clock_file_.update(result_.log_seconds, /*force=*/true);
    return "";
  }

  PlaybackResult fail(const std::string& why) {
    tellEvents();
    result_.error = why;
    result_.wall_seconds = secondsSince(wall_start_);
    return result_;
  }

  /// The end-of-run warnings and counts.
  PlaybackResult finish() {
    if (source_.trailingBytes() > 0 && !options_.quiet)
      std::cerr << "[playback] warning: " << source_.trailingBytes() << " unreadable bytes at the end of "
                << options_.log << " (truncated log?)" << std::endl;
    if (!options_.quiet && !faults_.empty()) {
      for (const auto& [ch, c] : faults_.counts())
        std::cerr << "[playback] faults on " << ch << ": dropped " << c.dropped << ", cut " << c.cut << ", duplicated "
                  << c.duplicated << ", delayed " << c.delayed << ", reordered " << c.reordered << ", corrupted "
                  << c.corrupted << ", NaN clouds " << c.nan_clouds << ", time-shifted " << c.time_shifted << std::endl;
    }
    tellEvents();
    if (!options_.quiet && result_.lost > 0) {
      std::cerr << "[playback] lockstep: " << result_.lost << " messages lost on the bus:";
      for (const auto& [where, n] : gate_.lost()) std::cerr << " " << where << " " << n << ";";
      std::cerr << " this run is not reproducible" << std::endl;
    }
    result_.wall_seconds = secondsSince(wall_start_);
    if (shutdownRequested()) result_.error = "interrupted";
    return result_;
  }

 private:
  struct ProgressContext {
    LockstepGate* gate;
    Clock::time_point start;
    std::string last_mover;  // the node whose PROGRESS last moved a count on
    SenderClocks clocks;     // each node's clock against ours (it may run on another host)
  };

  static LockstepGateOptions gateOptions(const PlaybackOptions& options) {
    LockstepGateOptions g;
    g.loss_grace_s = options.loss_grace_s;
    g.tolerate_restarts = options.respawn;
    g.honour_quiet_promises = !options.serial;
    if (!options.serial) g.may_lag = options.may_lag;
    g.max_lag_messages = options.max_lag_messages;
    g.max_lag_bytes = options.max_lag_bytes;
    return g;
  }

  double now_s() const { return secondsSince(wall_start_); }

  void subscribeProgress() {
    subscription_ = lcm_->subscribeFunction(
        options_.progress_channel,
        +[](const lcm::ReceiveBuffer* rbuf, const std::string&, ProgressContext* c) {
          progress_t p;
          if (p.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) != static_cast<int>(rbuf->data_size)) return;
          // the node's monotonic clock: this host's or another's, with an offset bounded from its reports
          const double received_s = std::chrono::duration<double>(Clock::now() - c->start).count();
          const double idle_checked_s =
              p.idle_checked_us > 0 ? c->clocks.toLocal(p.node, p.instance, p.idle_checked_us * 1e-6, received_s)
                                    : std::nan("");
          if (c->gate->onProgress(p, received_s, idle_checked_s))
            c->last_mover = p.node;
        },
        &context_);
  }

  void tellEvents() {
    for (const std::string& e : gate_.takeEvents())
      if (!options_.quiet) std::cerr << "[playback] lockstep: " << e << std::endl;
    result_.lost = gate_.lostMessages();
    result_.restarts = gate_.restarts();
  }

  /// One event out: paced in real time, or (lockstep) once the consumers let it go.
  std::string publish(const LogEvent& e) {
    if (!lockstep_ && !sink_.toFile() && options_.speed > 0.0) {
      const auto target =
          pace_start_ + std::chrono::microseconds(static_cast<int64_t>((e.utime - first_) / options_.speed));
      std::this_thread::sleep_until(target);
    }
    // the message's own stamp (what a quiet promise is about), not the log event's
    int64_t utime = LockstepGate::kNoUtime;
    if (lockstep_ && !messageUtime(e.data.data(), static_cast<int>(e.data.size()), &utime))
      utime = LockstepGate::kNoUtime;
    if (lockstep_ && result_.published > 0) {
      // the wait after the previous message, until this one may go (counted for the previous one)
      const bool must_wait = !gate_.mayPublish(e.channel, utime);
      if (!must_wait && !gate_.idle()) ++result_.not_waited;
      const Clock::time_point t0 = Clock::now();
      const std::string err = waitUntilCaughtUp(&e.channel, utime);
      if (!err.empty()) return err;
      if (must_wait) {
        LockstepWaits& waits = result_.waits[last_channel_];
        const double waited_s = secondsSince(t0);
        ++waits.waited;
        waits.seconds += waited_s;
        waits.seconds_by_last[context_.last_mover] += waited_s;
      }
    }
    sink_.emit(e);
    ++result_.published;
    if (!lockstep_) return "";
    gate_.onPublished(e.channel, now_s(), utime, static_cast<int64_t>(e.data.size()));
    ++result_.waits[e.channel].messages;
    last_channel_ = e.channel;
    last_log_seconds_ = result_.log_seconds;
    tellEvents();
    return "";
  }

  void tellLagging() {
    if (!lockstep_ || options_.quiet) return;
    if (options_.serial) {
      std::cerr << "[playback] lockstep: serial (every consumer handles every message before the next)" << std::endl;
      return;
    }
    if (options_.may_lag.empty()) return;
    std::string names;
    for (const auto& c : gate_.lagging()) names += (names.empty() ? "" : ", ") + c;
    std::ostringstream os;
    if (names.empty())
      os << "every consumer in step";
    else
      os << names << " may lag up to " << options_.max_lag_messages << " messages (" << std::fixed
         << std::setprecision(1) << options_.max_lag_bytes / 1048576.0 << " MB) behind the rest";
    std::cerr << "[playback] lockstep: " << os.str() << std::endl;
  }

  /// Lockstep: handles PROGRESS until the next message (on `next_channel`, stamped `next_utime`)
  /// may go out (LockstepGate::mayPublish), or, without one, until the pipeline has handled
  /// everything published so far.
  std::string waitUntilCaughtUp(const std::string* next_channel, int64_t next_utime) {
    while (!(next_channel ? gate_.mayPublish(*next_channel, next_utime) : gate_.idle()) ||
           gate_.awaitingRestart(now_s())) {
      if (shutdownRequested()) return "interrupted";
      gate_.checkSilent(now_s());
      tellEvents();
      const auto dead = gate_.finished();
      if (!options_.respawn && !dead.empty())
        return "lockstep: consumer " + dead.front() + " exited; still waiting for: " + gate_.pendingDescription();
      if (gate_.stalledFor(now_s()) > options_.stall_timeout_s) {
        std::ostringstream os;
        os << "lockstep: stalled: no progress for " << options_.stall_timeout_s << " s on what is awaited after ";
        if (next_channel)
          os << "message " << result_.published << " (" << last_channel_ << " at " << std::fixed << std::setprecision(3)
             << last_log_seconds_ << " s of log)";
        else
          os << "the end of the log";
        os << "; waiting for: " << gate_.pendingDescription();
        return os.str();
      }
      if (lcm_->handleTimeout(100) < 0) {
        if (shutdownRequested()) return "interrupted";
        return "lockstep: LCM provider failed";
      }
    }
    return "";
  }

  const PlaybackOptions& options_;
  lcm::LCM* lcm_;
  const Clock::time_point wall_start_;
  LogSource source_;
  FaultInjector faults_;
  EventSink sink_;
  LockstepGate gate_;
  std::optional<ProgressLine> progress_line_;
  LogClockFile clock_file_{options_.clock_file};
  std::string last_channel_;  // lockstep: of the message published last
  double last_log_seconds_ = 0.0;
  ProgressContext context_;
  lcm::Subscription* subscription_ = nullptr;
  bool lockstep_ = false;
  bool watch_progress_ = false;
  Clock::time_point pace_start_;
  int64_t first_ = -1;
  PlaybackResult result_;
};

}  // namespace

std::vector<std::string> describeWaits(const std::map<std::string, LockstepWaits>& waits, size_t max_lines) {
  std::vector<std::pair<std::string, const LockstepWaits*>> order;
  for (const auto& [channel, w] : waits) order.emplace_back(channel, &w);
  std::stable_sort(order.begin(), order.end(),
                   [](const auto& a, const auto& b) { return a.second->seconds > b.second->seconds; });
  std::vector<std::string> lines;
  for (const auto& [channel, w] : order) {
    if (lines.size() >= max_lines || w->waited == 0) break;
    std::vector<std::pair<std::string, double>> by(w->seconds_by_last.begin(), w->seconds_by_last.end());
    std::stable_sort(by.begin(), by.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
    std::ostringstream os;
    os << std::fixed << std::setprecision(2) << channel << ": " << w->waited << " of " << w->messages << " waited for, "
       << w->seconds << " s (";
    for (size_t i = 0; i < by.size(); ++i)
      os << (i ? ", " : "") << (by[i].first.empty() ? "?" : by[i].first) << " " << by[i].second;
    os << ")";
    lines.push_back(os.str());
  }
  return lines;
}

PlaybackResult runPlayback(const PlaybackOptions& options, lcm::LCM* lcm) {
  PlaybackRun run(options, lcm);
  if (const std::string err = run.waitForConsumers(); !err.empty()) return run.fail(err);
  if (const std::string err = run.replay(); !err.empty()) return run.fail(err);
  return run.finish();
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

}  // namespace livo::playback
