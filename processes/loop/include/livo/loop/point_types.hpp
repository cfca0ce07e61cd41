// Point containers of the loop-closure core: plain Eigen vectors, no middleware.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <Eigen/StdVector>

#include "livo/so3.hpp"

namespace livo::loop {

using Points = std::vector<Vec3>;
using Covariances = std::vector<Mat3>;
/// FPFH: three 11-bin histograms (angle alpha, phi, theta), each summing to 100.
constexpr int kFpfhSize = 33;
using Fpfh = Eigen::Matrix<float, kFpfhSize, 1>;
using Features = std::vector<Fpfh, Eigen::aligned_allocator<Fpfh>>;

/// A pair of indices: source point `source` matches target point `target`.
struct Correspondence {
  int source = 0;
  int target = 0;
};
using Correspondences = std::vector<Correspondence>;

/// Applies T to every point.
Points transformed(const Points& points, const Pose3& T);

}  // namespace livo::loop
