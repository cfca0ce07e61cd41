#include "occupancy_map.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

#include "livo/file_output.hpp"

namespace livo {
namespace octomap_export {

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

// Open-addressing set of packed voxel keys (3 x 16 bits), reused across sweeps: the ray casting's
// inner loop, several times faster than octomap's KeySet (an unordered_set).
class FlatKeySet {
 public:
  void clear() {
    if (size_ == 0) return;
    std::fill(slots_.begin(), slots_.end(), 0);
    size_ = 0;
    order_.clear();
  }
  // true if newly inserted
  bool insert(uint64_t packed) {
    if ((size_ + 1) * 2 > slots_.size()) grow();
    const uint64_t v = packed + 1;
    size_t i = hash(v) & (slots_.size() - 1);
    while (slots_[i]) {
      if (slots_[i] == v) return false;
      i = (i + 1) & (slots_.size() - 1);
    }
    slots_[i] = v;
    ++size_;
    order_.push_back(packed);
    return true;
  }
  bool contains(uint64_t packed) const {
    if (slots_.empty()) return false;
    const uint64_t v = packed + 1;
    size_t i = hash(v) & (slots_.size() - 1);
    while (slots_[i]) {
      if (slots_[i] == v) return true;
      i = (i + 1) & (slots_.size() - 1);
    }
    return false;
  }
  const std::vector<uint64_t>& keys() const { return order_; }  // insertion order

 private:
  static size_t hash(uint64_t v) { return static_cast<size_t>((v * 0x9E3779B97F4A7C15ull) >> 20); }
  void grow() {
    std::vector<uint64_t> old = std::move(order_);
    slots_.assign(std::max<size_t>(1 << 14, slots_.size() * 2), 0);
    size_ = 0;
    order_.clear();
    order_.reserve(slots_.size() / 2);
    for (uint64_t k : old) insert(k);
  }
  std::vector<uint64_t> slots_;
  std::vector<uint64_t> order_;
  size_t size_ = 0;
};

struct OccupancyMap::Scratch {
  FlatKeySet free, hit, endpoints;
  octomap::KeyRay ray;
};

namespace {
uint64_t pack(const octomap::OcTreeKey& k) { return (uint64_t(k[0]) << 32) | (uint64_t(k[1]) << 16) | uint64_t(k[2]); }
octomap::OcTreeKey unpack(uint64_t v) {
  return octomap::OcTreeKey(uint16_t(v >> 32), uint16_t(v >> 16), uint16_t(v));
}

// Log-odds updates of finest-level leaves, as octomap's updateNode(key, log_odds, lazy_eval = true)
// makes them (same clamping and early abort, so the tree is the same), but walking down only from
// the deepest node the key shares with the previous one: keys in ray or sweep order share most of
// their path, so most updates cost a few pointer steps instead of two full descents (octomap's
// search, then updateNodeRecurs). Missing nodes are created by octomap's updateNode.
template <class Tree>
class LeafUpdater {
 public:
  explicit LeafUpdater(Tree& t) : t_(t), depth_(static_cast<int>(t.getTreeDepth())) {}

