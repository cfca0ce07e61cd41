#include "livo/report/octomap_slice.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "livo/report/picture_annotations.hpp"

namespace livo::report {

namespace {
constexpr double kTouch = 1e-4;  // m: a voxel that only touches the band (float rounding) is not in it
}  // namespace

std::vector<OccupiedVoxel> occupiedVoxelsInBand(const ::octomap::OcTree& tree, const TrajectoryHeight& height,
                                                const SliceBand& band) {
  std::vector<OccupiedVoxel> out;
  if (tree.size() == 0) return out;
  double x0, y0, z0, x1, y1, z1;
  tree.getMetricMin(x0, y0, z0);
  tree.getMetricMax(x1, y1, z1);
  // only the leaves that can reach the band anywhere
  const double lo = std::max(z0, height.minimum() - band.below_m), hi = std::min(z1, height.maximum() + band.above_m);
  if (lo > hi) return out;
  const ::octomap::point3d bmin(static_cast<float>(x0), static_cast<float>(y0), static_cast<float>(lo));
  const ::octomap::point3d bmax(static_cast<float>(x1), static_cast<float>(y1), static_cast<float>(hi));
  for (auto it = tree.begin_leafs_bbx(bmin, bmax), end = tree.end_leafs_bbx(); it != end; ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    OccupiedVoxel v;
    v.centre = Vec3(it.getX(), it.getY(), it.getZ());
    v.size = it.getSize();
    const double ref = height.at(v.centre.x(), v.centre.y());
    const double bottom = v.centre.z() - 0.5 * v.size - ref, top = v.centre.z() + 0.5 * v.size - ref;
    if (top <= -band.below_m + kTouch || bottom >= band.above_m - kTouch) continue;  // outside, or touching it
    v.height = std::clamp(v.centre.z() - ref, -band.below_m, band.above_m);
    out.push_back(v);
  }
  return out;
}

std::unique_ptr<::octomap::OcTree> readOctomapBinary(const std::string& path) {
  auto tree = std::make_unique<::octomap::OcTree>(0.1);
  if (!tree->readBinary(path)) throw std::runtime_error(path + ": not a binary OctoMap (.bt) file");
  return tree;
}

cv::Mat renderSlice(const std::vector<OccupiedVoxel>& voxels, const TopViewFrame& frame, const SliceBand& band) {
  cv::Mat image(frame.height, frame.width, CV_8UC3, cv::Scalar(255, 255, 255));
  std::vector<size_t> order(voxels.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return voxels[a].height < voxels[b].height; });
  const double span = band.below_m + band.above_m;
  for (size_t k : order) {
    const OccupiedVoxel& v = voxels[k];
    const double h = 0.5 * v.size;
    const cv::Point2d a = frame.pixel(v.centre.x() - h, v.centre.y() + h),
                      b = frame.pixel(v.centre.x() + h, v.centre.y() - h);
    // the pixels whose centres lie in the square, at least the one holding the voxel's centre
    int u0 = static_cast<int>(std::ceil(a.x - 0.5)), u1 = static_cast<int>(std::floor(b.x - 0.5));
    int v0 = static_cast<int>(std::ceil(a.y - 0.5)), v1 = static_cast<int>(std::floor(b.y - 0.5));
    if (u1 < u0) u0 = u1 = static_cast<int>(std::floor(0.5 * (a.x + b.x)));
    if (v1 < v0) v0 = v1 = static_cast<int>(std::floor(0.5 * (a.y + b.y)));
    u0 = std::max(u0, 0), v0 = std::max(v0, 0);
    u1 = std::min(u1, frame.width - 1), v1 = std::min(v1, frame.height - 1);
    if (u0 > u1 || v0 > v1) continue;
    const cv::Vec3b c = heightColour(span > 0 ? (v.height + band.below_m) / span : 0.5);
    image(cv::Rect(u0, v0, u1 - u0 + 1, v1 - v0 + 1)).setTo(cv::Scalar(c[0], c[1], c[2]));
  }
  return image;
}

}  // namespace livo::report
