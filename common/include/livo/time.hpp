// Sensor time (int64 microseconds, "utime") and time-ordered buffers.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <utility>

namespace livo {

inline double toSeconds(int64_t utime) { return static_cast<double>(utime) * 1e-6; }
inline int64_t toUtime(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e6)); }

/// Samples kept in time order whatever order they arrive in; a node acts on them up to a
/// watermark, so its output depends only on the samples' stamps, never on arrival order.
template <class T>
class TimeBuffer {
 public:
  struct Entry {
    int64_t utime;
    T value;
  };

  /// Inserts in time order. Equal stamps keep arrival order. Returns false (and drops the
  /// sample) if it is at or before the last stamp already consumed by popUntil().
  bool insert(int64_t utime, T value) {
    if (consumed_any_ && utime <= consumed_until_) return false;
    auto it = std::upper_bound(entries_.begin(), entries_.end(), utime,
                               [](int64_t t, const Entry& e) { return t < e.utime; });
    entries_.insert(it, Entry{utime, std::move(value)});
    return true;
  }

  /// Removes and returns (in order) every sample with utime <= t.
  template <class Fn>
  void popUntil(int64_t t, Fn&& fn) {
    while (!entries_.empty() && entries_.front().utime <= t) {
      fn(entries_.front());
      consumed_until_ = std::max(consumed_until_, entries_.front().utime);
      consumed_any_ = true;
      entries_.pop_front();
    }
  }

  /// Drops samples older than t without marking them consumed.
  void dropBefore(int64_t t) {
    while (!entries_.empty() && entries_.front().utime < t) entries_.pop_front();
  }

  void clear() {
    entries_.clear();
    consumed_any_ = false;
    consumed_until_ = 0;
  }

  bool empty() const { return entries_.empty(); }
  size_t size() const { return entries_.size(); }
  const Entry& front() const { return entries_.front(); }
  const Entry& back() const { return entries_.back(); }
  const std::deque<Entry>& entries() const { return entries_; }

 private:
  std::deque<Entry> entries_;
  bool consumed_any_ = false;
  int64_t consumed_until_ = 0;
};

/// Index i such that stamps[i] <= t < stamps[i+1] in a sorted sequence, with the blend factor;
/// false if t lies outside [front, back].
template <class Seq, class StampOf>
bool bracket(const Seq& seq, int64_t t, StampOf stamp_of, size_t* index, double* alpha) {
  if (seq.empty() || t < stamp_of(seq.front()) || t > stamp_of(seq.back())) return false;
  auto it = std::upper_bound(seq.begin(), seq.end(), t, [&](int64_t tt, const auto& e) { return tt < stamp_of(e); });
  size_t i = static_cast<size_t>(std::distance(seq.begin(), it));
  if (i == seq.size()) {  // t == back
    *index = seq.size() >= 2 ? seq.size() - 2 : 0;
    *alpha = seq.size() >= 2 ? 1.0 : 0.0;
    return true;
  }
  *index = i - 1;
  const int64_t t0 = stamp_of(seq[i - 1]), t1 = stamp_of(seq[i]);
  *alpha = t1 > t0 ? static_cast<double>(t - t0) / static_cast<double>(t1 - t0) : 0.0;
  return true;
}

}  // namespace livo