  void update(const octomap::OcTreeKey& key, float log_odds) {
    using Node = typename Tree::NodeType;
    path_[0] = t_.getRoot();
    if (!path_[0]) {
      fallback(key, log_odds, 0);
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
    for (; d < depth_; ++d) {
      const unsigned pos = octomap::computeChildIdx(key, depth_ - 1 - d);
      if (!t_.nodeChildExists(path_[d], pos)) {
        fallback(key, log_odds, d);
        return;
      }
      path_[d + 1] = t_.getNodeChild(path_[d], pos);
    }
    Node* leaf = path_[depth_];
    const float v = leaf->getLogOdds();
    if (!((log_odds >= 0 && v >= t_.getClampingThresMaxLog()) || (log_odds <= 0 && v <= t_.getClampingThresMinLog())))
      t_.updateNodeLogOdds(leaf, log_odds);
    prev_ = key;
    valid_ = depth_;
  }

 private:
  void fallback(const octomap::OcTreeKey& key, float log_odds, int valid) {
    t_.updateNode(key, log_odds, true);  // creates the missing nodes below path_[valid]
    prev_ = key;
    valid_ = valid;  // path_[0 .. valid] still hold (nodes are never moved or freed by an update)
  }

  Tree& t_;
  const int depth_;
  std::array<typename Tree::NodeType*, 17> path_{};  // path_[d]: node at depth d (tree depth <= 16)
  octomap::OcTreeKey prev_;
  int valid_ = 0;  // path_[0 .. valid_] matches prev_
};

template <class Tree>
size_t integrate(Tree& t, const std::vector<OccupancyMap::Slice>& slices, const OctomapOptions& o,
                 OccupancyMap::Scratch& s) {
  s.free.clear();
  s.hit.clear();
  const double min2 = o.min_range * o.min_range;
  size_t rays = 0;
  for (const OccupancyMap::Slice& slice : slices) {
    if (!slice.points || !slice.origin.allFinite()) continue;
    const octomap::point3d origin(slice.origin.x(), slice.origin.y(), slice.origin.z());
    s.endpoints.clear();
    for (const Eigen::Vector3f& p : *slice.points) {
      if (!p.allFinite()) continue;
      const Eigen::Vector3d d = p.cast<double>() - slice.origin;
      const double r2 = d.squaredNorm();
      if (r2 < min2) continue;
      octomap::OcTreeKey key;
      if (!t.coordToKeyChecked(octomap::point3d(p.x(), p.y(), p.z()), key)) continue;
      ++rays;
      if (!s.endpoints.insert(pack(key))) continue;  // one ray per endpoint voxel and slice
      // discretised: the ray ends at the endpoint voxel's centre
      octomap::point3d end = t.keyToCoord(key);
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
      if (hit) s.hit.insert(pack(key));
      if (t.computeRayKeys(origin, end, s.ray))
        for (const octomap::OcTreeKey& k : s.ray) s.free.insert(pack(k));
    }
  }
  LeafUpdater<Tree> updater(t);
  const float miss = t.getProbMissLog(), hit = t.getProbHitLog();
  for (uint64_t k : s.free.keys())
    if (!s.hit.contains(k)) updater.update(unpack(k), miss);
  for (uint64_t k : s.hit.keys()) updater.update(unpack(k), hit);
  return rays;
}
}  // namespace

OccupancyMap::OccupancyMap(const OctomapOptions& options) : options_(options), scratch_(std::make_unique<Scratch>()) {
  clear();
}
OccupancyMap::~OccupancyMap() = default;
OccupancyMap::OccupancyMap(OccupancyMap&&) noexcept = default;
OccupancyMap& OccupancyMap::operator=(OccupancyMap&&) noexcept = default;

void OccupancyMap::clear() {
  plain_.reset();
  colour_.reset();
  if (options_.colour) {
    colour_ = std::make_unique<octomap::ColorOcTree>(options_.resolution);
    configure(colour_.get(), options_);
  } else {
    plain_ = std::make_unique<octomap::OcTree>(options_.resolution);
    configure(plain_.get(), options_);
  }
  inner_dirty_ = false;
}

const octomap::AbstractOccupancyOcTree& OccupancyMap::tree() const {
  if (colour_) return *colour_;
  return *plain_;
}

void OccupancyMap::refreshInner() const {
  if (!inner_dirty_) return;
  if (colour_) colour_->updateInnerOccupancy();
  else plain_->updateInnerOccupancy();
  inner_dirty_ = false;
}

size_t OccupancyMap::insertRays(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3d& origin) {
  Slice s;
  s.origin = origin;
  s.points = &points;
  return insertSweep({s});
}

size_t OccupancyMap::insertSweep(const std::vector<Slice>& slices) {
  // lazy: inner nodes are refreshed once before any read
  const size_t n = colour_ ? integrate(*colour_, slices, options_, *scratch_) : integrate(*plain_, slices, options_, *scratch_);
  if (n) inner_dirty_ = true;
  return n;
}

size_t OccupancyMap::setColours(const std::vector<Eigen::Vector3f>& points, const std::vector<std::array<uint8_t, 3>>& rgb) {
  if (!colour_) return 0;
  size_t n = 0;
  for (size_t i = 0; i < points.size() && i < rgb.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    if (!p.allFinite()) continue;
    octomap::OcTreeKey key;
    if (!colour_->coordToKeyChecked(octomap::point3d(p.x(), p.y(), p.z()), key)) continue;
    octomap::ColorOcTreeNode* node = colour_->search(key);
    if (!node || !colour_->isNodeOccupied(node)) continue;
    colour_->averageNodeColor(key, rgb[i][0], rgb[i][1], rgb[i][2]);
    ++n;
  }
  if (n) inner_dirty_ = true;
  return n;
}

int OccupancyMap::classify(const Eigen::Vector3d& p) const {
  refreshInner();
  const octomap::point3d q(p.x(), p.y(), p.z());
  if (colour_) {
    const auto* n = colour_->search(q);
    return n ? (colour_->isNodeOccupied(n) ? 1 : 0) : -1;
  }
  const auto* n = plain_->search(q);
  return n ? (plain_->isNodeOccupied(n) ? 1 : 0) : -1;
}

std::vector<Eigen::Vector3d> OccupancyMap::occupiedVoxels() const {
  refreshInner();
  std::vector<Eigen::Vector3d> out;
  auto collect = [&](const auto& t) {
    const double res = t.getResolution();
    for (auto it = t.begin_leafs(), end = t.end_leafs(); it != end; ++it) {
      if (!t.isNodeOccupied(*it)) continue;
      const double size = it.getSize();
      const int n = std::max(1, static_cast<int>(std::lround(size / res)));
      const octomap::point3d c = it.getCoordinate();
      const double start = -0.5 * size + 0.5 * res;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
          for (int k = 0; k < n; ++k)
            out.emplace_back(c.x() + start + i * res, c.y() + start + j * res, c.z() + start + k * res);
    }
  };
  if (colour_) collect(*colour_);
  else collect(*plain_);
  return out;
}

size_t OccupancyMap::leafCount() const {
  refreshInner();
  return colour_ ? colour_->getNumLeafNodes() : plain_->getNumLeafNodes();
}

std::unique_ptr<octomap::OcTree> OccupancyMap::occupancyOnly() const {
  auto t = std::make_unique<octomap::OcTree>(options_.resolution);
  configure(t.get(), options_);
  const unsigned tree_depth = colour_->getTreeDepth();
  for (auto it = colour_->begin_leafs(), end = colour_->end_leafs(); it != end; ++it) {
    // a pruned leaf covers n^3 finest voxels around its centre key
    const int n = 1 << (tree_depth - it.getDepth());
    const int half = n / 2;
    const octomap::OcTreeKey c = it.getKey();
    const float value = it->getLogOdds();
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        for (int k = 0; k < n; ++k)
          t->setNodeValue(octomap::OcTreeKey(c[0] - half + i, c[1] - half + j, c[2] - half + k), value, true);
  }
  t->updateInnerOccupancy();
  return t;
}

std::string OccupancyMap::binaryBytes() const {
  refreshInner();
  std::ostringstream s;
  if (colour_) {
    auto t = occupancyOnly();
    t->writeBinary(s);
  } else {
    // writeBinary prunes; work on the const path so the tree being built is not changed
    plain_->writeBinaryConst(s);
  }
  return s.str();
}

std::string OccupancyMap::fullBytes() const {
  refreshInner();
  std::ostringstream s;
  tree().write(s);
  return s.str();
}

std::string OccupancyMap::treeType() const { return tree().getTreeType(); }

bool OccupancyMap::writeBinary(const std::string& path) const { return writeFileAtomically(path, {binaryBytes()}); }
bool OccupancyMap::writeFull(const std::string& path) const { return writeFileAtomically(path, {fullBytes()}); }

}  // namespace octomap_export
}  // namespace livo
