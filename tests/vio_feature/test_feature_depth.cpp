// Feature depth from a registered depth image and from LiDAR points, on constructed scenes with an
// occluding foreground: a feature takes the depth of its own surface or none, never the other's.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <optional>
#include <vector>

#include "livo/vio_feature/feature_depth.hpp"

using namespace livo;
using namespace livo::vio_feature;

namespace {

CameraRig testCamera() {
  CameraRig c;
  c.fx = c.fy = 400.0;
  c.cx = 319.5;
  c.cy = 239.5;
  c.distortion = {-0.05, 0.01, 0.0005, -0.0003};
  return c;
}

FeatureObservation at(double u, double v) {
  FeatureObservation f;
  f.pixel = Eigen::Vector2d(u, v);
  return f;
}

// A planar surface in the camera frame: n . p = d, bounded to |x - centre.x| <= half.x and
// |y - centre.y| <= half.y when `bounded`.
struct Surface {
  Vec3 normal;
  double d;
  bool bounded = false;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero(), half = Eigen::Vector2d::Zero();
};

/// Distance along the unit ray from `origin` to the nearest surface (none: nullopt).
std::optional<double> cast(const std::vector<Surface>& scene, const Vec3& origin, const Vec3& ray) {
  std::optional<double> best;
  for (const Surface& s : scene) {
    const double den = s.normal.dot(ray);
    if (std::abs(den) < 1e-9) continue;
    const double t = (s.d - s.normal.dot(origin)) / den;
    if (t <= 0.0 || (best && t >= *best)) continue;
    const Vec3 p = origin + t * ray;
    if (s.bounded && (std::abs(p.x() - s.centre.x()) > s.half.x() || std::abs(p.y() - s.centre.y()) > s.half.y()))
      continue;
    best = t;
  }
  return best;
}

/// A 16-beam spinning LiDAR 15 cm above and 10 cm beside the camera (axis along the camera's -y),
/// beams 2 degrees apart from -15 to +15 degrees, 0.2 degrees per firing, 1 cm range noise:
/// its points in the camera frame.
std::vector<Vec3> lidarPoints(const std::vector<Surface>& scene) {
  const Vec3 origin(0.1, -0.15, 0.0);
  std::vector<Vec3> points;
  uint64_t state = 12345;
  auto noise = [&state]() {  // deterministic, uniform in [-1, 1]
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return static_cast<double>(state >> 11) / static_cast<double>(1ULL << 53) * 2.0 - 1.0;
  };
  for (int ring = 0; ring < 16; ++ring) {
    const double el = (-15.0 + 2.0 * ring) * M_PI / 180.0;
    for (double az = -80.0; az <= 80.0; az += 0.2) {
      const double a = az * M_PI / 180.0;
      const Vec3 ray(std::cos(el) * std::sin(a), -std::sin(el), std::cos(el) * std::cos(a));
      const std::optional<double> t = cast(scene, origin, ray);
      if (t) points.push_back(origin + (*t + 0.01 * noise()) * ray);
    }
  }
  return points;
}

struct LidarResult {
  int assigned = 0, covered = 0, wrong = 0;
};

/// Features on a 3 px grid inside the LiDAR's field (|v - cy| < 90 px) of a camera at the origin:
/// every depth given must be its own surface's (within 3 %); `covered` counts the features at least
/// `edge_px` from any depth edge of the true depth image.
LidarResult checkLidarDepth(const std::vector<Surface>& scene, double edge_px) {
  const CameraProjection camera(testCamera());
  LidarDepthMap map(camera, LidarDepthOptions{});
  map.setPoints(lidarPoints(scene));
  auto true_z = [&](const Eigen::Vector2d& px) {
    const Vec3 ray = camera.pixelRay(px);
    const std::optional<double> t = cast(scene, Vec3::Zero(), ray);
    return t ? *t * ray.z() : 0.0;
  };
  LidarResult r;
  for (double v = 160; v <= 320; v += 3)
    for (double u = 20; u <= 620; u += 3) {
      const Eigen::Vector2d px(u, v);
      const double truth = true_z(px);
      bool near_edge = false;
      for (double a = 0; a < 2 * M_PI && !near_edge; a += M_PI / 8) {
        const double z = true_z(px + edge_px * Eigen::Vector2d(std::cos(a), std::sin(a)));
        near_edge = std::abs(z - truth) > 0.2 * truth;
      }
      const double z = map.depthAt(px);
      if (!near_edge) ++r.covered;
      if (z == 0.0) continue;
      if (!near_edge) ++r.assigned;
      if (std::abs(z - truth) > 0.03 * truth) {
        ++r.wrong;
        ADD_FAILURE() << "pixel " << u << ", " << v << ": depth " << z << ", truth " << truth;
      }
    }
  return r;
}

}  // namespace

