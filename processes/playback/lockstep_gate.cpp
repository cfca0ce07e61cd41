#include "lockstep_gate.hpp"

#include <sstream>

namespace livo {

LockstepGate::LockstepGate(std::vector<std::string> consumers) : consumers_(std::move(consumers)) {}

bool LockstepGate::onProgress(const progress_t& p) {
  const bool is_new = !nodes_.count(p.node);
  NodeState& n = nodes_[p.node];
  if (p.sequence <= n.sequence && !p.finished) return false;  // stale or reordered
  bool changed = is_new || (p.finished && !n.finished);
  n.sequence = p.sequence;
  n.finished = n.finished || p.finished;
  for (int i = 0; i < p.num_inputs; ++i) {
    int64_t& v = n.handled[p.input_channel[i]];
    changed = changed || v != p.handled[i];
    v = p.handled[i];
  }
  for (int i = 0; i < p.num_outputs; ++i) {
    int64_t& v = n.published[p.output_channel[i]];
    changed = changed || v != p.published[i];
    v = p.published[i];
  }
  return changed;
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
  int64_t n = 0;
  auto it = playback_published_.find(channel);
  if (it != playback_published_.end()) n += it->second;
  for (const auto& [name, node] : nodes_) {
    auto p = node.published.find(channel);
    if (p != node.published.end()) n += p->second;
  }
  return n;
}

bool LockstepGate::idle() const {
  for (const auto& c : consumers_) {
    auto it = nodes_.find(c);
    if (it == nodes_.end()) return false;
    for (const auto& [channel, handled] : it->second.handled)
      if (handled < totalPublished(channel)) return false;
  }
  return true;
}

std::string LockstepGate::pendingDescription() const {
  std::ostringstream os;
  for (const auto& c : consumers_) {
    auto it = nodes_.find(c);
    if (it == nodes_.end()) {
      os << c << ": never reported; ";
      continue;
    }
    for (const auto& [channel, handled] : it->second.handled) {
      const int64_t total = totalPublished(channel);
      if (handled < total) os << c << ": " << channel << " " << handled << "/" << total << "; ";
    }
  }
  std::string s = os.str();
  if (s.size() >= 2) s.resize(s.size() - 2);
  return s;
}

}  // namespace livo
