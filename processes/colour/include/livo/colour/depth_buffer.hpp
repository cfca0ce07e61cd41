// A coarse depth buffer over the image for the occlusion test: every projected point covers a
// square of cells sized from a physical radius at its depth (so sparse LiDAR rows of a foreground
// object still hide the background between them), keeping the nearest depth per cell.
#pragma once

#include <vector>

#include <Eigen/Core>

namespace livo::colour {

struct DepthBufferOptions {
  int cell_px = 4;
  double occluder_radius = 0.06;  // m
  int max_splat_cells = 6;
  double tolerance = 0.05;        // m
  double tolerance_rel = 0.02;
};

class DepthBuffer {
 public:
  DepthBuffer(int width, int height, double focal_px, const DepthBufferOptions& options);

  void clear();
  /// Covers the cells around `pixel` with depth z.
  void splat(const Eigen::Vector2d& pixel, double z);
  /// Nearest depth at the cell of `pixel` (infinity if nothing was splatted there).
  float nearest(const Eigen::Vector2d& pixel) const;
  /// True if a point at depth z seen at `pixel` is not hidden behind something nearer.
  bool visible(const Eigen::Vector2d& pixel, double z) const;

 private:
  int cellIndex(const Eigen::Vector2d& pixel, int* cx, int* cy) const;
  DepthBufferOptions options_;
  int cols_, rows_;
  double focal_;
  std::vector<float> depth_;
};

}  // namespace livo::colour
