#include "livo/octomap/occupancy_map.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include "livo/file_output.hpp"
#include "livo/octomap/morton_index.hpp"
#include "livo/octomap/ray_keys.hpp"
#include "livo/spill_file.hpp"

namespace livo::octomap {

namespace {
template <class Tree>
void configure(Tree* t, const OctomapOptions& o) {
  t->setProbHit(o.prob_hit);
  t->setProbMiss(o.prob_miss);
  t->setClampingThresMin(o.clamping_min);
  t->setClampingThresMax(o.clamping_max);
  t->setOccupancyThres(o.occupancy_threshold);
}
}  // namespace

// The voxels a sweep touches, as bits: blocks of 16^3 voxels (found by their packed block key in an
// open-addressing table, the last one cached: a ray's consecutive keys are neighbours), in each a
// bit per voxel for "a ray crossed it", "an endpoint of the sweep", "an endpoint of the current
// slice". A voxel's bit index in its block is its Morton code (x in the lowest bit, as octomap's
// child index), and forEach() visits the blocks in Morton order of their keys: the voxels come in
// the tree's depth-first order, so consecutive updates share most of their path down. Reused
// across sweeps (blocks are kept and cleared, not freed).
class SweepVoxels {
 public:
  static constexpr int kBits = 4;  // a block spans 2^kBits keys per axis
  static constexpr int kWords = (1 << (3 * kBits)) / 64;
  static constexpr unsigned kMask = (1u << kBits) - 1;

  void clear() {
    for (size_t i = 0; i < used_; ++i) slots_[blocks_[i]->slot] = Slot{};
    used_ = 0;
    last_ = nullptr;
  }
  // marks the voxels a ray crosses from origin (key origin_key) towards end (forEachRayKey's keys)
  void addRay(const ::octomap::OcTree& keys, const ::octomap::point3d& origin, const ::octomap::OcTreeKey& origin_key,
              const ::octomap::point3d& end) {
    RayWalker w{*this};
    walkRayKeys(keys, origin, origin_key, end, w);
  }
  void addHit(const ::octomap::OcTreeKey& k) { set(k, &Block::hit); }
  // true if k was not yet an endpoint of this slice
  bool addEndpoint(const ::octomap::OcTreeKey& k) {
    Block& b = block(k);
    const unsigned i = local(k);
    uint64_t& w = b.endpoint[i >> 6];
    const uint64_t bit = uint64_t{1} << (i & 63);
    if (w & bit) return false;
    if (!w) endpoint_words_.push_back(&w);
    w |= bit;
    return true;
  }
  void endSlice() {
    for (uint64_t* w : endpoint_words_) *w = 0;
    endpoint_words_.clear();
  }
  // f(key, hit) for each voxel crossed or hit, in the tree's depth-first order
  template <class F>
  void forEach(F&& f) {
    order_.clear();
    for (size_t i = 0; i < used_; ++i) order_.emplace_back(morton(blocks_[i]->key), blocks_[i].get());
    std::sort(order_.begin(), order_.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& [code, b] : order_) {
      (void)code;
      const unsigned x0 = unsigned(b->key >> 32) << kBits, y0 = unsigned((b->key >> 16) & 0xFFFF) << kBits,
                     z0 = unsigned(b->key & 0xFFFF) << kBits;
      for (int w = 0; w < kWords; ++w) {
        uint64_t m = b->free[w] | b->hit[w];
        while (m) {
          const int bit = __builtin_ctzll(m);
          m &= m - 1;
          const unsigned c = tables().coords[(w << 6) | bit];
          const ::octomap::OcTreeKey k(static_cast<::octomap::key_type>(x0 | (c & kMask)),
                                       static_cast<::octomap::key_type>(y0 | ((c >> kBits) & kMask)),
                                       static_cast<::octomap::key_type>(z0 | (c >> (2 * kBits))));
          f(k, (b->hit[w] >> bit) & 1);
        }
      }
    }
  }

