#include "livo/playback/lockstep_gate.hpp"

#include <algorithm>
#include <iomanip>
#include <limits>
#include <sstream>

namespace livo::playback {

namespace {
constexpr double kPublishHistoryS = 60.0;      // how far back publish times are kept (>> loss_grace_s)
constexpr size_t kUtimeHistory = 1024;         // playback stamps kept per channel for quiet promises
constexpr int64_t kMaxAlwaysQuietBacklog = 8;  // messages a promise for a whole channel lets wait
}  // namespace

LockstepGate::LockstepGate(std::vector<std::string> consumers, LockstepGateOptions options)
    : consumers_(std::move(consumers)), options_(options) {}

bool LockstepGate::isConsumer(const std::string& node) const {
  return std::find(consumers_.begin(), consumers_.end(), node) != consumers_.end();
}

bool LockstepGate::onProgress(const progress_t& p, double now_s, double idle_checked_s) {
  const bool is_new = !nodes_.count(p.node);
  NodeState& n = nodes_[p.node];
  bool changed = is_new;
  const size_t inputs_before = n.handled.size(), outputs_before = n.published.size();
  const bool away_before = n.away;
  if (is_new) {
    n.instance = p.instance;
  } else if (p.instance != n.instance) {
    startNewInstance(p, n);
    changed = true;
  }
  if (p.sequence <= n.sequence && !p.finished) return false;  // stale or reordered
  n.last_heard_s = now_s;
  if (n.away && !n.finished && !p.finished) {
    n.away = false;
    events_.push_back("consumer " + p.node + " is heard again");
  }
  n.sequence = p.sequence;
  const bool counts_changed = recordCounts(p, n, now_s);
  changed = changed || counts_changed;
  if (p.finished && !n.finished) {
    noteFinished(p.node, n, now_s);
    changed = true;
  }
  if (p.idle && !p.finished && isConsumer(p.node))
    detectLosses(p.node, n, std::isfinite(idle_checked_s) ? std::min(idle_checked_s, now_s) : now_s);
  updateWaiting(now_s);
  // who may lag depends on who takes what (and who is away): worked out again when that changes
  if (is_new || n.handled.size() != inputs_before || n.published.size() != outputs_before || n.away != away_before)
    noteLagDecisions();
  return changed;
}

void LockstepGate::startNewInstance(const progress_t& p, NodeState& n) {
  // A new process under the same name: its counts start again from zero. What the old instance
  // published stays published; what was published before the new one reported is lost to it.
  for (const auto& [channel, count] : n.published) n.published_before[channel] += count;
  for (const auto& [channel, bytes] : n.published_bytes) n.published_bytes_before[channel] += bytes;
  n.published.clear();
  n.published_bytes.clear();
  std::ostringstream lost;
  int64_t lost_total = 0;
  for (int i = 0; i < p.num_inputs; ++i) {
    const std::string& channel = p.input_channel[i];
    const int64_t missed = totalPublished(channel) - n.handled[channel] - n.offset[channel];
    if (missed > 0) {
      lost << (lost_total ? ", " : "") << missed << " " << channel;
      lost_total += missed;
    }
  }
  n.handled.clear();
  n.offset.clear();
  for (int i = 0; i < p.num_inputs; ++i)
    n.offset[p.input_channel[i]] = totalPublished(p.input_channel[i]) - p.handled[i];
  n.instance = p.instance;
  n.sequence = -1;
  n.finished = false;
  n.away = false;
  if (isConsumer(p.node)) {
    ++restarts_;
    events_.push_back("consumer " + p.node + " restarted" +
                      (lost_total ? "; missed while it was away: " + lost.str() : std::string()));
  }
}

bool LockstepGate::recordCounts(const progress_t& p, NodeState& n, double now_s) {
  bool changed = false;
  n.quiet.clear();
  for (int i = 0; i < p.num_quiet; ++i)
    if (p.quiet_before[i] > p.quiet_from[i]) n.quiet[p.quiet_channel[i]] = {p.quiet_from[i], p.quiet_before[i]};
  for (int i = 0; i < p.num_inputs; ++i) {
    int64_t& v = n.handled[p.input_channel[i]];
    changed = changed || v != p.handled[i];
    v = p.handled[i];
  }
  for (int i = 0; i < p.num_outputs; ++i) {
    if (static_cast<size_t>(i) < p.published_bytes.size())
      n.published_bytes[p.output_channel[i]] = p.published_bytes[i];
    int64_t& v = n.published[p.output_channel[i]];
    if (v != p.published[i]) {
      changed = true;
      v = p.published[i];
      notePublished(p.output_channel[i], now_s);
    }
  }
  return changed;
}

void LockstepGate::noteFinished(const std::string& node, NodeState& n, double now_s) {
  n.finished = true;
  if (options_.tolerate_restarts && isConsumer(node)) {
    n.away = true;
    n.away_since_s = now_s;
    events_.push_back("consumer " + node + " exited; not waited for until it restarts");
  }
}

void LockstepGate::onPublished(const std::string& channel, double now_s, int64_t utime, int64_t bytes) {
  const int64_t index = ++playback_published_[channel];
  playback_bytes_[channel] += bytes;
  auto& stamps = playback_utimes_[channel];
  stamps.emplace_back(index, utime);
  if (stamps.size() > kUtimeHistory) stamps.pop_front();
  notePublished(channel, now_s);
  updateWaiting(now_s);
}

void LockstepGate::notePublished(const std::string& channel, double now_s) {
  const int64_t total = countPublished(channel);
  int64_t& known = known_total_[channel];
  if (total <= known) return;
  known = total;
  auto& history = reached_at_[channel];
  history.emplace_back(total, now_s);
  while (history.size() > 2 && history[1].second < now_s - kPublishHistoryS) history.pop_front();
}

int64_t LockstepGate::publishedBy(const std::string& channel, double t_s) const {
  auto it = reached_at_.find(channel);
  if (it == reached_at_.end()) return 0;
  const auto& history = it->second;
  // the last entry reached at or before t_s (times do not decrease along the history)
  auto after = std::upper_bound(history.begin(), history.end(), t_s,
                                [](double t, const std::pair<int64_t, double>& e) { return t < e.second; });
  return after == history.begin() ? 0 : std::prev(after)->first;
}

int64_t LockstepGate::deficit(const NodeState& n, const std::string& channel) const {
  auto h = n.handled.find(channel);
  auto o = n.offset.find(channel);
  return totalPublished(channel) - (h == n.handled.end() ? 0 : h->second) - (o == n.offset.end() ? 0 : o->second);
}

void LockstepGate::detectLosses(const std::string& node, NodeState& n, double idle_at_s) {
  for (const auto& [channel, handled] : n.handled) {
    if (deficit(n, channel) <= 0) continue;
    const int64_t old = publishedBy(channel, idle_at_s - options_.loss_grace_s) - handled - n.offset[channel];
    if (old <= 0) continue;
    n.offset[channel] += old;
    lost_total_[node + ": " + channel] += old;
    std::ostringstream os;
    os << "lost on the bus: " << node << " never received " << old << " " << channel << " message"
       << (old > 1 ? "s" : "") << " (it is idle and has handled " << handled << " of " << totalPublished(channel)
       << ", the missing ones published more than " << options_.loss_grace_s << " s ago); going on without "
       << (old > 1 ? "them" : "it");
    events_.push_back(os.str());
  }
}

void LockstepGate::updateWaiting(double now_s) {
  for (const auto& c : consumers_) {
    auto it = nodes_.find(c);
    if (it == nodes_.end()) continue;
    const NodeState& n = it->second;
    for (const auto& [channel, handled] : n.handled) {
      const auto key = std::make_pair(c, channel);
      if (n.away || deficit(n, channel) <= 0) {
        waiting_.erase(key);
        continue;
      }
      auto o = n.offset.find(channel);
      const int64_t counted = handled + (o == n.offset.end() ? 0 : o->second);
      auto w = waiting_.find(key);
      if (w == waiting_.end() || w->second.handled != counted) waiting_[key] = Waiting{counted, now_s};
    }
  }
}

void LockstepGate::checkSilent(double now_s) {
  if (!options_.tolerate_restarts) return;
  bool someone_went = false;
  for (const auto& c : consumers_) {
    auto it = nodes_.find(c);
    if (it == nodes_.end() || it->second.away) continue;
    if (now_s - it->second.last_heard_s > options_.silent_after_s) {
      someone_went = true;
      it->second.away = true;
      it->second.away_since_s = now_s;
      std::ostringstream os;
      os << "consumer " << c << " silent for " << std::fixed << std::setprecision(1) << now_s - it->second.last_heard_s
         << " s; not waited for until it reports again";
      events_.push_back(os.str());
    }
  }
  if (someone_went) noteLagDecisions();
  updateWaiting(now_s);
}

bool LockstepGate::allPresent() const { return missing().empty(); }

std::vector<std::string> LockstepGate::missing() const {
  std::vector<std::string> out;
  for (const auto& c : consumers_)
    if (!nodes_.count(c)) out.push_back(c);
  return out;
}

std::vector<std::string> LockstepGate::finished() const {
  std::vector<std::string> out;
  for (const auto& c : consumers_) {
    auto it = nodes_.find(c);
    if (it != nodes_.end() && it->second.finished) out.push_back(c);
  }
  return out;
}

int64_t LockstepGate::totalPublished(const std::string& channel) const {
  auto it = known_total_.find(channel);
  return it == known_total_.end() ? 0 : it->second;
}

int64_t LockstepGate::countPublished(const std::string& channel) const {
  int64_t n = 0;
  auto it = playback_published_.find(channel);
  if (it != playback_published_.end()) n += it->second;
  for (const auto& [name, node] : nodes_) {
    auto p = node.published.find(channel);
    if (p != node.published.end()) n += p->second;
    auto b = node.published_before.find(channel);
    if (b != node.published_before.end()) n += b->second;
  }
  return n;
}

bool LockstepGate::idle() const {
  for (const auto& c : consumers_) {
    auto it = nodes_.find(c);
    if (it == nodes_.end()) return false;
    if (it->second.away) continue;
    for (const auto& [channel, handled] : it->second.handled)
      if (deficit(it->second, channel) > 0) return false;
  }
  return true;
}

int64_t LockstepGate::behind(const NodeState& n) const {
  int64_t total = 0;
  for (const auto& [channel, handled] : n.handled) total += std::max<int64_t>(0, deficit(n, channel));
  return total;
}

int64_t LockstepGate::behindBytes(const NodeState& n) const {
  double total = 0.0;
  for (const auto& [channel, handled] : n.handled) {
    const int64_t d = deficit(n, channel);
    if (d <= 0) continue;
    int64_t bytes = 0;
    if (auto pb = playback_bytes_.find(channel); pb != playback_bytes_.end()) bytes += pb->second;
    for (const auto& [name, node] : nodes_) {
      if (auto b = node.published_bytes.find(channel); b != node.published_bytes.end()) bytes += b->second;
      if (auto b = node.published_bytes_before.find(channel); b != node.published_bytes_before.end())
        bytes += b->second;
    }
    const int64_t count = totalPublished(channel);
    if (count > 0) total += static_cast<double>(d) * static_cast<double>(bytes) / static_cast<double>(count);
  }
  return static_cast<int64_t>(total);
}

std::string LockstepGate::keptInStepBecause(const std::string& node) const {
  auto it = nodes_.find(node);
  if (it == nodes_.end()) return "it has not reported";
  for (const auto& [channel, count] : it->second.published) {
    for (const auto& c : consumers_) {
      if (c == node) continue;
      auto taker = nodes_.find(c);
      if (taker == nodes_.end() || taker->second.away || taker->second.published.empty()) continue;  // recorder
      if (taker->second.handled.count(channel)) return c + " takes its " + channel;
    }
  }
  return "";
}

void LockstepGate::noteLagDecisions() {
  lagging_.clear();
  for (const auto& c : options_.may_lag)
    if (isConsumer(c) && keptInStepBecause(c).empty()) lagging_.push_back(c);
  for (const auto& c : options_.may_lag) {
    if (!nodes_.count(c)) continue;
    const std::string why = keptInStepBecause(c);
    auto [it, is_new] = lag_decision_.emplace(c, why);
    if (!is_new && it->second == why) continue;
    it->second = why;
    if (!why.empty()) events_.push_back("consumer " + c + " kept in step (it may not lag): " + why);
  }
}

bool LockstepGate::caughtUp() const {
  const std::vector<std::string>& lag = lagging_;
  for (const auto& c : consumers_) {
    auto it = nodes_.find(c);
    if (it == nodes_.end()) return false;
    const NodeState& n = it->second;
    if (n.away) continue;
    if (std::find(lag.begin(), lag.end(), c) != lag.end()) {
      if (behind(n) > options_.max_lag_messages || behindBytes(n) > options_.max_lag_bytes) return false;
      continue;
    }
    for (const auto& [channel, handled] : n.handled)
      if (deficit(n, channel) > 0 && !promisedQuiet(n, channel)) return false;
  }
  return true;
}

bool LockstepGate::mayPublish(const std::string& channel, int64_t utime) const {
  for (const auto& c : consumers_) {
    auto it = nodes_.find(c);
    if (it == nodes_.end()) return false;
    const NodeState& n = it->second;
    if (n.away) continue;
    if (isLagging(c)) {
      if (behind(n) > options_.max_lag_messages || behindBytes(n) > options_.max_lag_bytes) return false;
      continue;
    }
    if (busyLoudly(n)) {
      if (!answerMayBeInFlight(c, n, channel, utime)) return false;
      continue;
    }
    if (n.handled.count(channel) && !quietFor(n, channel, utime) && awaitsNodeMessages(n)) return false;
  }
  return true;
}

bool LockstepGate::answerMayBeInFlight(const std::string& c, const NodeState& n, const std::string& channel,
                                       int64_t utime) const {
  if (!options_.honour_quiet_promises) return false;
  if (n.handled.count(channel)) return false;  // (1) it takes the message
  for (const auto& d : consumers_) {
    if (d == c) continue;
    auto it = nodes_.find(d);
    if (it == nodes_.end()) return false;
    const NodeState& m = it->second;
    if (m.away) continue;
    const bool recorder = m.published.empty();
    // (2) the message makes no consumer in step publish (lagging ones are bounded as ever)
    if (m.handled.count(channel) && !isLagging(d) && (busyLoudly(m) || !quietFor(m, channel, utime))) return false;
    // (3) what it answers with reaches only recorders and consumers in step that promise it quiet
    for (const auto& [output, count] : n.published) {
      if (!m.handled.count(output) || recorder) continue;
      if (isLagging(d) || busyLoudly(m) || !quietFor(m, output, kNoUtime, /*whole_channel=*/true)) return false;
    }
  }
  return true;
}

bool LockstepGate::busyLoudly(const NodeState& n) const {
  for (const auto& [channel, handled] : n.handled)
    if (deficit(n, channel) > 0 && !promisedQuiet(n, channel)) return true;
  return false;
}

bool LockstepGate::quietFor(const NodeState& n, const std::string& channel, int64_t utime, bool whole_channel) const {
  if (!options_.honour_quiet_promises) return false;
  auto q = n.quiet.find(channel);
  if (q == n.quiet.end()) return false;
  const auto [from, before] = q->second;
  if (whole_channel)
    return from == std::numeric_limits<int64_t>::min() && before == std::numeric_limits<int64_t>::max();
  if (from == std::numeric_limits<int64_t>::min() && before == std::numeric_limits<int64_t>::max()) return true;
  return utime != kNoUtime && utime >= from && utime < before;
}

bool LockstepGate::awaitsNodeMessages(const NodeState& n) const {
  for (const auto& [channel, handled] : n.handled) {
    if (deficit(n, channel) <= 0) continue;
    auto pb = playback_published_.find(channel);
    if (pb == playback_published_.end() || totalPublished(channel) != pb->second) return true;
  }
  return false;
}

bool LockstepGate::isLagging(const std::string& node) const {
  return std::find(lagging_.begin(), lagging_.end(), node) != lagging_.end();
}

bool LockstepGate::promisedQuiet(const NodeState& n, const std::string& channel) const {
  if (!options_.honour_quiet_promises) return false;
  auto q = n.quiet.find(channel);
  if (q == n.quiet.end()) return false;
  const auto [from, before] = q->second;
  // every message on the channel: no stamp needed, nodes may publish it too; the backlog is
  // bounded all the same (the receive buffer), as a lagging consumer's is
  if (from == std::numeric_limits<int64_t>::min() && before == std::numeric_limits<int64_t>::max())
    return deficit(n, channel) <= kMaxAlwaysQuietBacklog;
  auto pb = playback_published_.find(channel);
  if (pb == playback_published_.end() || totalPublished(channel) != pb->second) return false;  // nodes publish it too
  auto h = n.handled.find(channel);
  auto o = n.offset.find(channel);
  const int64_t first_unhandled = (h == n.handled.end() ? 0 : h->second) + (o == n.offset.end() ? 0 : o->second) + 1;
  const auto& stamps = playback_utimes_.at(channel);
  if (stamps.empty() || stamps.front().first > first_unhandled) return false;  // older than the history
  for (auto it = stamps.rbegin(); it != stamps.rend() && it->first >= first_unhandled; ++it)
    if (it->second == kNoUtime || it->second < from || it->second >= before) return false;
  return true;
}

bool LockstepGate::awaitingRestart(double now_s) const {
  for (const auto& c : consumers_) {
    auto it = nodes_.find(c);
    if (it != nodes_.end() && it->second.away && now_s - it->second.away_since_s < options_.restart_wait_s) return true;
  }
  return false;
}

double LockstepGate::stalledFor(double now_s) const {
  double longest = 0.0;
  for (const auto& [key, w] : waiting_) longest = std::max(longest, now_s - w.since_s);
  return longest;
}

std::string LockstepGate::pendingDescription() const {
  std::ostringstream os;
  for (const auto& c : consumers_) {
    auto it = nodes_.find(c);
    if (it == nodes_.end()) {
      os << c << ": never reported; ";
      continue;
    }
    if (it->second.away) continue;
    for (const auto& [channel, handled] : it->second.handled) {
      if (deficit(it->second, channel) <= 0) continue;
      const int64_t total = totalPublished(channel);
      os << c << ": " << channel << " " << total - deficit(it->second, channel) << "/" << total << "; ";
    }
  }
  std::string s = os.str();
  if (s.size() >= 2) s.resize(s.size() - 2);
  return s;
}

std::vector<std::string> LockstepGate::takeEvents() {
  std::vector<std::string> out;
  out.swap(events_);
  return out;
}

int64_t LockstepGate::lostMessages() const {
  int64_t n = 0;
  for (const auto& [key, count] : lost_total_) n += count;
  return n;
}

}  // namespace livo::playback
