#include "livo/vio/point_patch_map.hpp"

#include <algorithm>
#include <cmath>

namespace livo::vio {

PointPatchMap::PointPatchMap(const MapOptions& options) : options_(options), inv_voxel_(1.0 / options.voxel_size) {}

uint64_t PointPatchMap::keyOf(const Vec3& p) const { return voxelKeyOf(p, inv_voxel_); }

int PointPatchMap::find(const Vec3& p) const { return index_.find(keyOf(p)); }

int PointPatchMap::add(const Vec3& p, int64_t utime, PatchObservation observation, const Vec3& normal) {
  const int index = static_cast<int>(points_.size());
  if (index_.insert(keyOf(p), index) != index) return -1;  // the voxel's point is another
  MapPoint m;
  m.id = next_id_++;
  m.position = p;
  m.normal = normal;
  m.last_seen = utime;
  m.observations.push_back(std::move(observation));
  points_.push_back(std::move(m));
  return index;
}

void PointPatchMap::addObservation(int index, PatchObservation observation) {
  auto& obs = point(index).observations;
  if (static_cast<int>(obs.size()) >= options_.max_observations) obs.erase(obs.begin());
  obs.push_back(std::move(observation));
}

void PointPatchMap::prune(const Vec3& centre) {
  // with hysteresis, so that the compaction and re-indexing run every few images, not every one:
  // by radius once the camera moved a tenth of it, by count down to 90 % of the bound
  const bool moved = !pruned_once_ || (centre - pruned_at_).norm() > 0.1 * options_.radius;
  const bool full = static_cast<int>(points_.size()) > options_.max_points;
  if (!moved && !full) return;
  const double r2 = options_.radius * options_.radius;
  std::vector<char> drop(points_.size(), 0);
  std::vector<std::pair<int64_t, int64_t>> kept;  // (last_seen, id) of the points within the radius
  std::vector<size_t> kept_index;
  if (moved) {
    pruned_once_ = true;
    pruned_at_ = centre;
  }
  for (size_t i = 0; i < points_.size(); ++i) {
    if (moved && (points_[i].position - centre).squaredNorm() > r2) {
      drop[i] = 1;
      continue;
    }
    kept.emplace_back(points_[i].last_seen, points_[i].id);
    kept_index.push_back(i);
  }
  if (static_cast<int>(kept.size()) > options_.max_points) {
    const size_t target = static_cast<size_t>(options_.max_points) * 9 / 10;
    std::vector<size_t> order(kept.size());
    for (size_t k = 0; k < order.size(); ++k) order[k] = k;
    // the most recently seen first; ties by id, newer first
    std::nth_element(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(target), order.end(),
                     [&](size_t a, size_t b) { return kept[a] > kept[b]; });
    for (size_t k = target; k < order.size(); ++k) drop[kept_index[order[k]]] = 1;
  }
  size_t out = 0;
  for (size_t i = 0; i < points_.size(); ++i) {
    if (drop[i]) continue;
    if (out != i) points_[out] = std::move(points_[i]);
    ++out;
  }
  if (out == points_.size()) return;
  points_.resize(out);
  reindex();
}

void PointPatchMap::transform(const Pose3& T) {
  Eigen::Matrix<float, 6, 6> J = Eigen::Matrix<float, 6, 6>::Zero();  // both blocks in the world frame
  J.topLeftCorner<3, 3>() = T.linear().cast<float>();
  J.bottomRightCorner<3, 3>() = T.linear().cast<float>();
  for (auto& m : points_) {
    m.position = T * m.position;
    m.normal = T.linear() * m.normal;
    for (auto& o : m.observations) {
      o.view.T_W_I = T * o.view.T_W_I;
      o.view.vel_W = T.linear() * o.view.vel_W;
      o.pose_cov_W = J * o.pose_cov_W * J.transpose();
    }
  }
  // two points may now share a voxel: both stay, the older one is indexed
  reindex();
}

void PointPatchMap::clear() {
  points_.clear();
  index_.clear();
}

void PointPatchMap::reindex() {
  index_.resetFor(points_.size());
  for (size_t i = 0; i < points_.size(); ++i) index_.insert(keyOf(points_[i].position), static_cast<int>(i));
}

size_t PointPatchMap::observationCount() const {
  size_t n = 0;
  for (const auto& m : points_) n += m.observations.size();
  return n;
}

size_t PointPatchMap::memoryBytes() const {
  // the index's slots: a key and an index each, padded to two keys
  size_t bytes = points_.capacity() * sizeof(MapPoint) + index_.capacity() * 2 * sizeof(VoxelKey);
  for (const auto& m : points_) {
    bytes += m.observations.capacity() * sizeof(PatchObservation);
    for (const auto& o : m.observations) bytes += o.pixels.capacity();
  }
  return bytes;
}

}  // namespace livo::vio