 private:
  struct Block {
    uint64_t key = 0;
    size_t slot = 0;
    uint64_t free[kWords];
    uint64_t hit[kWords];
    uint64_t endpoint[kWords];
  };
  struct Slot {
    uint64_t key_plus1 = 0;  // 0: empty
    Block* block = nullptr;
  };
  struct Tables {
    std::array<uint16_t, 1 << kBits> spread{};        // kBits bits -> every third bit
    std::array<uint16_t, 1 << (3 * kBits)> coords{};  // Morton index -> x | y << kBits | z << 2 kBits
    Tables() {
      for (unsigned v = 0; v < (1u << kBits); ++v)
        for (int j = 0; j < kBits; ++j) spread[v] = uint16_t(spread[v] | (((v >> j) & 1u) << (3 * j)));
      for (unsigned x = 0; x < (1u << kBits); ++x)
        for (unsigned y = 0; y < (1u << kBits); ++y)
          for (unsigned z = 0; z < (1u << kBits); ++z)
            coords[spread[x] | (spread[y] << 1) | (spread[z] << 2)] = uint16_t(x | (y << kBits) | (z << (2 * kBits)));
    }
  };
  static_assert(kBits >= 2 && kBits <= 5, "a block's voxel index and coordinates fit 16 bits");
  // a step moves the key by one along one axis: the voxel's block and index follow by one add
  // on that axis's index bits, the block looked up again only when the step leaves it (dir 0
  // does not come: an axis the ray does not move along never has the nearest border; it would
  // leave the voxel as it is)
  struct RayWalker {
    SweepVoxels& v;
    Block* b = nullptr;
    unsigned i = 0;
    void start(const ::octomap::OcTreeKey& k) {
      b = &v.block(k);
      i = local(k);
      mark();
    }
    template <int A>
    __attribute__((always_inline)) void step(int dir, const ::octomap::OcTreeKey& k) {
      if (dir > 0) {
        if (morton::atTop<A, kBits>(i)) b = &v.block(k);
        i = morton::up<A, kBits>(i);
      } else if (dir < 0) {
        if (morton::atBottom<A, kBits>(i)) b = &v.block(k);
        i = morton::down<A, kBits>(i);
      }
      mark();
    }
    __attribute__((always_inline)) void mark() { b->free[i >> 6] |= uint64_t{1} << (i & 63); }
  };
  static const Tables& tables() {
    static const Tables t;
    return t;
  }
  __attribute__((always_inline)) static unsigned local(const ::octomap::OcTreeKey& k) {
    const auto& s = tables().spread;
    constexpr unsigned m = (1u << kBits) - 1;
    return unsigned(s[k[0] & m]) | (unsigned(s[k[1] & m]) << 1) | (unsigned(s[k[2] & m]) << 2);
  }
  static uint64_t blockKey(const ::octomap::OcTreeKey& k) {
    return (uint64_t(k[0] >> kBits) << 32) | (uint64_t(k[1] >> kBits) << 16) | uint64_t(k[2] >> kBits);
  }
  // interleaved block coordinates, highest level first, x in the lowest bit of each triple
  static uint64_t morton(uint64_t key) {
    const uint64_t x = key >> 32, y = (key >> 16) & 0xFFFF, z = key & 0xFFFF;
    uint64_t code = 0;
    for (int d = 16 - kBits - 1; d >= 0; --d)
      code = (code << 3) | ((x >> d) & 1) | (((y >> d) & 1) << 1) | (((z >> d) & 1) << 2);
    return code;
  }
  __attribute__((always_inline)) void set(const ::octomap::OcTreeKey& k, uint64_t (Block::*bits)[kWords]) {
    const unsigned i = local(k);
    (block(k).*bits)[i >> 6] |= uint64_t{1} << (i & 63);
  }
  __attribute__((always_inline)) Block& block(const ::octomap::OcTreeKey& k) {
    const uint64_t key = blockKey(k);
    if (last_key_ == key && last_) return *last_;
    return find(key);
  }
  __attribute__((noinline)) Block& find(uint64_t key) {
    if ((used_ + 1) * 2 > slots_.size()) grow();
    const size_t mask = slots_.size() - 1;
    size_t i = hash(key);
    while (slots_[i].key_plus1 && slots_[i].key_plus1 != key + 1) i = (i + 1) & mask;
    if (!slots_[i].key_plus1) {
      if (used_ == blocks_.size()) blocks_.push_back(std::make_unique<Block>());
      Block* b = blocks_[used_++].get();
      std::fill(std::begin(b->free), std::end(b->free), 0);
      std::fill(std::begin(b->hit), std::end(b->hit), 0);
      std::fill(std::begin(b->endpoint), std::end(b->endpoint), 0);
      b->key = key;
      b->slot = i;
      slots_[i] = Slot{key + 1, b};
    }
    last_key_ = key;
    last_ = slots_[i].block;
    return *last_;
  }
  // Fibonacci hashing: the product's top bits depend on every bit of the key (middle bits would
  // barely see x, which sits in bits 32+ of the key, and a whole axis could collide)
  size_t hash(uint64_t key) const { return static_cast<size_t>((key * 0x9E3779B97F4A7C15ull) >> slot_shift_); }
  void grow() {
    slots_.assign(std::max<size_t>(1 << 12, slots_.size() * 2), Slot{});
    slot_shift_ = 64 - __builtin_ctzll(slots_.size());
    const size_t mask = slots_.size() - 1;
    for (size_t j = 0; j < used_; ++j) {
      Block* b = blocks_[j].get();
      size_t i = hash(b->key);
      while (slots_[i].key_plus1) i = (i + 1) & mask;
      slots_[i] = Slot{b->key + 1, b};
      b->slot = i;
    }
  }

