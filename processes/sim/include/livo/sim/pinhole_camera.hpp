// Pinhole projection with radial-tangential (k1 k2 p1 p2) distortion; pixel (i, j) has its centre
// at (i, j) (OpenCV convention). Camera frame: z forward, x right, y down.
#pragma once

#include "livo/sensor_rig.hpp"

namespace livo::sim {

class PinholeCamera {
 public:
  explicit PinholeCamera(const CameraRig& rig);

  /// Pixel of a point in the camera frame; false if it is behind the camera.
  bool project(const Vec3& p_C, Eigen::Vector2d* pixel) const;
  /// Unit ray in the camera frame through a pixel (inverts the distortion iteratively).
  Vec3 pixelRay(const Eigen::Vector2d& pixel) const;

  Eigen::Vector2d distort(const Eigen::Vector2d& normalized) const;
  Eigen::Vector2d undistort(const Eigen::Vector2d& distorted) const;

  int width() const { return rig_.width; }
  int height() const { return rig_.height; }
  const CameraRig& rig() const { return rig_; }

 private:
  CameraRig rig_;
};

}  // namespace livo::sim
