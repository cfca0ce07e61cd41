#include "livo/lio/voxel_planes.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <stdexcept>

namespace livo::lio {

VoxelPlanes::VoxelPlanes(VoxelPlanesOptions options) : options_(options) {
  if (!(options_.cell_size > 0.0) || options_.min_points < 3 || options_.max_points < options_.min_points ||
      options_.point_stride < 1 || !(options_.max_std > 0.0) || !(options_.max_normal_angle > 0.0) ||
      !(options_.refresh_range_ratio >= 0.0 && options_.refresh_range_ratio < 1.0))
    throw std::invalid_argument(
        "VoxelPlanes: cell_size > 0, 3 <= min_points <= max_points, point_stride >= 1, max_std > 0 and "
        "max_normal_angle > 0, 0 <= refresh_range_ratio < 1 required");
  inv_size_ = 1.0 / options_.cell_size;
}

void VoxelPlanes::add(const std::vector<Vec3>& points, const Vec3& origin) {
  const size_t stride = static_cast<size_t>(options_.point_stride);
  for (size_t i = 0; i < points.size(); i += stride) {
    const Vec3& p = points[i];
    if (!p.allFinite()) continue;
    const float range = static_cast<float>((p - origin).norm());
    if (options_.max_range > 0.0 && range > options_.max_range) continue;
    const int64_t cx = floorToInt(p.x() * inv_size_), cy = floorToInt(p.y() * inv_size_),
                  cz = floorToInt(p.z() * inv_size_);
    const VoxelKey key = packVoxel(cx, cy, cz);
    const int32_t next = static_cast<int32_t>(cells_.size());
    const int32_t v = index_.insert(key, next);
    if (v == next) {
      Cell c;
      c.key = key;
      c.cx = static_cast<int32_t>(cx), c.cy = static_cast<int32_t>(cy), c.cz = static_cast<int32_t>(cz);
      cells_.push_back(c);
    }
    Cell& c = cells_[static_cast<size_t>(v)];
    const float ratio = static_cast<float>(options_.refresh_range_ratio);
    if (c.count > 0 && ratio > 0.0f) {
      if (range < ratio * c.nearest_range) {
        c.count = 0;  // a much nearer view: the cell starts again from it
        c.sum.setZero();
        c.outer.setZero();
        c.beams.setZero();
      } else if (ratio * range > c.nearest_range) {
        continue;  // a much farther view than the cell holds
      }
    }
    if (c.count >= options_.max_points) continue;
    c.nearest_range = c.count == 0 ? range : std::min(c.nearest_range, range);
    const Vec3 q = p - corner(c);
    ++c.count;
    c.sum += q;
    addOuter(q, &c.outer);
    if (range > 0.0f) {
      const Vec3 beam = (p - origin) / static_cast<double>(range);
      addOuter(beam, &c.beams);
    }
    if (!c.dirty) {
      c.dirty = true;
      dirty_.push_back(v);
    }
  }
  for (const int32_t v : dirty_) refit(&cells_[static_cast<size_t>(v)]);
  dirty_.clear();
}

void VoxelPlanes::refit(Cell* c) const {
  c->dirty = false;
  c->planar = false;
  if (c->count < options_.min_points) return;
  const double n = c->count;
  const Vec3 mean = c->sum / n;
  // The range noise moves each point along its beam: the scatter is the surface's plus
  // sigma^2 times the mean beam outer product. Plain least squares (the scatter's smallest
  // eigenvector) leans the plane towards the beams wherever the surface's own spread is not much
  // larger than the noise (a wall crossed by two rings, ground seen at grazing incidence); with
  // the noise's part taken out first it does not (bias-corrected total least squares).
  const Mat3 noise = options_.range_noise_std * options_.range_noise_std / n * toMatrix(c->beams);
  const Mat3 scatter = toMatrix(c->outer) / n - mean * mean.transpose();
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(Mat3(scatter - noise));
  const Vec3 lambda = eig.eigenvalues();
  const Vec3 normal = eig.eigenvectors().col(0);
  // a plane: the points scatter off it by no more than the noise explains (lambda[0], what is
  // left of that scatter, within (max_variance_ratio - 1) of the noise's part plus the model's),
  // and it spans more than the noise can smear a line in both directions, with a normal held to
  // max_normal_angle by the points' number and spread
  constexpr double kMinInPlaneSpreadInNoise = 3.0;
  const double sigma2 = options_.range_noise_std * options_.range_noise_std;
  const double explained = normal.dot(noise * normal);
  const double max_excess = (options_.max_variance_ratio - 1.0) * explained + options_.model_std * options_.model_std;
  const double max_angle2 = options_.max_normal_angle * options_.max_normal_angle;
  if (!(lambda[0] + explained <= options_.max_std * options_.max_std) || !(lambda[0] <= max_excess) ||
      !(lambda[1] >= kMinInPlaneSpreadInNoise * kMinInPlaneSpreadInNoise * sigma2) ||
      !(explained + std::max(lambda[0], 0.0) <= max_angle2 * n * lambda[1]))
    return;
  c->plane.normal = normal;
  c->plane.offset = -c->plane.normal.dot(mean + corner(*c));
  c->planar = true;
}

const Plane* VoxelPlanes::planeAt(const Vec3& q) const {
  if (cells_.empty() || !q.allFinite()) return nullptr;
  const int32_t v = index_.find(voxelKeyOf(q, inv_size_));
  if (v < 0) return nullptr;
  const Cell& c = cells_[static_cast<size_t>(v)];
  return c.planar ? &c.plane : nullptr;
}

void VoxelPlanes::removeFarFrom(const Vec3& centre, double radius) {
  const double r2 = radius * radius;
  size_t kept = 0;
  for (size_t v = 0; v < cells_.size(); ++v) {
    const Vec3 mid = corner(cells_[v]) + Vec3::Constant(0.5 * options_.cell_size);
    if ((mid - centre).squaredNorm() > r2) continue;
    if (kept != v) cells_[kept] = cells_[v];
    ++kept;
  }
  if (kept == cells_.size()) return;
  cells_.resize(kept);
  cells_.shrink_to_fit();
  reindex();
}

void VoxelPlanes::reindex() {
  index_.resetFor(cells_.size());
  for (size_t v = 0; v < cells_.size(); ++v) index_.insert(cells_[v].key, static_cast<int32_t>(v));
}

void VoxelPlanes::clear() {
  cells_.clear();
  dirty_.clear();
  index_.resetFor(0);
}

size_t VoxelPlanes::numPlanes() const {
  size_t n = 0;
  for (const auto& c : cells_) n += c.planar ? 1 : 0;
  return n;
}

}  // namespace livo::lio