  std::vector<Slot> slots_;
  int slot_shift_ = 64;                         // 64 - log2(slots_.size())
  std::vector<std::unique_ptr<Block>> blocks_;  // [0, used_) in use this sweep
  size_t used_ = 0;
  Block* last_ = nullptr;
  uint64_t last_key_ = 0;
  std::vector<uint64_t*> endpoint_words_;  // endpoint words set in the current slice
  std::vector<std::pair<uint64_t, Block*>> order_;
};

struct OccupancyMap::Scratch {
  SweepVoxels voxels;
};

// What the levels above the tiles need of a tile's root (the node at the tiles' depth), and the
// size of its subtree in the format being written.
struct OccupancyMap::TileSummary {
  uint64_t index = 0;
  uint64_t morton = 0;   // the tile's place in the tree's depth-first order
  float log_odds = 0.f;  // full format: the root's value and colour
  std::array<uint8_t, 3> rgb{{255, 255, 255}};
  bool leaf = false;      // binary: the root is a (maximum-likelihood) leaf ...
  bool occupied = false;  // ... and occupied
  uint64_t nodes = 0;     // nodes of its subtree in this format
  bool present = false;   // the tile holds a node at all
};

struct OccupancyMap::Tile {
  std::unique_ptr<::octomap::AbstractOccupancyOcTree> tree;  // resident
  bool spilled = false;
  int64_t last_used = INT64_MIN;
  bool dirty = false;  // inner nodes not refreshed since the last update
  // on disk: the tree's node stream (octomap's full format from the root: after the levels above
  // the tile's root it is the tile's part of a .ot as it is) and the tile's part of a .bt, with
  // what the levels above need of each, so a file is written without decoding a tile on disk
  SpillFile::Record record;
  uint64_t full_offset = 0;  // bytes of `record` before the tile's root
  SpillFile::Record binary;
  TileSummary full_summary, binary_summary;
  size_t leaves = 0;  // on disk: its leaf count
};

namespace {
constexpr int kTreeDepth = 16;  // octomap's key depth

// Log-odds updates of finest-level leaves, as octomap's updateNode(key, log_odds, lazy_eval = true)
// makes them (same clamping and early abort, the same nodes created or expanded, so the tree is the
// same), but walking down only from the deepest node the key shares with the previous one: keys in
// depth-first order share most of their path, so most updates cost a few pointer steps instead of
// two full descents (octomap's search, then updateNodeRecurs). Only an empty tree goes to octomap's
// updateNode (it creates the root).
template <class Tree>
class LeafUpdater {
 public:
  using Node = typename Tree::NodeType;
  explicit LeafUpdater(Tree& t) : t_(t), depth_(static_cast<int>(t.getTreeDepth())) {}

  void update(const ::octomap::OcTreeKey& key, float log_odds) {
    path_[0] = t_.getRoot();
    if (!path_[0]) {
      t_.updateNode(key, log_odds, true);
      valid_ = 0;
      return;
    }
    // the node at depth d is fixed by the key bits above depth_ - 1 - d: shared up to the highest
    // bit in which the keys differ
    int d = 0;
    if (valid_ > 0) {
      const unsigned diff = unsigned(key[0] ^ prev_[0]) | unsigned(key[1] ^ prev_[1]) | unsigned(key[2] ^ prev_[2]);
      const int highest = diff ? 31 - __builtin_clz(diff) : -1;
      d = std::min(valid_, depth_ - 1 - highest);
    }
    prev_ = key;
    for (; d < depth_; ++d) {
      const unsigned pos = ::octomap::computeChildIdx(key, depth_ - 1 - d);
      if (!t_.nodeChildExists(path_[d], pos)) {
        grow(key, log_odds, d, pos);
        return;
      }
      path_[d + 1] = t_.getNodeChild(path_[d], pos);
    }
    valid_ = depth_;
    // the leaf's value is rarely in the cache (a node each, allocated as the tree grew): it is
    // fetched now and updated kAhead updates later, the walk down meanwhile overlapping the miss
    // (a leaf's update touches only the leaf, and a sweep updates each leaf once)
    Node* leaf = path_[depth_];
    __builtin_prefetch(leaf, 1);
    Pending& p = pending_[queued_++ % kAhead];
    if (queued_ > kAhead) apply(p);
    p = Pending{leaf, log_odds};
  }
  // the updates still pending; due before the tree is used otherwise
  void flush() {
    for (size_t n = queued_ > kAhead ? queued_ - kAhead : 0; n < queued_; ++n) apply(pending_[n % kAhead]);
    queued_ = 0;
  }

 private:
  // no change: the value is at the clamping bound the update goes to
  bool clamped(float value, float log_odds) const {
    return (log_odds >= 0 && value >= t_.getClampingThresMaxLog()) ||
           (log_odds <= 0 && value <= t_.getClampingThresMinLog());
  }
  // path_[d] has no child `pos` on the key's way: as octomap's updateNode, a node without children
  // (a pruned one: search() ends there) that is clamped is left as it is, else expanded; a node
  // with other children gets the child, and so do the nodes created below it
  void grow(const ::octomap::OcTreeKey& key, float log_odds, int d, unsigned pos) {
    bool created = false;
    Node* n = path_[d];
    if (!t_.nodeHasChildren(n)) {
      if (clamped(n->getLogOdds(), log_odds)) {
        valid_ = d;
        return;
      }
      t_.expandNode(n);
    } else {
      t_.createNodeChild(n, pos);
      created = true;
    }
    path_[d + 1] = t_.getNodeChild(n, pos);
    for (++d; d < depth_; ++d) {
      n = path_[d];
      pos = ::octomap::computeChildIdx(key, depth_ - 1 - d);
      if (!t_.nodeChildExists(n, pos)) {
        if (!created && !t_.nodeHasChildren(n)) {
          t_.expandNode(n);
        } else {
          t_.createNodeChild(n, pos);
          created = true;
        }
      }
      path_[d + 1] = t_.getNodeChild(n, pos);
    }
    valid_ = depth_;
    t_.updateNodeLogOdds(path_[depth_], log_odds);
  }

  struct Pending {
    Node* leaf = nullptr;
    float log_odds = 0.f;
  };
  static constexpr size_t kAhead = 8;
  void apply(const Pending& p) {
    if (!clamped(p.leaf->getLogOdds(), p.log_odds)) t_.updateNodeLogOdds(p.leaf, p.log_odds);
  }

