// Which map points an image is aligned on: projected with the prior, not occluded (a coarse
// depth buffer of the recent LiDAR points and the map points: a point well behind the nearest
// one in its cell is hidden, the paper's rejection of occluded and depth-inconsistent points),
// not next to a depth edge (a patch straddling one changes with the viewpoint),
// with a reference patch seen from a similar direction (the lowest score of view angle,
// photometric error and age) whose warp into this view stays inside the stored patch, and at
// most one per grid cell (the best textured).
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "livo/camera_projection.hpp"
#include "livo/vio/photometric_residual.hpp"
#include "livo/vio/point_patch_map.hpp"
#include "livo/vio/vio_options.hpp"

namespace livo::vio {

/// Nearest and farthest LiDAR/map point per image cell (depth and pixel).
class DepthGrid {
 public:
  DepthGrid(int width, int height, int cell_px);
  void clear();
  void add(const Eigen::Vector2d& pixel, float z);
  /// Nearest depth in the cell of `pixel` (infinity if none).
  float nearest(const Eigen::Vector2d& pixel) const;
  /// True if a point at depth z is hidden behind something nearer in its cell.
  bool occluded(const Eigen::Vector2d& pixel, double z, double tolerance, double tolerance_rel) const {
    return nearest(pixel) < z - (tolerance + tolerance_rel * z);
  }
  /// True if the points within `radius_px` of `pixel` (with the point itself, at depth z) do not
  /// lie on one plane: inverse depth is affine in the pixel coordinates on a plane, so a least-
  /// squares plane in (u, v, 1/z) is fitted and any deviation beyond tolerance + tolerance_rel z
  /// (in depth) marks a depth edge or a strongly curved surface, where a patch changes with the
  /// viewpoint. Slanted planes (a floor at a grazing angle) pass.
  bool depthEdge(const Eigen::Vector2d& pixel, double z, double radius_px, double tolerance,
                 double tolerance_rel) const;

 private:
  struct Cell {
    float near_z, near_u, near_v;
    float far_z, far_u, far_v;
  };
  static constexpr Cell kEmpty{std::numeric_limits<float>::infinity(),  0.0f, 0.0f,
                               -std::numeric_limits<float>::infinity(), 0.0f, 0.0f};
  int index(const Eigen::Vector2d& pixel) const;
  int cell_, cols_, rows_;
  std::vector<Cell> cells_;
  std::vector<int> filled_;  // cells with a point since the last clear()
};

/// Square cells of at least 8 px over the image, row-major (one tracked or new point per cell).
struct CellGrid {
  CellGrid(int width, int height, int cell_px);
  size_t size() const { return static_cast<size_t>(cols) * rows; }
  /// The cell of a pixel inside the image.
  size_t of(const Eigen::Vector2d& pixel) const {
    return static_cast<size_t>(static_cast<int>(pixel.y()) / cell * cols + static_cast<int>(pixel.x()) / cell);
  }
  int cell, cols, rows;
};

struct SelectionStats {
  int in_view = 0;  // project inside the image with the patch border, in the depth range
  int occluded = 0;
  int depth_edge = 0;    // next to a depth discontinuity
  int no_reference = 0;  // no patch seen from close enough a direction, or the warp leaves it
  int selected = 0;
};

/// The reference observation for a point seen from camera centre c_W at time utime, or -1.
int chooseReference(const MapPoint& point, const Vec3& c_W, int64_t utime, const SelectionOptions& options);

/// The tracked patches of the image at camera pose T_W_C with the camera calibration `calibration`
/// (reference patches re-centred where the reference images see the points through it, and warped
/// into this view).
std::vector<TrackedPatch> selectPatches(const PointPatchMap& map, const CameraProjection& camera, const Pose3& T_W_C,
                                        const SensorCalibration& calibration, int64_t utime, float exposure_time,
                                        const DepthGrid& depth, int levels, const SelectionOptions& options,
                                        SelectionStats* stats);

}  // namespace livo::vio
