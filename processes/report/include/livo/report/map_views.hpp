// Pictures of a point map without a GPU: the points are splatted as small squares into an image
// with a depth buffer (the nearest point to the viewer wins a pixel), from straight above
// (orthographic) or through a pinhole camera looking down at the map from one side. Images are
// OpenCV 8-bit BGR (as cv::imwrite takes them).
#pragma once

#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "livo/coloured_point_files.hpp"
#include "livo/report/trajectory_height.hpp"
#include "livo/trajectory_io.hpp"

namespace livo::report {

struct Box3 {
  Vec3 min = Vec3::Zero();
  Vec3 max = Vec3::Zero();
  Vec3 centre() const { return 0.5 * (min + max); }
  Vec3 size() const { return max - min; }
};

/// Per axis, the values at the `lower` and `upper` fractions of the sorted coordinates (0 and 1:
/// the bounding box), so a few stray far points do not shrink the picture. Non-finite points are
/// ignored; throws std::invalid_argument without any finite point.
Box3 percentileBox(const std::vector<Vec3>& points, double lower = 0.005, double upper = 0.995);
/// `box` grown to hold the trajectory's positions too.
Box3 withTrajectory(Box3 box, const Trajectory& trajectory);

/// An orthographic view from above: x to the right, y up. Pixel (u, v) covers
/// x in [x_min + u m, x_min + (u + 1) m) and y in (y_max - (v + 1) m, y_max - v m], m = metres_per_pixel.
struct TopViewFrame {
  double x_min = 0.0;
  double y_max = 0.0;
  double metres_per_pixel = 0.01;
  int width = 0;
  int height = 0;
  /// Continuous pixel coordinates of a world point (the pixel is their floor).
  cv::Point2d pixel(double x, double y) const {
    return {(x - x_min) / metres_per_pixel, (y_max - y) / metres_per_pixel};
  }
};

/// A frame over the box's horizontal extent, widened by `margin` (a fraction of its larger side) on
/// every side and, about its centre, to at least 1 m and to at least `min_short_px` pixels on its
/// shorter side; its longer side `long_side_px` pixels.
TopViewFrame topViewFrame(const Box3& box, int long_side_px = 1600, int min_short_px = 400, double margin = 0.03);

/// A pinhole camera: a world point p is q = R_C_W (p - position) in the camera (x right, y down,
/// z forward) and lands at (f q.x / q.z + cx, f q.y / q.z + cy).
struct PerspectiveView {
  Mat3 R_C_W = Mat3::Identity();
  Vec3 position = Vec3::Zero();
  double f = 1.0, cx = 0.0, cy = 0.0;
  int width = 0, height = 0;
  static constexpr double kNear = 0.05;  // m: nearer points are not drawn
  /// False behind the camera or nearer than kNear; else the pixel and the depth q.z.
  bool project(const Vec3& p, cv::Point2d* pixel, double* depth) const;
};

/// The horizontal direction (unit, x y) along which the points spread most (the major axis of
/// their horizontal covariance), its sign fixed so that its larger component is positive.
Eigen::Vector2d majorHorizontalAxis(const std::vector<Vec3>& points);

/// Looks at the box's centre from `distance_factor` times its half-diagonal away, down at
/// `elevation_deg`, from the side across `major_axis` (the long side of the map faces the camera)
/// turned by `azimuth_deg` about z. The focal length and the principal point make the box's eight
/// corners fill the image but a margin; the height follows the corners' aspect within
/// [0.45, 0.8] of `width`.
PerspectiveView obliqueView(const Box3& box, const Eigen::Vector2d& major_axis, int width = 1600,
                            double elevation_deg = 35.0, double azimuth_deg = 30.0, double distance_factor = 2.0);

/// The image cut to the rectangle holding every pixel that differs from `background`, widened by
/// `margin_px` on each side (within the image): the oblique view's framing fits the box's corners,
/// which a map seldom fills. The whole image when every pixel is background.
cv::Mat cropToContent(const cv::Mat& image, const cv::Vec3b& background, int margin_px);

struct SplatStyle {
  double point_size_m = 0.05;           // the map's point spacing (livo-colour's voxel): a splat's width
  int max_px = 12;                      // splats no wider than this
  cv::Vec3b background{255, 255, 255};  // BGR
  /// Eye-dome lighting: a pixel nearer than its neighbours stays bright, one farther (behind an
  /// edge) is darkened by exp(-strength * the sum of its log-depth steps); 0: the points' colours.
  double edl_strength = 0.0;
};

/// The points no higher than the trajectory's height there plus `cut_above_m` (the ceiling of a
/// room, the canopy over a road would hide the map from above).
ColouredPoints pointsBelowCut(const ColouredPoints& points, const TrajectoryHeight& height, double cut_above_m);

/// The points from straight above: the highest point of a pixel wins it. `top_z` (if given) gets
/// the z of each pixel's point (NaN where none).
cv::Mat renderTopView(const ColouredPoints& points, const TopViewFrame& frame, const SplatStyle& style,
                      cv::Mat1f* top_z = nullptr);
/// The points through the camera: the nearest wins. `depth` (if given) gets each pixel's depth
/// (infinity where none).
cv::Mat renderPerspective(const ColouredPoints& points, const PerspectiveView& view, const SplatStyle& style,
                          cv::Mat1f* depth = nullptr);

/// The trajectory cut into pieces, [begin, end) index ranges of at least one pose: at a reset
/// (a stamp in `reset_stamps` starts a new piece: the new epoch's frame is unrelated), at a
/// non-finite position (left out), and where consecutive positions are farther apart than
/// max(5 m, 20 x the median step) (a gap).
std::vector<std::pair<size_t, size_t>> pathPieces(const Trajectory& trajectory,
                                                  const std::vector<double>& reset_stamps = {});

/// The poses from the last reset stamp on: the maps livo-colour and livo-octomap hold at the end
/// are of the newest epoch (earlier epochs' maps go to *_epoch<N> files, in frames of their own).
/// All of them without a reset.
Trajectory newestEpoch(const Trajectory& trajectory, const std::vector<double>& reset_stamps);

/// Draws the path over a top view: a dark-outlined cyan line, a green dot at its start and a red
/// one at its end.
void drawPathTopView(cv::Mat& image, const Trajectory& trajectory, const TopViewFrame& frame,
                     const std::vector<double>& reset_stamps = {});
/// The same through the camera, where the path is not behind the drawn points (`depth` from
/// renderPerspective).
void drawPathPerspective(cv::Mat& image, const cv::Mat1f& depth, const Trajectory& trajectory,
                         const PerspectiveView& view, const std::vector<double>& reset_stamps = {});

}  // namespace livo::report