  Tree& t_;
  const int depth_;
  std::array<Pending, kAhead> pending_{};
  size_t queued_ = 0;             // updates queued; the last min(queued_, kAhead) are pending
  std::array<Node*, 17> path_{};  // path_[d]: node at depth d (tree depth <= 16)
  ::octomap::OcTreeKey prev_;
  int valid_ = 0;  // path_[0 .. valid_] matches prev_
};

// Casts the sweep into the voxel sets (on the key arithmetic of `keys`), then updates the leaves in
// the trees of their tiles (`tree_of(tile index)`): each voxel once a sweep, a hit if some ray ends
// there, else a miss (the order of the updates does not change the tree: each is of another leaf).
template <class Tree, class TreeOf, class TileOf>
size_t integrate(const ::octomap::OcTree& keys, const std::vector<OccupancyMap::Slice>& slices, const OctomapOptions& o,
                 OccupancyMap::Scratch& s, TreeOf tree_of, TileOf tile_of) {
  SweepVoxels& v = s.voxels;
  v.clear();
  const double min2 = o.min_range * o.min_range;
  size_t rays = 0;
  for (const OccupancyMap::Slice& slice : slices) {
    if (!slice.points || !slice.origin.allFinite()) continue;
    const ::octomap::point3d origin(slice.origin.x(), slice.origin.y(), slice.origin.z());
    ::octomap::OcTreeKey origin_key;
    const bool origin_in_range = keys.coordToKeyChecked(origin, origin_key);  // else no ray clears
    for (const Eigen::Vector3f& p : *slice.points) {
      if (!p.allFinite()) continue;
      const Eigen::Vector3d d = p.cast<double>() - slice.origin;
      const double r2 = d.squaredNorm();
      if (r2 < min2) continue;
      ::octomap::OcTreeKey key;
      if (!keys.coordToKeyChecked(::octomap::point3d(p.x(), p.y(), p.z()), key)) continue;
      ++rays;
      if (!v.addEndpoint(key)) continue;  // one ray per endpoint voxel and slice
      // discretised: the ray ends at the endpoint voxel's centre
      ::octomap::point3d end = keys.keyToCoord(key);
      bool hit = true;
      const double r = std::sqrt(r2);
      if (o.max_range > 0.0 && r > o.max_range) {
        end = origin + (end - origin).normalized() * float(o.max_range);
        hit = false;
      } else if (o.free_margin > 0.0) {
        // clear only up to free_margin before the endpoint (nothing if the ray is shorter)
        const double length = (end - origin).norm();
        end = origin + (end - origin) * float(std::max(0.0, length - o.free_margin) / std::max(length, 1e-9));
      }
      if (hit) v.addHit(key);
      if (origin_in_range) v.addRay(keys, origin, origin_key, end);
    }
    v.endSlice();
  }
  // one updater per tile (each keeps its own path), the last one cached: in depth-first order the
  // keys stay in a tile for long runs
  std::map<uint64_t, std::unique_ptr<LeafUpdater<Tree>>> updaters;
  uint64_t last_tile = ~uint64_t{0};
  LeafUpdater<Tree>* updater = nullptr;
  const float miss = keys.getProbMissLog(), hit = keys.getProbHitLog();
  v.forEach([&](const ::octomap::OcTreeKey& key, bool is_hit) {
    const uint64_t tile = tile_of(key);
    if (tile != last_tile || !updater) {
      auto& u = updaters[tile];
      if (!u) u = std::make_unique<LeafUpdater<Tree>>(*tree_of(tile));
      updater = u.get();
      last_tile = tile;
    }
    updater->update(key, is_hit ? hit : miss);
  });
  for (auto& [tile, u] : updaters) u->flush();
  return rays;
}

// Calls f with the tree as the type it is (an OcTree or a ColorOcTree).
template <class F>
decltype(auto) withTree(bool colour, ::octomap::AbstractOccupancyOcTree& t, F&& f) {
  if (colour) return f(static_cast<::octomap::ColorOcTree&>(t));
  return f(static_cast<::octomap::OcTree&>(t));
}

// The node at `depth` on the tile's one path down (the levels above a tile hold one child each).
template <class Tree>
const typename Tree::NodeType* tileRoot(const Tree& t, int depth) {
  const auto* node = t.getRoot();
  for (int d = 0; node && d < depth; ++d) {
    const typename Tree::NodeType* next = nullptr;
    for (unsigned i = 0; i < 8; ++i) {
      if (!t.nodeChildExists(node, i)) continue;
      if (next) throw std::logic_error("octomap tile: more than one path above the tile's root");
      next = t.getNodeChild(node, i);
    }
    node = next;
  }
  return node;
}

// octomap's full format (writeNodesRecurs): the node's data, a byte of the children that exist,
// the children. Returns the nodes written (out null: only counted).
template <class Tree>
uint64_t writeFullNode(const Tree& t, const typename Tree::NodeType* node, std::ostream* out) {
  uint8_t children = 0;
  for (unsigned i = 0; i < 8; ++i)
    if (t.nodeChildExists(node, i)) children |= uint8_t(1u << i);
  if (out) {
    node->writeData(*out);
    out->write(reinterpret_cast<const char*>(&children), 1);
  }
  uint64_t n = 1;
  for (unsigned i = 0; i < 8; ++i)
    if (children & (1u << i)) n += writeFullNode(t, t.getNodeChild(node, i), out);
  return n;
}

// octomap's binary format of the maximum-likelihood tree, pruned (what OcTree::writeBinary
// writes after toMaxLikelihood() and prune()): a node whose eight children are leaves of one
// occupancy is a leaf. encode() appends a node's content (two bytes of 2-bit child codes, then the
// children's contents) to *out unless the node is a leaf.
struct BinaryNode {
  bool leaf = false;
  bool occupied = false;
  uint64_t nodes = 1;
};
inline void putChildCode(uint8_t codes[2], unsigned i, const BinaryNode& c) {
  // 10 free leaf, 01 occupied leaf, 11 inner (bit 2i is the first of the pair)
  const unsigned bits = !c.leaf ? 3u : (c.occupied ? 2u : 1u);
  codes[i / 4] |= uint8_t(bits << (2 * (i % 4)));
}
template <class Tree>
BinaryNode encodeBinary(const Tree& t, const typename Tree::NodeType* node, std::string* out, bool may_be_leaf = true) {
  BinaryNode me;
  if (!t.nodeHasChildren(node)) {
    if (may_be_leaf) {
      me.leaf = true;
      me.occupied = t.isNodeOccupied(node);
      return me;
    }
    out->append(2, '\0');  // the root of the tree: an inner node without children
    return me;
  }
  std::array<BinaryNode, 8> child{};
  std::array<bool, 8> exists{};
  std::string below;
  bool uniform = true;
  for (unsigned i = 0; i < 8; ++i) {
    exists[i] = t.nodeChildExists(node, i);
    if (!exists[i]) {
      uniform = false;
      continue;
    }
    child[i] = encodeBinary(t, t.getNodeChild(node, i), &below);
    uniform = uniform && child[i].leaf && child[i].occupied == child[0].occupied;
  }
  if (uniform && may_be_leaf) {
    me.leaf = true;
    me.occupied = child[0].occupied;
    return me;
  }
  uint8_t codes[2] = {0, 0};
  for (unsigned i = 0; i < 8; ++i) {
    if (!exists[i]) continue;
    putChildCode(codes, i, child[i]);
    me.nodes += child[i].nodes;
  }
  out->append(reinterpret_cast<const char*>(codes), 2);
  out->append(below);
  return me;
}

std::string header(bool colour, double resolution, bool binary, uint64_t nodes) {
  // octomap's headers (AbstractOcTree::write, OcTree::writeBinaryConst), written here: octomap's
  // own writers print to the console
  std::ostringstream s;
  s << (binary ? "# Octomap OcTree binary file" : "# Octomap OcTree file")
    << "\n# (feel free to add / change comments, but leave the first line as it is!)\n#\n"
    << "id " << (colour && !binary ? "ColorOcTree" : "OcTree") << "\nsize " << nodes << "\nres " << resolution
    << "\ndata\n";
  return s.str();
}
}  // namespace

OccupancyMap::OccupancyMap(const OctomapOptions& options)
    : options_(options),
      keys_(std::make_unique<::octomap::OcTree>(options.resolution)),
      scratch_(std::make_unique<Scratch>()) {
  configure(keys_.get(), options_);
  if (options_.tile_size > 0.0) {
    const double voxels = options_.tile_size / options_.resolution;
    tile_bits_ = std::clamp(static_cast<int>(std::lround(std::log2(std::max(voxels, 2.0)))), 1, kTreeDepth);
  }
}
OccupancyMap::~OccupancyMap() = default;
OccupancyMap::OccupancyMap(OccupancyMap&&) noexcept = default;
OccupancyMap& OccupancyMap::operator=(OccupancyMap&&) noexcept = default;

void OccupancyMap::clear() {
  tiles_.clear();
  spill_.reset();
}

std::unique_ptr<::octomap::AbstractOccupancyOcTree> OccupancyMap::newTree() const {
  if (options_.colour) {
    auto t = std::make_unique<::octomap::ColorOcTree>(options_.resolution);
    configure(t.get(), options_);
    return t;
  }
  auto t = std::make_unique<::octomap::OcTree>(options_.resolution);
  configure(t.get(), options_);
  return t;
}

OccupancyMap::Tile& OccupancyMap::residentTile(uint64_t tile_index) {
  std::unique_ptr<Tile>& slot = tiles_[tile_index];
  if (!slot) slot = std::make_unique<Tile>();
  Tile& t = *slot;
  if (t.spilled) {
    std::unique_ptr<::octomap::AbstractOccupancyOcTree> back;
    treeOf(t, &back);
    t.tree = std::move(back);
    spill_->release(t.record);  // the disk space goes back (written again when it goes)
    spill_->release(t.binary);
    t.spilled = false;
    t.leaves = 0;
  } else if (!t.tree) {
    t.tree = newTree();
  }
  t.last_used = now_;
  t.dirty = true;
  return t;
}

::octomap::AbstractOccupancyOcTree& OccupancyMap::treeOf(
    const Tile& tile, std::unique_ptr<::octomap::AbstractOccupancyOcTree>* holder) const {
  if (!tile.spilled) return *tile.tree;
  std::vector<uint8_t> bytes;
  spill_->read(tile.record, &bytes);
  std::istringstream in(std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
  *holder = newTree();
  withTree(options_.colour, **holder, [&](auto& t) {
    t.readData(in);
    return 0;
  });
  if (!in) throw std::runtime_error("octomap: a tile read back from the scratch file is incomplete");
  return **holder;
}

OccupancyMap::TileSummary OccupancyMap::summarize(const ::octomap::AbstractOccupancyOcTree& tree, Format format,
                                                  std::string* payload) const {
  const int depth = kTreeDepth - tile_bits_;
  TileSummary s;
  withTree(options_.colour, const_cast<::octomap::AbstractOccupancyOcTree&>(tree), [&](auto& t) {
    const auto* root = tileRoot(t, depth);
    if (!root) return 0;
    s.present = true;
    s.log_odds = root->getLogOdds();
    if constexpr (std::is_same_v<std::decay_t<decltype(t)>, ::octomap::ColorOcTree>) {
      const auto c = root->getColor();
      s.rgb = {c.r, c.g, c.b};
    }
    if (format == Format::kBinary) {
      std::string scratch;
      const BinaryNode b = encodeBinary(t, root, payload ? payload : &scratch, depth > 0);
      s.leaf = b.leaf;
      s.occupied = b.occupied;
      s.nodes = b.nodes;
    } else if (payload) {
      std::ostringstream out;
      s.nodes = writeFullNode(t, root, &out);
      *payload = out.str();
    } else {
      s.nodes = writeFullNode(t, root, nullptr);
    }
    return 0;
  });
  return s;
}

void OccupancyMap::spill(Tile* tile) {
  std::ostringstream out;
  withTree(options_.colour, *tile->tree, [&](auto& t) {
    t.updateInnerOccupancy();
    // lossless for an OcTree (eight equal leaves); a ColorOcTree would average their colours
    if (!options_.colour) t.prune();
    tile->leaves = t.getNumLeafNodes();
    t.writeData(out);  // no header: read back into a tree of the type (octomap's read() prints)
    // the levels above the tile's root hold one node each: its data and a byte of children
    using Node = typename std::decay_t<decltype(t)>::NodeType;
    std::ostringstream one;
    Node().writeData(one);
    tile->full_offset = static_cast<uint64_t>(kTreeDepth - tile_bits_) * (one.str().size() + 1);
    return 0;
  });
  const std::string bytes = out.str();
  std::string binary_bytes;
  tile->full_summary = summarize(*tile->tree, Format::kFull, nullptr);
  tile->binary_summary = summarize(*tile->tree, Format::kBinary, &binary_bytes);
  if (!spill_) spill_ = std::make_unique<SpillFile>();
  tile->record = spill_->append(bytes.data(), bytes.size());
  tile->binary = spill_->append(binary_bytes.data(), binary_bytes.size());
  tile->tree.reset();
  tile->spilled = true;
  tile->dirty = false;
}

size_t OccupancyMap::evictIdle() {
  // pruning is lossless for an OcTree (eight equal leaves become their parent; an update below
  // expands it again) and keeps the free space a sweep clears to a few nodes once it is clamped
  if (!options_.colour && !tiles_.empty()) {
    auto it = tiles_.lower_bound(prune_next_);
    for (size_t tried = 0; tried < tiles_.size(); ++tried, ++it) {
      if (it == tiles_.end()) it = tiles_.begin();
      if (it->second->spilled) continue;
      static_cast<::octomap::OcTree&>(*it->second->tree).prune();
      prune_next_ = it->first + 1;
      break;
    }
  }
  if (options_.tile_idle_s <= 0.0 || now_ == INT64_MIN) return 0;
  const int64_t before = now_ - static_cast<int64_t>(options_.tile_idle_s * 1e6);
  size_t n = 0;
  for (auto& [index, tile] : tiles_) {
    if (tile->spilled || tile->last_used >= before) continue;
    spill(tile.get());
    ++n;
  }
  return n;
}

size_t OccupancyMap::residentTiles() const {
  return static_cast<size_t>(
      std::count_if(tiles_.begin(), tiles_.end(), [](const auto& t) { return !t.second->spilled; }));
}
size_t OccupancyMap::spilledTiles() const { return tiles_.size() - residentTiles(); }
uint64_t OccupancyMap::spilledBytes() const { return spill_ ? spill_->liveBytes() : 0; }

void OccupancyMap::refreshResident() const {
  for (const auto& [index, tile] : tiles_) {
    if (tile->spilled || !tile->dirty) continue;
    withTree(options_.colour, *tile->tree, [](auto& t) {
      t.updateInnerOccupancy();
      return 0;
    });
    tile->dirty = false;
  }
}

size_t OccupancyMap::insertRays(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3d& origin) {
  Slice s;
  s.origin = origin;
  s.points = &points;
  return insertSweep({s});
}

size_t OccupancyMap::insertSweep(const std::vector<Slice>& slices) {
  const int b = tile_bits_;
  auto tile_of = [b](const ::octomap::OcTreeKey& k) {
    return (uint64_t(k[0] >> b) << 32) | (uint64_t(k[1] >> b) << 16) | uint64_t(k[2] >> b);
  };
  if (options_.colour) {
    return integrate<::octomap::ColorOcTree>(
        *keys_, slices, options_, *scratch_,
        [&](uint64_t i) { return static_cast<::octomap::ColorOcTree*>(residentTile(i).tree.get()); }, tile_of);
  }
  return integrate<::octomap::OcTree>(
      *keys_, slices, options_, *scratch_,
      [&](uint64_t i) { return static_cast<::octomap::OcTree*>(residentTile(i).tree.get()); }, tile_of);
}

size_t OccupancyMap::setColours(const std::vector<Eigen::Vector3f>& points,
                                const std::vector<std::array<uint8_t, 3>>& rgb) {
  if (!options_.colour) return 0;
  size_t n = 0;
  for (size_t i = 0; i < points.size() && i < rgb.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite()) continue;
    ::octomap::OcTreeKey key;
    if (!keys_->coordToKeyChecked(::octomap::point3d(p.x(), p.y(), p.z()), key)) continue;
    const uint64_t index = (uint64_t(key[0] >> tile_bits_) << 32) | (uint64_t(key[1] >> tile_bits_) << 16) |
                           uint64_t(key[2] >> tile_bits_);
    if (!tiles_.count(index)) continue;  // nothing mapped there
    auto& tree = static_cast<::octomap::ColorOcTree&>(*residentTile(index).tree);
    ::octomap::ColorOcTreeNode* node = tree.search(key);
    if (!node || !tree.isNodeOccupied(node)) continue;
    tree.averageNodeColor(key, rgb[i][0], rgb[i][1], rgb[i][2]);
    ++n;
  }
  return n;
}

int OccupancyMap::classify(const Eigen::Vector3d& p) const {
  refreshResident();
  ::octomap::OcTreeKey key;
  if (!keys_->coordToKeyChecked(::octomap::point3d(p.x(), p.y(), p.z()), key)) return -1;
  const uint64_t index =
      (uint64_t(key[0] >> tile_bits_) << 32) | (uint64_t(key[1] >> tile_bits_) << 16) | uint64_t(key[2] >> tile_bits_);
  auto it = tiles_.find(index);
  if (it == tiles_.end()) return -1;
  std::unique_ptr<::octomap::AbstractOccupancyOcTree> holder;
  return withTree(options_.colour, treeOf(*it->second, &holder), [&](auto& t) {
    const auto* n = t.search(key);
    return n ? (t.isNodeOccupied(n) ? 1 : 0) : -1;
  });
}

std::vector<Eigen::Vector3d> OccupancyMap::occupiedVoxels() const {
  refreshResident();
  std::vector<Eigen::Vector3d> out;
  for (const auto& [index, tile] : tiles_) {
    std::unique_ptr<::octomap::AbstractOccupancyOcTree> holder;
    withTree(options_.colour, treeOf(*tile, &holder), [&](auto& t) {
      const double res = t.getResolution();
      for (auto it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it) {
        if (!t.isNodeOccupied(*it)) continue;
        const double size = it.getSize();
        const int n = std::max(1, static_cast<int>(std::lround(size / res)));
        const ::octomap::point3d c = it.getCoordinate();
        const double start = -0.5 * size + 0.5 * res;
        for (int i = 0; i < n; ++i)
          for (int j = 0; j < n; ++j)
            for (int k = 0; k < n; ++k)
              out.emplace_back(c.x() + start + i * res, c.y() + start + j * res, c.z() + start + k * res);
      }
      return 0;
    });
  }
  return out;
}

size_t OccupancyMap::leafCount() const {
  refreshResident();
  size_t n = 0;
  for (const auto& [index, tile] : tiles_)
    n += tile->spilled ? tile->leaves
                       : withTree(options_.colour, *tile->tree, [](auto& t) { return t.getNumLeafNodes(); });
  return n;
}

// The tiles' summaries in the tree's depth-first order, and the levels above them: node (d, range
// of tiles), whose child i holds the tiles whose code at level d is i.
struct OccupancyMap::TileLevels {
  std::vector<TileSummary> tiles;  // by morton code
  int depth = 0;                   // of the tiles' roots