TEST(FeatureDepth, FromADepthImageOnlyWhereTheWindowAgrees) {
  // background 4 m, a foreground rectangle at 2 m, a hole (no depth) in the corner, 0.3 % noise
  cv::Mat depth(480, 640, CV_32FC1, cv::Scalar(4.0f));
  depth(cv::Rect(200, 150, 200, 180)).setTo(2.0f);
  cv::Mat noise(480, 640, CV_32FC1);
  cv::RNG rng(7);
  rng.fill(noise, cv::RNG::UNIFORM, -0.003, 0.003);
  depth = depth.mul(1.0 + noise);
  depth(cv::Rect(500, 50, 40, 40)).setTo(0.0f);
  depth.at<float>(100, 102) = std::nanf("");

  std::vector<FeatureObservation> f = {
      at(100, 100),    // background (a NaN in the window does not count)
      at(300, 240),    // foreground
      at(200.2, 240),  // on the rectangle's left edge: both depths in the window
      at(203, 240),    // just inside it
      at(399.6, 200),  // on the right edge
      at(520, 70),     // in the hole
      at(500.6, 70),   // on the hole's edge: too few valid pixels
      at(1, 1),        // the image corner: a clipped window
  };
  f[1].depth = 99.0;  // overwritten
  EXPECT_EQ(depthFromImage(depth, DepthImageOptions{}, &f), 4);
  EXPECT_NEAR(f[0].depth, 4.0, 0.02);
  EXPECT_NEAR(f[1].depth, 2.0, 0.01);
  EXPECT_EQ(f[2].depth, 0.0);
  EXPECT_NEAR(f[3].depth, 2.0, 0.01);
  EXPECT_EQ(f[4].depth, 0.0);
  EXPECT_EQ(f[5].depth, 0.0);
  EXPECT_EQ(f[6].depth, 0.0);
  EXPECT_NEAR(f[7].depth, 4.0, 0.02);

  EXPECT_THROW(depthFromImage(cv::Mat(480, 640, CV_16UC1), DepthImageOptions{}, &f), std::invalid_argument);
}

TEST(FeatureDepth, FromLidarNeverTakesTheOtherSurfacesDepth) {
  // a wall 8 m away and, in front of it, a 1.2 x 1 m board at 3 m; the LiDAR, 18 cm from the
  // camera, sees parts of the wall the camera cannot
  std::vector<Surface> scene(2);
  scene[0] = Surface{Vec3::UnitZ(), 8.0};
  scene[1] = Surface{Vec3::UnitZ(), 3.0, true, Eigen::Vector2d(-0.2, 0.0), Eigen::Vector2d(0.6, 0.5)};
  const LidarResult r = checkLidarDepth(scene, 15.0);
  std::cout << "board before a wall: " << r.assigned << " of " << r.covered
            << " features away from the edges given a depth, " << r.wrong << " wrong\n";
  EXPECT_EQ(r.wrong, 0);
  EXPECT_GT(r.assigned, 0.8 * r.covered);
}

TEST(FeatureDepth, FromLidarOnASlantedWall) {
  // a wall turned 50 degrees about the vertical, 4 to 37 m away across the image: on its far side
  // the depth changes by 3 % per pixel; the plane through the support gives it where a median of
  // the support could not
  std::vector<Surface> scene(1);
  const double a = 50.0 * M_PI / 180.0;
  scene[0] = Surface{Vec3(std::sin(a), 0.0, std::cos(a)), 4.0 * std::cos(a)};
  const LidarResult r = checkLidarDepth(scene, 15.0);
  std::cout << "slanted wall: " << r.assigned << " of " << r.covered << " features given a depth, " << r.wrong
            << " wrong\n";
  EXPECT_EQ(r.wrong, 0);
  EXPECT_GT(r.assigned, 0.8 * r.covered);
}

TEST(FeatureDepth, LidarDepthKeepsTheNearestPointPerCellAndFillsOnlyWhatItFinds) {
  const CameraProjection camera(testCamera());
  LidarDepthMap map(camera, LidarDepthOptions{});
  // two points in one cell (the farther one dropped), one behind the camera, one out of range
  map.setPoints({Vec3(0.0, 0.0, 5.0), Vec3(0.0, 0.0, 6.0), Vec3(0.0, 0.0, -5.0), Vec3(0.0, 0.0, 100.0)});
  EXPECT_EQ(map.keptPoints(), 1u);
  std::vector<FeatureObservation> f = {at(319.5, 239.5)};
  f[0].depth = 2.5;  // e.g. from a depth image: kept where the LiDAR has too little support
  EXPECT_EQ(map.assign(&f), 0);
  EXPECT_EQ(f[0].depth, 2.5);
}
