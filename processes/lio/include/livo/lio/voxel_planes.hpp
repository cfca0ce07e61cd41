// Planes that average the range noise out of the map (VoxelMap, Yuan et al. 2022; FAST-LIVO2's
// map): every registered point of every sweep adds to the scatter of its cell in a grid finer than
// the point map's, and a cell whose scatter is thin and wide answers with its least-squares plane.
// The point map's plane through k stored points keeps each point's range noise (3 cm on a
// VLP-16); a cell's plane through hundreds of beams from many sweeps averages it down, so the
// registration stops pulling every later sweep towards the same noisy plane. The noise's own
// part of the scatter (sigma^2 along each beam) is taken out before the fit, so a cell crossed by
// few rings or seen at grazing incidence does not lean towards the beams. Limits: cells do not
// follow a loop correction (they are cleared and fill again) and do not carve free space (a cell
// something moved through scatters too much to be a plane until a nearer view restarts it).
#pragma once

#include <cstdint>
#include <vector>

#include "livo/flat_key_index.hpp"
#include "livo/plane.hpp"
#include "livo/so3.hpp"

namespace livo::lio {

struct VoxelPlanesOptions {
  bool enabled = false;
  double cell_size = 0.5;  // m, edge of a cell
  int max_points = 2000;   // a cell's scatter takes no more points (then its plane stays)
  int min_points = 50;     // fewer points make no plane
  int point_stride = 2;    // every n-th point of a sweep is added
  double max_std = 0.03;   // m, largest root-mean-square distance of a cell's points to its plane
  // A cell is a plane only where its points scatter off the plane no more than the range noise
  // explains: sigma^2 times the mean squared cosine between the beams and the normal, times
  // max_variance_ratio, plus model_std^2 (curvature, the poses' own error). A cell holding an
  // edge, a step or returns mixed across a depth jump scatters more.
  double range_noise_std = 0.01;  // m, the LiDAR's (the rig states it)
  double max_variance_ratio = 1.5;
  double model_std = 0.005;        // m
  double max_normal_angle = 0.02;  // rad, the normal's spread: sqrt(off-plane / (n * weaker in-plane))
  // As the point map's refresh (VoxelMapOptions::refresh_range_ratio): a cell takes points seen
  // from at most 1/ratio times the nearest range it holds, and a point seen from below ratio times
  // that range starts the cell again (beam footprint and grazing smear grow with range: a street
  // first seen far ahead is re-measured when the sensor passes it). 0: every range.
  double refresh_range_ratio = 0.5;
  double max_range = 0.0;  // m, farther points are not added (0: no limit)
};

class VoxelPlanes {
 public:
  explicit VoxelPlanes(VoxelPlanesOptions options = {});

  /// Adds every point_stride-th point of a sweep seen from `origin` (world frame) to its cell
  /// and refits the cells that changed.
  void add(const std::vector<Vec3>& points, const Vec3& origin);
  /// The plane of the cell holding q, or null. Valid until the next non-const call.
  const Plane* planeAt(const Vec3& q) const;
  /// Drops the cells whose centre is farther than radius from centre.
  void removeFarFrom(const Vec3& centre, double radius);
  void clear();

  size_t numCells() const { return cells_.size(); }
  size_t numPlanes() const;
  const VoxelPlanesOptions& options() const { return options_; }

 private:
  /// The upper triangle of a sum of outer products v v^T: xx, xy, xz, yy, yz, zz.
  using SymmetricSum = Eigen::Matrix<double, 6, 1>;
  static void addOuter(const Vec3& v, SymmetricSum* sum) {
    *sum += (SymmetricSum() << v.x() * v.x(), v.x() * v.y(), v.x() * v.z(), v.y() * v.y(), v.y() * v.z(), v.z() * v.z())
                .finished();
  }
  static Mat3 toMatrix(const SymmetricSum& s) {
    return (Mat3() << s[0], s[1], s[2], s[1], s[3], s[4], s[2], s[4], s[5]).finished();
  }
  struct Cell {
    VoxelKey key;
    int32_t cx, cy, cz;
    int32_t count = 0;
    bool planar = false;
    bool dirty = false;
    float nearest_range = 0.0f;                 // of the points in the scatter
    Vec3 sum = Vec3::Zero();                    // of the points relative to the cell's corner
    SymmetricSum outer = SymmetricSum::Zero();  // of their outer products
    SymmetricSum beams = SymmetricSum::Zero();  // of the unit beam directions' outer products
    Plane plane;
  };
  Vec3 corner(const Cell& c) const { return Vec3(c.cx, c.cy, c.cz) * options_.cell_size; }
  void refit(Cell* c) const;
  void reindex();

  VoxelPlanesOptions options_;
  double inv_size_;
  std::vector<Cell> cells_;
  FlatKeyIndex index_;
  std::vector<int32_t> dirty_;
};

}  // namespace livo::lio
