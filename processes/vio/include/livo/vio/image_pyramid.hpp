// A grey image pyramid by 2x2 averaging, with the sampling the photometric update needs.
// Pixel (i, j) of level l covers level-0 pixels [2^l i, 2^l (i+1)) x ..., so a level-0
// coordinate u maps to (u + 0.5) / 2^l - 0.5 (pixel centres at integers, as in OpenCV).
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

namespace livo::vio {

class ImagePyramid {
 public:
  /// Level 0 shares `grey` (CV_8UC1); levels 1.. are computed.
  void build(const cv::Mat& grey, int levels);

  int levels() const { return static_cast<int>(levels_.size()); }
  const cv::Mat& level(int l) const { return levels_[l]; }

  static Eigen::Vector2d toLevel(const Eigen::Vector2d& u0, int level) {
    const double s = 1.0 / static_cast<double>(1 << level);
    return Eigen::Vector2d((u0.x() + 0.5) * s - 0.5, (u0.y() + 0.5) * s - 0.5);
  }

  /// Samples an n x n grid centred on `centre` (level coordinates) with unit spacing: sample
  /// (i, j) is at centre + (i - (n-1)/2, j - (n-1)/2). All samples share one set of bilinear
  /// weights. Row-major into out[n*n]; false (out untouched) if the grid leaves the image.
  bool sampleGrid(int level, const Eigen::Vector2d& centre, int n, float* out) const;

  /// Bilinear value at (x, y) of a level; the caller keeps (x, y) inside [0, w-1] x [0, h-1].
  float sample(int level, double x, double y) const;

 private:
  std::vector<cv::Mat> levels_;
};

}  // namespace livo::vio
