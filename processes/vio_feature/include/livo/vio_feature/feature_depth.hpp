// Depth for tracked features, where the rig measures it: from a depth image registered to the
// camera (RGB-D) and from LiDAR points (REGISTERED_SCAN moved into the camera frame), as LVI-SAM
// does. A feature gets a depth only where the measurements around it agree; on a depth edge, or
// where the LiDAR sees two surfaces near it, it gets none and the back end triangulates it.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "livo/camera_projection.hpp"
#include "livo/vio_feature/feature_tracker.hpp"

namespace livo::vio_feature {

struct DepthImageOptions {
  int window_radius_px = 2;         // the window is (2 r + 1)^2 pixels around the feature
  double min_valid_fraction = 0.5;  // of the window's pixels with a depth
  double agreement = 0.03;          // every valid depth within this fraction of their median
  double min_depth = 0.1;           // m; depths outside [min, max] count as none
  double max_depth = 20.0;
};

struct LidarDepthOptions {
  double min_depth = 0.3;  // m along z; points outside [min, max] are not used
  double max_depth = 60.0;
  int cell_px = 4;                    // occlusion cells: the nearest point per cell is kept
  double occlusion_ratio = 1.3;       // a kept point this many times farther than one in a
                                      // neighbouring cell is behind a nearer surface: not support,
                                      // and a feature near it gets no depth (a depth edge)
  double search_radius_px = 16.0;     // the kept points this close to a feature are its support
                                      // (more than a 16-beam scan's ring spacing, ~14 px at f 400)
  int min_points = 3;                 // support needed for a depth
  double surround_margin_px = 3.0;    // the feature must lie in the support's pixel bounding box
                                      // grown by this: a surface is not extended over a part of the
                                      // image the LiDAR did not see (its shadow behind an edge)
  double agreement = 0.05;            // median depth: every support depth within this fraction of it
  double plane_tolerance = 0.05;      // plane depth: every support point within this distance (m)
  double plane_tolerance_rel = 0.02;  //   plus this fraction of its depth of the fitted plane
};

/// Sets `depth` of each observation from `depth_image` (CV_32F metres along z, 0 or not finite =
/// none, registered to the camera): the median of the valid depths in the window when there are
/// enough of them and they agree, else 0. Returns how many got a depth.
int depthFromImage(const cv::Mat& depth_image, const DepthImageOptions& options,
                   std::vector<FeatureObservation>* features);

/// LiDAR points in the camera frame, projected and thinned to the nearest per image cell (and
/// rid of points behind a nearer neighbour cell), queried per feature.
class LidarDepthMap {
 public:
  LidarDepthMap(const CameraProjection& camera, const LidarDepthOptions& options);

  /// Replaces the points (camera frame, metres).
  void setPoints(const std::vector<Eigen::Vector3d>& points_C);
  /// Depth along z at a pixel: the ray's intersection with the plane through the support (when the
  /// support spans a plane and lies on it) or the support's median depth (when the depths agree);
  /// 0 when there is too little support, when it disagrees or does not surround the pixel, or when
  /// an occluded point lies within the search radius (two surfaces: a depth edge, where a sparse
  /// scan cannot tell which one the feature is on).
  double depthAt(const Eigen::Vector2d& pixel) const;
  /// Sets `depth` of each observation with depthAt() where it finds one, leaving the others as they
  /// are (a depth image's, or 0). Returns how many it set.
  int assign(std::vector<FeatureObservation>* features) const;

  /// Points kept as support (the nearest in their cell, not occluded).
  size_t keptPoints() const;

 private:
  struct Kept {
    Eigen::Vector3d p_C;
    Eigen::Vector2d pixel;
    bool valid = false;     // a point fell into the cell
    bool occluded = false;  // it lies behind the nearest point of a neighbouring cell
  };
  CameraProjection camera_;
  LidarDepthOptions options_;
  int cols_, rows_;
  std::vector<Kept> cells_;  // row-major, cols_ x rows_
};

}  // namespace livo::vio_feature