  unsigned childCode(size_t tile, int d) const { return unsigned(tiles[tile].morton >> (3 * (depth - 1 - d))) & 7u; }
  // the ranges of tiles of the children of node (d, [lo, hi)); empty ranges for the absent ones
  std::array<std::pair<size_t, size_t>, 8> children(size_t lo, size_t hi, int d) const {
    std::array<std::pair<size_t, size_t>, 8> out;
    out.fill({0, 0});
    for (size_t a = lo; a < hi;) {
      size_t b = a;
      while (b < hi && childCode(b, d) == childCode(a, d)) ++b;
      out[childCode(a, d)] = {a, b};
      a = b;
    }
    return out;
  }
  // value and colour of a node above the tiles as octomap's updateInnerOccupancy makes them
  // (maximum child log-odds; the integer mean of the children's colours that are set, else white),
  // and the nodes of its subtree in the full format
  struct Inner {
    float log_odds = 0.f;
    std::array<uint8_t, 3> rgb{{255, 255, 255}};
    uint64_t nodes = 0;
  };
  Inner inner(size_t lo, size_t hi, int d) const {
    if (d == depth) return Inner{tiles[lo].log_odds, tiles[lo].rgb, tiles[lo].nodes};
    Inner me;
    me.nodes = 1;
    me.log_odds = -std::numeric_limits<float>::max();
    int sum[3] = {0, 0, 0}, coloured = 0;
    for (const auto& [a, b] : children(lo, hi, d)) {
      if (a == b) continue;
      const Inner c = inner(a, b, d + 1);
      me.nodes += c.nodes;
      me.log_odds = std::max(me.log_odds, c.log_odds);
      if (!(c.rgb[0] == 255 && c.rgb[1] == 255 && c.rgb[2] == 255)) {
        for (int k = 0; k < 3; ++k) sum[k] += c.rgb[k];
        ++coloured;
      }
    }
    if (coloured > 0)
      for (int k = 0; k < 3; ++k) me.rgb[k] = static_cast<uint8_t>(sum[k] / coloured);
    return me;
  }
  // the nodes of the subtree of node (d, [lo, hi)) in the binary format: the levels above the tiles
  // are inner nodes (one per distinct prefix); tiles' roots that are leaves count one node each
  // (their BinaryNode says so)
  uint64_t binaryNodes(size_t lo, size_t hi, int d) const {
    if (d == depth) return tiles[lo].nodes;
    uint64_t n = 1;
    for (const auto& [a, b] : children(lo, hi, d))
      if (a != b) n += binaryNodes(a, b, d + 1);
    return n;
  }
};

OccupancyMap::TileLevels OccupancyMap::tileLevels(Format format, bool resident_only) const {
  TileLevels levels;
  levels.depth = kTreeDepth - tile_bits_;
  const bool binary = format == Format::kBinary;
  for (const auto& [index, tile] : tiles_) {
    if (resident_only && tile->spilled) continue;
    TileSummary s =
        tile->spilled ? (binary ? tile->binary_summary : tile->full_summary) : summarize(*tile->tree, format, nullptr);
    if (!s.present) continue;
    s.index = index;
    // depth-first order: at every level the child index (x bit 1, y bit 2, z bit 4)
    const uint64_t x = index >> 32, y = (index >> 16) & 0xFFFF, z = index & 0xFFFF;
    s.morton = 0;
    for (int d = levels.depth - 1; d >= 0; --d)
      s.morton = (s.morton << 3) | (((x >> d) & 1) | (((y >> d) & 1) << 1) | (((z >> d) & 1) << 2));
    levels.tiles.push_back(s);
  }
  std::sort(levels.tiles.begin(), levels.tiles.end(),
            [](const TileSummary& a, const TileSummary& b) { return a.morton < b.morton; });
  return levels;
}

void OccupancyMap::writeTilePayload(std::ostream& out, const TileSummary& s, Format format) const {
  const bool binary = format == Format::kBinary;
  const Tile& tile = *tiles_.at(s.index);
  if (tile.spilled) {  // as written when it went to disk
    std::vector<uint8_t> bytes;
    spill_->read(binary ? tile.binary : tile.record, &bytes);
    const size_t skip = binary ? 0 : tile.full_offset;
    out.write(reinterpret_cast<const char*>(bytes.data()) + skip, static_cast<std::streamsize>(bytes.size() - skip));
    return;
  }
  std::string bytes;
  summarize(*tile.tree, format, &bytes);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

void OccupancyMap::writeLevel(std::ostream& out, const TileLevels& levels, size_t lo, size_t hi, int d,
                              Format format) const {
  if (d == levels.depth) {
    writeTilePayload(out, levels.tiles[lo], format);
    return;
  }
  const std::array<std::pair<size_t, size_t>, 8> children = levels.children(lo, hi, d);
  if (format == Format::kBinary) {
    uint8_t codes[2] = {0, 0};
    for (unsigned i = 0; i < 8; ++i) {
      const auto [a, b] = children[i];
      if (a == b) continue;
      BinaryNode c;  // a level above the tiles is inner; a tile's root may be a leaf
      if (d + 1 == levels.depth) c.leaf = levels.tiles[a].leaf, c.occupied = levels.tiles[a].occupied;
      putChildCode(codes, i, c);
    }
    out.write(reinterpret_cast<const char*>(codes), 2);
    for (unsigned i = 0; i < 8; ++i) {
      const auto [a, b] = children[i];
      if (a == b || (d + 1 == levels.depth && levels.tiles[a].leaf)) continue;
      writeLevel(out, levels, a, b, d + 1, format);
    }
    return;
  }
  const TileLevels::Inner me = levels.inner(lo, hi, d);
  out.write(reinterpret_cast<const char*>(&me.log_odds), sizeof(float));
  if (options_.colour) out.write(reinterpret_cast<const char*>(me.rgb.data()), 3);
  uint8_t exists = 0;
  for (unsigned i = 0; i < 8; ++i)
    if (children[i].first != children[i].second) exists |= uint8_t(1u << i);
  out.write(reinterpret_cast<const char*>(&exists), 1);
  for (unsigned i = 0; i < 8; ++i)
    if (children[i].first != children[i].second)
      writeLevel(out, levels, children[i].first, children[i].second, d + 1, format);
}

// The one octree the tiles make, in octomap's full (.ot) or binary (.bt) format, streamed: first
// every tile's root and subtree size (the header needs the node count), then the levels above the
// tiles, each tile's subtree in its place. A tile on disk is not decoded: what the file needs of it
// was written beside it when it went there.
bool OccupancyMap::writeTree(std::ostream& out, Format format, bool resident_only) const {
  refreshResident();
  const bool binary = format == Format::kBinary;
  const TileLevels levels = tileLevels(format, resident_only);
  if (levels.tiles.empty()) {
    out << header(options_.colour, options_.resolution, binary, 0);
    return bool(out);
  }
  const size_t n = levels.tiles.size();
  const uint64_t nodes = binary ? levels.binaryNodes(0, n, 0) : levels.inner(0, n, 0).nodes;
  out << header(options_.colour, options_.resolution, binary, nodes);
  writeLevel(out, levels, 0, n, 0, format);
  return bool(out);
}

std::string OccupancyMap::binaryBytes(bool resident_only) const {
  std::ostringstream s;
  writeTree(s, Format::kBinary, resident_only);
  return s.str();
}

std::string OccupancyMap::fullBytes(bool resident_only) const {
  std::ostringstream s;
  writeTree(s, Format::kFull, resident_only);
  return s.str();
}

std::string OccupancyMap::treeType() const { return options_.colour ? "ColorOcTree" : "OcTree"; }

bool OccupancyMap::writeBinary(const std::string& path) const {
  return writeFileAtomically(path, [&](std::ostream& out) { return writeTree(out, Format::kBinary, false); });
}
bool OccupancyMap::writeFull(const std::string& path) const {
  return writeFileAtomically(path, [&](std::ostream& out) { return writeTree(out, Format::kFull, false); });
}

}  // namespace livo::octomap
