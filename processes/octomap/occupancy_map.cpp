#include "occupancy_map.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

#include <octomap/ColorOcTree.h>
#include <octomap/OcTree.h>

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

OccupancyMap::OccupancyMap(const OctomapOptions& options) : options_(options) { clear(); }
OccupancyMap::~OccupancyMap() = default;

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
  if (!origin.allFinite()) return 0;
  octomap::Pointcloud cloud;
  cloud.reserve(points.size());
  const double min2 = options_.min_range * options_.min_range;
  for (const Eigen::Vector3f& p : points) {
    if (!p.allFinite()) continue;
    if ((p.cast<double>() - origin).squaredNorm() < min2) continue;
    cloud.push_back(p.x(), p.y(), p.z());
  }
  if (cloud.size() == 0) return 0;
  const octomap::point3d o(origin.x(), origin.y(), origin.z());
  // lazy: inner nodes are refreshed once before any read; discretize: one ray per endpoint voxel
  if (colour_) colour_->insertPointCloud(cloud, o, options_.max_range, true, true);
  else plain_->insertPointCloud(cloud, o, options_.max_range, true, true);
  inner_dirty_ = true;
  return cloud.size();
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

namespace {
bool writeFileAtomically(const std::string& path, const std::string& bytes) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return false;
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out) return false;
  }
  return std::rename(tmp.c_str(), path.c_str()) == 0;
}
}  // namespace

bool OccupancyMap::writeBinary(const std::string& path) const { return writeFileAtomically(path, binaryBytes()); }
bool OccupancyMap::writeFull(const std::string& path) const { return writeFileAtomically(path, fullBytes()); }

}  // namespace octomap_export
}  // namespace livo
