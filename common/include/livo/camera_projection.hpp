// Pinhole projection with radial-tangential (k1 k2 p1 p2, cv::projectPoints) or equidistant
// (Kannala-Brandt k1..k4, cv::fisheye) distortion, as CameraRig::distortion_model says; OpenCV
// convention (pixel (i, j) has its centre at (i, j)); camera frame z forward, x right, y down.
// The one camera model of the project: estimators and the simulator's renderer use it alike.
#pragma once

#include <Eigen/Core>

#include "livo/sensor_rig.hpp"

namespace livo {

class CameraProjection {
 public:
  explicit CameraProjection(const CameraRig& rig);

  /// Pixel of p_C; false if behind the camera, outside the distortion model's valid field, or
  /// outside the image shrunk by `border` pixels.
  bool project(const Eigen::Vector3d& p_C, Eigen::Vector2d* pixel, double border = 0.0) const;
  /// project() with the Jacobian d pixel / d p_C (2x3, distortion included); same validity.
  bool projectWithJacobian(const Eigen::Vector3d& p_C, Eigen::Vector2d* pixel, Eigen::Matrix<double, 2, 3>* J,
                           double border = 0.0) const;
  Eigen::Vector2d distort(const Eigen::Vector2d& xy) const;
  /// d distort(xy) / d xy.
  Eigen::Matrix2d distortJacobian(const Eigen::Vector2d& xy) const;
  /// The normalised image point xy whose distortion is `distorted` (radtan: Newton on distort(xy);
  /// equidistant: Newton on theta_d(theta), theta kept below 90 degrees).
  Eigen::Vector2d undistort(const Eigen::Vector2d& distorted) const;
  /// The unit ray of a pixel, camera frame (the inverse of project() up to scale).
  Eigen::Vector3d pixelRay(const Eigen::Vector2d& pixel) const;

  /// Vignetting gain at a pixel for fall-off v (the simulator's and a common calibration model).
  double vignette(const Eigen::Vector2d& pixel, double v) const;

  const CameraRig& rig() const { return rig_; }

 private:
  CameraRig rig_;
  double max_r2_ = 1e9;  // normalised radius^2 beyond which the polynomial is not trusted
};

}  // namespace livo
