// A flat open-addressing hash table from voxel keys (livo/voxel_key.hpp) to dense indices
// (faster than std::unordered_map for the per-point lookups of the map and the scan
// downsampling; deterministic: no dependence on addresses).
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "livo/voxel_key.hpp"

namespace livo {

/// Key -> int32 index, linear probing, grows at 50 % load. No single-key erase: callers rebuild.
class FlatKeyIndex {
 public:
  /// Sized for `expected` keys without growing.
  explicit FlatKeyIndex(size_t expected = 512) { resetFor(expected); }

  /// Index stored for key, or -1.
  int32_t find(VoxelKey key) const {
    size_t i = slot(key);
    while (true) {
      const Entry& e = table_[i];
      if (e.key == key) return e.index;
      if (e.key == kNoVoxel) return -1;
      i = (i + 1) & mask_;
    }
  }

  /// Inserts key -> index if absent; returns the stored index (the existing one if present).
  int32_t insert(VoxelKey key, int32_t index) {
    if (2 * (size_ + 1) > table_.size()) rehash(table_.size() * 2);
    size_t i = slot(key);
    while (true) {
      Entry& e = table_[i];
      if (e.key == key) return e.index;
      if (e.key == kNoVoxel) {
        e.key = key;
        e.index = index;
        ++size_;
        return index;
      }
      i = (i + 1) & mask_;
    }
  }

  void clear() {
    for (auto& e : table_) e = Entry{};
    size_ = 0;
  }
  size_t size() const { return size_; }
  size_t capacity() const { return table_.size(); }
  /// Shrinks or grows to hold n keys at 50 % load; drops all entries.
  void resetFor(size_t n) {
    size_t cap = 1024;
    while (cap < 2 * n + 2) cap *= 2;
    if (cap != table_.size()) {
      table_.assign(cap, Entry{});
      mask_ = cap - 1;
    } else {
      clear();
    }
    size_ = 0;
  }

 private:
  struct Entry {
    VoxelKey key = kNoVoxel;
    int32_t index = -1;
  };
  size_t slot(VoxelKey k) const {
    k ^= k >> 33;
    k *= 0xff51afd7ed558ccdULL;
    k ^= k >> 33;
    return static_cast<size_t>(k) & mask_;
  }
  void rehash(size_t cap) {
    std::vector<Entry> old;
    old.swap(table_);
    table_.assign(cap, Entry{});
    mask_ = cap - 1;
    size_ = 0;
    for (const auto& e : old)
      if (e.key != kNoVoxel) insert(e.key, e.index);
  }

  std::vector<Entry> table_;
  size_t mask_ = 0;
  size_t size_ = 0;
};

}  // namespace livo
