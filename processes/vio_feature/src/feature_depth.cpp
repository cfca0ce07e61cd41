#include "livo/vio_feature/feature_depth.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/Eigenvalues>

namespace livo::vio_feature {

namespace {

/// Median of `v` (reordered); v must not be empty.
double median(std::vector<double>* v) {
  const size_t mid = v->size() / 2;
  std::nth_element(v->begin(), v->begin() + static_cast<std::ptrdiff_t>(mid), v->end());
  double m = (*v)[mid];
  if (v->size() % 2 == 0) m = 0.5 * (m + *std::max_element(v->begin(), v->begin() + static_cast<std::ptrdiff_t>(mid)));
  return m;
}

/// The median when every value lies within `agreement` x median of it, else 0.
double agreeingMedian(std::vector<double>* v, double agreement) {
  const double m = median(v);
  const auto [lo, hi] = std::minmax_element(v->begin(), v->end());
  return (m - *lo <= agreement * m && *hi - m <= agreement * m) ? m : 0.0;
}

}  // namespace

int depthFromImage(const cv::Mat& depth_image, const DepthImageOptions& options,
                   std::vector<FeatureObservation>* features) {
  if (depth_image.type() != CV_32FC1) throw std::invalid_argument("depthFromImage: the depth image must be CV_32F");
  const int r = std::max(0, options.window_radius_px);
  const int window = (2 * r + 1) * (2 * r + 1);
  std::vector<double> valid;
  valid.reserve(static_cast<size_t>(window));
  int assigned = 0;
  for (FeatureObservation& f : *features) {
    f.depth = 0.0;
    const int u = static_cast<int>(std::lround(f.pixel.x())), v = static_cast<int>(std::lround(f.pixel.y()));
    valid.clear();
    for (int y = std::max(0, v - r); y <= std::min(depth_image.rows - 1, v + r); ++y) {
      const float* row = depth_image.ptr<float>(y);
      for (int x = std::max(0, u - r); x <= std::min(depth_image.cols - 1, u + r); ++x) {
        const double z = row[x];
        if (std::isfinite(z) && z >= options.min_depth && z <= options.max_depth) valid.push_back(z);
      }
    }
    if (valid.empty() || static_cast<double>(valid.size()) < options.min_valid_fraction * window) continue;
    f.depth = agreeingMedian(&valid, options.agreement);
    assigned += f.depth > 0.0;
  }
  return assigned;
}

LidarDepthMap::LidarDepthMap(const CameraProjection& camera, const LidarDepthOptions& options)
    : camera_(camera),
      options_(options),
      cols_((camera.rig().width + std::max(1, options.cell_px) - 1) / std::max(1, options.cell_px)),
      rows_((camera.rig().height + std::max(1, options.cell_px) - 1) / std::max(1, options.cell_px)) {
  options_.cell_px = std::max(1, options_.cell_px);
  cells_.resize(static_cast<size_t>(cols_) * rows_);
}

void LidarDepthMap::setPoints(const std::vector<Eigen::Vector3d>& points_C) {
  for (Kept& c : cells_) c.valid = false;
  const int cell = options_.cell_px;
  for (const Eigen::Vector3d& p : points_C) {
    if (!(p.z() >= options_.min_depth && p.z() <= options_.max_depth)) continue;
    Eigen::Vector2d pixel;
    if (!camera_.project(p, &pixel)) continue;
    const int cx = static_cast<int>(pixel.x()) / cell, cy = static_cast<int>(pixel.y()) / cell;
    Kept& k = cells_[static_cast<size_t>(cy) * cols_ + cx];
    if (!k.valid || p.z() < k.p_C.z()) k = Kept{p, pixel, true, false};
  }
  // A point far behind the nearest point of a neighbouring cell lies behind a nearer surface (in
  // the camera's view: the LiDAR, mounted elsewhere, may have seen it past the surface's edge), or
  // next to one: either way it marks a depth edge.
  for (int cy = 0; cy < rows_; ++cy)
    for (int cx = 0; cx < cols_; ++cx) {
      Kept& k = cells_[static_cast<size_t>(cy) * cols_ + cx];
      if (!k.valid) continue;
      for (int ny = std::max(0, cy - 1); ny <= std::min(rows_ - 1, cy + 1) && !k.occluded; ++ny)
        for (int nx = std::max(0, cx - 1); nx <= std::min(cols_ - 1, cx + 1); ++nx) {
          const Kept& n = cells_[static_cast<size_t>(ny) * cols_ + nx];
          if (n.valid && k.p_C.z() > options_.occlusion_ratio * n.p_C.z()) {
            k.occluded = true;
            break;
          }
        }
    }
}

size_t LidarDepthMap::keptPoints() const {
  return static_cast<size_t>(
      std::count_if(cells_.begin(), cells_.end(), [](const Kept& k) { return k.valid && !k.occluded; }));
}

double LidarDepthMap::depthAt(const Eigen::Vector2d& pixel) const {
  const double r = options_.search_radius_px;
  const int cell = options_.cell_px;
  const int x0 = std::max(0, static_cast<int>(std::floor((pixel.x() - r) / cell)));
  const int x1 = std::min(cols_ - 1, static_cast<int>(std::floor((pixel.x() + r) / cell)));
  const int y0 = std::max(0, static_cast<int>(std::floor((pixel.y() - r) / cell)));
  const int y1 = std::min(rows_ - 1, static_cast<int>(std::floor((pixel.y() + r) / cell)));
  std::vector<const Eigen::Vector3d*> support;
  Eigen::Vector2d pixel_min = Eigen::Vector2d::Constant(1e9), pixel_max = Eigen::Vector2d::Constant(-1e9);
  for (int cy = y0; cy <= y1; ++cy)
    for (int cx = x0; cx <= x1; ++cx) {
      const Kept& k = cells_[static_cast<size_t>(cy) * cols_ + cx];
      if (!k.valid || (k.pixel - pixel).squaredNorm() > r * r) continue;
      if (k.occluded) return 0.0;
      support.push_back(&k.p_C);
      pixel_min = pixel_min.cwiseMin(k.pixel);
      pixel_max = pixel_max.cwiseMax(k.pixel);
    }
  if (static_cast<int>(support.size()) < std::max(1, options_.min_points)) return 0.0;
  const double m = options_.surround_margin_px;
  if ((pixel.array() < pixel_min.array() - m).any() || (pixel.array() > pixel_max.array() + m).any()) return 0.0;

  std::vector<double> depths;
  depths.reserve(support.size());
  for (const Eigen::Vector3d* p : support) depths.push_back(p->z());
  const auto [lo, hi] = std::minmax_element(depths.begin(), depths.end());
  const double z_min = *lo, z_max = *hi;

  // The plane through the support, if it spans one (not all on one scan line) and lies on it.
  if (support.size() >= 3) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d* p : support) centroid += *p;
    centroid /= static_cast<double>(support.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const Eigen::Vector3d* p : support) cov += (*p - centroid) * (*p - centroid).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    const Eigen::Vector3d normal = eig.eigenvectors().col(0);
    const bool spans_plane = eig.eigenvalues()(1) > 0.05 * eig.eigenvalues()(2);
    bool on_plane = spans_plane;
    for (const Eigen::Vector3d* p : support)
      on_plane = on_plane && std::abs(normal.dot(*p - centroid)) <=
                                 options_.plane_tolerance + options_.plane_tolerance_rel * p->z();
    const Eigen::Vector3d ray = camera_.pixelRay(pixel);
    const double cos_incidence = std::abs(normal.dot(ray));
    if (on_plane && cos_incidence > 0.1) {
      const double z = normal.dot(centroid) / normal.dot(ray) * ray.z();
      // The plane is trusted near its support only.
      if (z >= (1.0 - options_.agreement) * z_min && z <= (1.0 + options_.agreement) * z_max) return z;
    }
  }
  return agreeingMedian(&depths, options_.agreement);
}

int LidarDepthMap::assign(std::vector<FeatureObservation>* features) const {
  int assigned = 0;
  for (FeatureObservation& f : *features) {
    const double z = depthAt(f.pixel);
    if (z > 0.0) f.depth = z, ++assigned;
  }
  return assigned;
}

}  // namespace livo::vio_feature
