// The colouring core without LCM: projection against OpenCV, occlusion on a constructed scene,
// the time window, accumulation and exposure normalisation, loop corrections, the colour image
// (decoding itself is the shared livo_camera_image, tested in tests/unit/test_camera_image.cpp) and
// the PLY/PCD files.
#include <algorithm>
#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "livo/camera_projection.hpp"
#include "livo/colour/colour_map.hpp"
#include "livo/colour/colouring_pipeline.hpp"
#include "livo/colour/depth_buffer.hpp"
#include "livo/colour/exposure_gain.hpp"
#include "livo/colour/view_cone.hpp"
#include "livo/coloured_point_files.hpp"
#include "scene_fixtures.hpp"
#include "temp_path.hpp"

using namespace livo;
using namespace livo::colour;
using livo_test::WallAndBox;

namespace {

RegisteredScanView viewOf(int64_t utime, const std::vector<float>& x, const std::vector<float>& y,
                          const std::vector<float>& z, const std::vector<float>& dt,
                          const Pose3& T = Pose3::Identity()) {
  RegisteredScanView v;
  v.utime = utime;
  v.cloud_utime = utime - 100000;
  v.T_W_I = T;
  v.num_points = static_cast<int>(x.size());
  v.x = x.data();
  v.y = y.data();
  v.z = z.data();
  v.time_offset = dt.data();
  return v;
}

}  // namespace

TEST(CameraProjection, AgreesWithOpenCvProjectPointsWithDistortion) {
  const CameraRig rig = livo_test::testCamera(true);
  CameraProjection cam(rig);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<cv::Point3d> object;
  for (int i = 0; i < 500; ++i) object.emplace_back(0.7 * u(rng), 0.5 * u(rng), 1.0 + std::abs(2.0 * u(rng)));
  const cv::Mat K = (cv::Mat_<double>(3, 3) << rig.fx, 0, rig.cx, 0, rig.fy, rig.cy, 0, 0, 1);
  const cv::Mat D =
      (cv::Mat_<double>(1, 4) << rig.distortion[0], rig.distortion[1], rig.distortion[2], rig.distortion[3]);
  std::vector<cv::Point2d> expected;
  cv::projectPoints(object, cv::Mat::zeros(3, 1, CV_64F), cv::Mat::zeros(3, 1, CV_64F), K, D, expected);
  int inside = 0;
  for (size_t i = 0; i < object.size(); ++i) {
    Eigen::Vector2d px;
    if (!cam.project(Eigen::Vector3d(object[i].x, object[i].y, object[i].z), &px)) continue;
    ++inside;
    EXPECT_NEAR(px.x(), expected[i].x, 1e-9);
    EXPECT_NEAR(px.y(), expected[i].y, 1e-9);
  }
  EXPECT_GT(inside, 100);
  Eigen::Vector2d px;
  EXPECT_FALSE(cam.project(Eigen::Vector3d(0, 0, -1), &px));  // behind
  EXPECT_FALSE(cam.project(Eigen::Vector3d(10, 0, 1), &px));  // far outside the field
}

TEST(ColouringPipeline, ColoursFromTheCameraPoseAtTheImageTimeWithExtrinsics) {
  // body moves along x; the camera is mounted 0.1 m to the body's right and looks along body z.
  CameraRig rig = livo_test::testCamera(false);
  rig.T_I_C = Pose3::Identity();
  rig.T_I_C.translation() = Vec3(0.1, 0.0, 0.0);
  ColourOptions o;
  o.estimate_gain = false;
  o.max_time_difference = 0.2;
  ColouringPipeline pipe(o, rig);
  // at t_img the camera sits at the world origin: body at x = -0.1; poses at 0 and 0.2 s bracket it
  const int64_t t0 = 1000000, t_img = t0 + 100000, t1 = t0 + 200000;
  Pose3 A = Pose3::Identity(), B = Pose3::Identity();
  A.translation() = Vec3(-0.2, 0, 0);
  B.translation() = Vec3(0.0, 0, 0);
  pipe.addPose(t0, A);
  std::vector<float> x, y, z;
  WallAndBox::points(0.05, 0.1, &x, &y, &z);
  std::vector<float> dt(x.size(), 0.05f);  // measured at t1 - 0.05 s: inside the window
  std::string error;
  ASSERT_TRUE(pipe.addImage(WallAndBox::render(rig, t_img), &error)) << error;
  EXPECT_EQ(pipe.pendingImages(), 1u);  // the scan that closes the window has not come yet
  ASSERT_TRUE(pipe.addScan(viewOf(t1, x, y, z, dt, B), &error)) << error;
  ASSERT_TRUE(pipe.addScan(viewOf(t1 + 200000, {}, {}, {}, {}, B), &error)) << error;
  EXPECT_EQ(pipe.pendingImages(), 0u);
  EXPECT_EQ(pipe.stats().images, 1);
  int checked = 0;
  for (const MapPoint& p : pipe.map().points()) {
    if (!p.coloured()) continue;
    const double truth = WallAndBox::inBox(p.position.x(), p.position.y()) && p.position.z() < 3
                             ? WallAndBox::kBoxGrey
                             : WallAndBox::wallGrey(p.position.x(), p.position.y());
    if (p.position.z() > 3 && WallAndBox::inBox(p.position.x() * 0.4, p.position.y() * 0.4)) continue;
    EXPECT_NEAR(p.colour[0], truth, 3.0) << p.position.transpose();
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

TEST(ColouringPipeline, OcclusionKeepsForegroundColourOffTheBackground) {
  const CameraRig rig = livo_test::testCamera(false);
  ColourOptions o;
  o.estimate_gain = false;
  ColouringPipeline pipe(o, rig);
  std::vector<float> x, y, z;
  WallAndBox::points(0.03, 0.12, &x, &y, &z);  // sparse rows, as a LiDAR gives
  std::vector<float> dt(x.size(), 0.0f);
  std::string error;
  ASSERT_TRUE(pipe.addScan(viewOf(1000000, x, y, z, dt), &error));
  ASSERT_TRUE(pipe.addImage(WallAndBox::render(rig, 1000000), &error));
  pipe.flush();
  int hidden = 0, hidden_coloured = 0, visible_wall = 0, box = 0;
  for (const MapPoint& p : pipe.map().points()) {
    const double px = p.position.x(), py = p.position.y();
    if (p.position.z() < 3) {
      ++box;
      ASSERT_TRUE(p.coloured());
      EXPECT_NEAR(p.colour[0], WallAndBox::kBoxGrey, 3.0) << p.position.transpose();
      continue;
    }
    // the box's shadow on the wall (scaled by 5/2), minus a 5 cm margin for the edge
    const double sx = px * WallAndBox::kBoxZ / WallAndBox::kWallZ, sy = py * WallAndBox::kBoxZ / WallAndBox::kWallZ;
    const bool shadow = std::abs(sx) < WallAndBox::kBoxHalfX - 0.02 && std::abs(sy) < WallAndBox::kBoxHalfY - 0.02;
    const bool clear = std::abs(sx) > WallAndBox::kBoxHalfX + 0.02 || std::abs(sy) > WallAndBox::kBoxHalfY + 0.02;
    if (shadow) {
      ++hidden;
      if (p.coloured()) ++hidden_coloured;
    } else if (clear && p.coloured()) {
      ++visible_wall;
      EXPECT_NEAR(p.colour[0], WallAndBox::wallGrey(px, py), 3.0);
    }
  }
  EXPECT_GT(box, 100);
  EXPECT_GT(hidden, 100);
  EXPECT_EQ(hidden_coloured, 0);
  EXPECT_GT(visible_wall, 2000);
  EXPECT_GT(pipe.stats().occluded, hidden);
}

TEST(ColouringPipeline, PointsFarFromTheImageTimeTakeNoColour) {
  const CameraRig rig = livo_test::testCamera(false);
  ColourOptions o;
  o.max_time_difference = 0.1;
  ColouringPipeline pipe(o, rig);
  std::vector<float> x, y, z;
  WallAndBox::points(0.05, 0.1, &x, &y, &z);
  std::vector<float> dt(x.size(), 0.0f);
  std::string error;
  ASSERT_TRUE(pipe.addScan(viewOf(1000000, x, y, z, dt), &error));       // measured at 0.9 s
  ASSERT_TRUE(pipe.addScan(viewOf(1400000, x, y, z, dt), &error));       // and again at 1.3 s
  ASSERT_TRUE(pipe.addImage(WallAndBox::render(rig, 1150000), &error));  // >= 0.15 s from both
  pipe.flush();
  EXPECT_EQ(pipe.stats().images, 1);
  EXPECT_EQ(pipe.map().colouredCount(), 0u);
  EXPECT_EQ(pipe.stats().projected, 0);
}

TEST(ColourMap, RobustRunningMeanRejectsOutliersAndSaturates) {
  ColourMap map(0.1);
  bool created = false;
  const uint32_t id = map.addPoint(Eigen::Vector3f(0.01f, 0.02f, 0.03f), -1, &created);
  EXPECT_TRUE(created);
  EXPECT_EQ(map.addPoint(Eigen::Vector3f(0.09f, 0.05f, 0.01f), -1, &created), id);  // same voxel
  EXPECT_FALSE(created);
  AccumulationOptions o;
  o.outlier_threshold = 30;
  o.outlier_min_count = 3;
  o.max_count = 4;
  for (float v : {100.f, 110.f, 90.f}) EXPECT_TRUE(map.accumulate(id, Eigen::Vector3f::Constant(v), o));
  EXPECT_NEAR(map.point(id).colour[0], 100.0f, 1e-4);
  EXPECT_FALSE(map.accumulate(id, Eigen::Vector3f(100, 100, 250), o));  // an occluder's colour
  EXPECT_EQ(map.point(id).rejected, 1);
  EXPECT_TRUE(map.accumulate(id, Eigen::Vector3f::Constant(120), o));
  EXPECT_NEAR(map.point(id).colour[0], 105.0f, 1e-4);
  EXPECT_TRUE(map.accumulate(id, Eigen::Vector3f::Constant(125), o));  // count saturates at 4
  EXPECT_NEAR(map.point(id).colour[0], 110.0f, 1e-4);
  EXPECT_EQ(map.point(id).count, 4);
}

TEST(ExposureGain, MedianRatioIgnoresDarkSaturatedAndOutliers) {
  std::vector<Eigen::Vector3f> obs, map;
  for (int i = 0; i < 100; ++i) {
    const float m = 40.0f + i;
    map.push_back(Eigen::Vector3f::Constant(m));
    obs.push_back(Eigen::Vector3f::Constant(i % 10 == 0 ? 0.4f * m : 1.3f * m));  // 10 % outliers
  }
  map.push_back(Eigen::Vector3f::Constant(2.0f));
  obs.push_back(Eigen::Vector3f::Constant(9.0f));
  const GainEstimate g = estimateGain(obs, map, 50, 0.5, 2.0);
  ASSERT_TRUE(g.valid);
  EXPECT_EQ(g.pairs, 100);
  EXPECT_NEAR(g.gain, 1.3, 1e-5);
  EXPECT_FALSE(estimateGain(obs, map, 200, 0.5, 2.0).valid);
}

TEST(ColouringPipeline, ExposureNormalisationKeepsColoursAcrossBrightnessChanges) {
  const CameraRig rig = livo_test::testCamera(false);
  std::vector<float> x, y, z;
  WallAndBox::points(0.05, 0.1, &x, &y, &z);
  std::vector<float> dt(x.size(), 0.0f);
  for (bool known_exposure : {true, false}) {
    ColourOptions o;
    o.max_time_difference = 0.5;
    o.use_exposure_time = known_exposure;
    o.estimate_gain = !known_exposure;
    ColouringPipeline pipe(o, rig);
    std::string error;
    pipe.addPose(800000, Pose3::Identity());
    pipe.addPose(1200000, Pose3::Identity());
    ASSERT_TRUE(pipe.addScan(viewOf(1000000, x, y, z, dt), &error));
    // the image brightens by 30 % (auto-exposure); stamps say so only when known_exposure
    const double gains[4] = {1.0, 1.0, 1.3, 1.3};
    for (int k = 0; k < 4; ++k)
      ASSERT_TRUE(pipe.addImage(
          WallAndBox::render(rig, 900000 + 50000 * k, gains[k], known_exposure ? float(0.005 * gains[k]) : 0.0f),
          &error));
    pipe.flush();
    EXPECT_EQ(pipe.stats().images, 4);
    if (!known_exposure) {
      EXPECT_NEAR(pipe.stats().last_gain, 1.3, 0.02);
    }
    double err = 0;
    int n = 0;
    for (const MapPoint& p : pipe.map().points()) {
      if (!p.coloured() || p.position.z() < 3 || WallAndBox::inBox(p.position.x() * 0.4, p.position.y() * 0.4))
        continue;
      if (WallAndBox::wallGrey(p.position.x(), p.position.y()) * 1.3 > 250) continue;
      err += std::abs(p.colour[0] - WallAndBox::wallGrey(p.position.x(), p.position.y()));
      ++n;
    }
    ASSERT_GT(n, 1000);
    EXPECT_LT(err / n, 1.5) << (known_exposure ? "exposure time" : "estimated gain");
  }
}

TEST(ColouringPipeline, LoopCorrectionMovesPointsWithTheirKeyframe) {
  const CameraRig rig = livo_test::testCamera(false);
  ColouringPipeline pipe(ColourOptions{}, rig);
  pipe.addKeyframe(0, 1000000, Pose3::Identity());
  std::vector<float> x{0.f, 1.f}, y{0.f, 0.f}, z{5.f, 5.f}, dt{0.f, 0.f};
  std::string error;
  ASSERT_TRUE(pipe.addScan(viewOf(1000000, x, y, z, dt), &error));
  pipe.addKeyframe(1, 2000000, Pose3::Identity());
  std::vector<float> x2{3.f}, y2{0.f}, z2{5.f}, dt2{0.f};
  ASSERT_TRUE(pipe.addScan(viewOf(2000000, x2, y2, z2, dt2), &error));
  Pose3 corrected = Pose3::Identity();
  corrected.translation() = Vec3(0.0, 0.5, 0.0);
  EXPECT_EQ(pipe.applyCorrection({{1, corrected}}), 1);
  ASSERT_EQ(pipe.map().size(), 3u);
  EXPECT_NEAR(pipe.map().point(0).position.y(), 0.0, 1e-6);  // anchored to keyframe 0: stays
  EXPECT_NEAR(pipe.map().point(2).position.y(), 0.5, 1e-6);  // anchored to keyframe 1: moves
  EXPECT_EQ(pipe.applyCorrection({{1, corrected}}), 0);      // already there
}

// Scan points farther than max_depth + map_margin (30 + 10 m) from the body cannot be coloured
// by any image of their time window: they are counted and stay out of the map (with a 100 m LiDAR
// they would otherwise keep every tile in reach in memory; see the colour README, Memory).
TEST(ColouringPipeline, PointsBeyondTheCamerasReachAreNotMapped) {
  const CameraRig rig = livo_test::testCamera(false);
  ColourOptions o;
  o.map_only_in_view = false;  // the points lie to the side: only the reach is tested here
  ColouringPipeline pipe(o, rig);
  Pose3 B = Pose3::Identity();
  B.translation() = Vec3(100.0, -50.0, 2.0);
  std::vector<float> x{139.9f, 140.1f, 100.f, 59.9f}, y{-50.f, -50.f, -10.5f, -50.f}, z{2.f, 2.f, 2.f, 2.f},
      dt{0.f, 0.f, 0.f, 0.f};
  std::string error;
  ASSERT_TRUE(pipe.addScan(viewOf(2000000, x, y, z, dt, B), &error)) << error;
  EXPECT_EQ(pipe.map().size(), 2u);  // 39.9 m and 39.5 m away; the two 40.1 m away left out
  EXPECT_EQ(pipe.stats().points_out_of_reach, 2);
  EXPECT_EQ(pipe.stats().points_in, 2);
  ColourOptions wide = o;
  wide.map_margin = 100.0;
  ColouringPipeline all(wide, rig);
  ASSERT_TRUE(all.addScan(viewOf(2000000, x, y, z, dt, B), &error)) << error;
  EXPECT_EQ(all.map().size(), 4u);
}

// A point no image of its time window coloured leaves the map once no kept scan refers to it (it
// could only be coloured by an image within max_time_difference of a measurement of it): a 360 deg
// LiDAR under one camera would otherwise keep most of every resident tile uncoloured, more with
// every pass (see the colour README, Memory). A later measurement of the voxel creates it anew.
TEST(ColouringPipeline, PointsNoImageCanColourLeaveTheMap) {
  const CameraRig rig = livo_test::testCamera(false);
  ColourOptions o;
  o.estimate_gain = false;     // window 0.3 s: scans are kept 2 * 0.3 + 1 s past their last point
  o.map_only_in_view = false;  // the point behind the camera must enter the map first
  ColouringPipeline pipe(o, rig);
  std::string error;
  // in front of the camera (coloured by the image at 1.0 s) and behind it (seen by no image)
  std::vector<float> x{0.f, 0.f}, y{0.f, 0.f}, z{5.f, -5.f}, dt{0.1f, 0.1f};
  ASSERT_TRUE(pipe.addImage(WallAndBox::render(rig, 1000000), &error)) << error;
  ASSERT_TRUE(pipe.addScan(viewOf(1000000, x, y, z, dt), &error)) << error;
  int64_t t = 1000000;
  auto emptyScansUntil = [&](int64_t until) {
    while (t + 100000 <= until) {
      t += 100000;
      ASSERT_TRUE(pipe.addScan(viewOf(t, {}, {}, {}, {}), &error)) << error;
    }
  };
  emptyScansUntil(2500000);  // the first scan is still kept: nothing leaves
  EXPECT_EQ(pipe.stats().images, 1);
  EXPECT_EQ(pipe.map().residentPoints(), 2u);
  EXPECT_EQ(pipe.stats().points_pruned, 0);
  emptyScansUntil(3100000);  // dropped at 2.7 s (its points at 1.0 s); the next pass is at 3.0 s
  ASSERT_EQ(pipe.map().residentPoints(), 1u);
  EXPECT_EQ(pipe.stats().points_pruned, 1);
  uint32_t kept = 0;
  for (uint32_t id = 0; id < pipe.map().size(); ++id)
    if (pipe.map().point(id).live()) kept = id;
  EXPECT_TRUE(pipe.map().point(kept).coloured());
  EXPECT_FLOAT_EQ(pipe.map().point(kept).position.z(), 5.f);
  // the voxel behind the camera measured again, 2 cm over: a new point, at the new measurement
  std::vector<float> x2{0.02f}, y2{0.f}, z2{-5.f}, dt2{0.f};
  t += 100000;
  ASSERT_TRUE(pipe.addScan(viewOf(t, x2, y2, z2, dt2), &error)) << error;
  ASSERT_EQ(pipe.map().residentPoints(), 2u);
  bool found = false;
  for (uint32_t id = 0; id < pipe.map().size(); ++id) {
    const MapPoint& p = pipe.map().point(id);
    if (p.live() && p.position.z() < 0) {
      found = true;
      EXPECT_FLOAT_EQ(p.position.x(), 0.02f);
      EXPECT_FALSE(p.coloured());
    }
  }
  EXPECT_TRUE(found);
  // a point measured again and again stays while it is measured
  for (int k = 0; k < 30; ++k) {
    t += 100000;
    ASSERT_TRUE(pipe.addScan(viewOf(t, x2, y2, z2, dt2), &error)) << error;
    ASSERT_EQ(pipe.map().residentPoints(), 2u) << "scan " << k;
  }
}

// A spinning LiDAR sees all around; one camera sees a cone. Points no image of their time window
// can see are not mapped (they would only fill the tiles in use): the cone is the camera's field
// (45 deg to the corners of the test camera) + view_margin_deg (15) + 1.5 x the body's rotation
// over the window, and points nearer than the camera's travel pass whatever their direction.
TEST(ColouringPipeline, PointsOutsideTheWidenedViewConeAreNotMapped) {
  const CameraRig rig = livo_test::testCamera(false);
  auto deg = [](double a) { return a * M_PI / 180.0; };
  auto at = [](double angle, double r) {  // in the camera's x-z plane, `angle` from its axis (+z)
    return Eigen::Vector3f(float(r * std::sin(angle)), 0.f, float(r * std::cos(angle)));
  };
  std::vector<Eigen::Vector3f> pts{at(deg(0), 5),  at(deg(55), 5),  at(deg(65), 5),
                                   at(deg(90), 5), at(deg(180), 5), at(deg(120), 0.15)};
  auto scanOf = [&](int64_t utime, const Pose3& T, std::vector<float>* x, std::vector<float>* y, std::vector<float>* z,
                    std::vector<float>* dt) {
    x->clear(), y->clear(), z->clear(), dt->clear();
    for (const Eigen::Vector3f& p : pts) {
      const Eigen::Vector3f w = (T * p.cast<double>()).cast<float>();
      x->push_back(w.x()), y->push_back(w.y()), z->push_back(w.z()), dt->push_back(0.05f);
    }
    return viewOf(utime, *x, *y, *z, *dt, T);
  };
  std::vector<float> x, y, z, dt;
  std::string error;
  {  // at rest: 0, 55 deg and the point 0.15 m away (within the 0.2 m travel margin) are mapped
    ColouringPipeline pipe(ColourOptions{}, rig);
    ASSERT_TRUE(pipe.addScan(scanOf(1000000, Pose3::Identity(), &x, &y, &z, &dt), &error)) << error;
    EXPECT_EQ(pipe.map().residentPoints(), 3u);
    EXPECT_EQ(pipe.stats().points_out_of_view, 3);
    ColourOptions all;
    all.map_only_in_view = false;
    ColouringPipeline every(all, rig);
    ASSERT_TRUE(every.addScan(scanOf(1000000, Pose3::Identity(), &x, &y, &z, &dt), &error)) << error;
    EXPECT_EQ(every.map().residentPoints(), pts.size());
  }
  {  // turning at 1 rad/s about the camera's y axis: the cone widens by 1.5 * 1 * (0.3 + 0.1) s = 34 deg
    ColouringPipeline pipe(ColourOptions{}, rig);
    ASSERT_TRUE(pipe.addScan(viewOf(900000, {}, {}, {}, {}, Pose3::Identity()), &error)) << error;
    Pose3 turned = Pose3::Identity();
    turned.linear() = so3::Exp(Vec3(0, 0.1, 0));
    ASSERT_TRUE(pipe.addScan(scanOf(1000000, turned, &x, &y, &z, &dt), &error)) << error;
    EXPECT_EQ(pipe.map().residentPoints(), 5u);  // 65 and 90 deg now too (< 45 + 15 + 34 + 2); not 180
  }
}

TEST(ColouringPipeline, RefusesStaleStampsAndSkipsNonFinitePoints) {
  const CameraRig rig = livo_test::testCamera(false);
  ColouringPipeline pipe(ColourOptions{}, rig);
  std::vector<float> x{0.f, NAN, 1.f}, y{0.f, 0.f, INFINITY}, z{5.f, 5.f, 5.f}, dt{0.f, 0.f, 0.f};
  std::string error;
  ASSERT_TRUE(pipe.addScan(viewOf(2000000, x, y, z, dt), &error));
  EXPECT_EQ(pipe.stats().points_rejected, 2);
  EXPECT_FALSE(pipe.addScan(viewOf(1000000, x, y, z, dt), &error));
  ColourImage img = WallAndBox::render(rig, 2000000);
  EXPECT_TRUE(pipe.addImage(img, &error));
  EXPECT_FALSE(pipe.addImage(img, &error));
  ColourImage small;
  small.utime = 3000000;
  small.pixels = cv::Mat(10, 10, CV_8UC1, cv::Scalar(0));
  EXPECT_FALSE(pipe.addImage(small, &error));
}

// Without registered scans (no LIO output) images cannot be processed: at most max_pending_images
// wait, the oldest are dropped and counted, and the ones kept are coloured once scans come.
TEST(ColouringPipeline, PendingImagesAreBoundedWhileNoScansCome) {
  const CameraRig rig = livo_test::testCamera(false);
  ColourOptions o;
  o.max_pending_images = 4;
  o.max_time_difference = 0.1;
  ColouringPipeline pipe(o, rig);
  std::string error;
  const ColourImage frame = WallAndBox::render(rig, 0);
  for (int k = 0; k < 10; ++k) {
    ColourImage img = frame;
    img.utime = 1000000 + 50000 * k;
    ASSERT_TRUE(pipe.addImage(img, &error)) << error;
    EXPECT_LE(pipe.pendingImages(), 4u);
  }
  EXPECT_EQ(pipe.pendingImages(), 4u);
  EXPECT_EQ(pipe.stats().images_dropped, 6);
  // the kept ones (1.30 .. 1.45 s) are coloured when scans and poses cover them
  pipe.addPose(1200000, Pose3::Identity());
  std::vector<float> x, y, z;
  WallAndBox::points(0.05, 0.1, &x, &y, &z);
  for (int64_t t = 1300000; t <= 1700000; t += 100000) {
    const std::vector<float> at(x.size(), 0.05f);
    ASSERT_TRUE(pipe.addScan(viewOf(t, x, y, z, at), &error)) << error;
  }
  EXPECT_EQ(pipe.pendingImages(), 0u);
  EXPECT_EQ(pipe.stats().images, 4);
  EXPECT_EQ(pipe.stats().images_without_pose, 0);
  EXPECT_GT(pipe.map().colouredCount(), 1000u);
}

// decodeColourImage: grey stays one channel, colour becomes R, G, B; sample() interpolates either;
// the stamp and a usable exposure time are kept; the rig's size and sample()'s 2x2 are required.
TEST(ColourImage, DecodesThroughTheSharedDecoderAndSamples) {
  cv::Mat rgb(4, 5, CV_8UC3);
  for (int v = 0; v < 4; ++v)
    for (int u = 0; u < 5; ++u) rgb.at<cv::Vec3b>(v, u) = cv::Vec3b(10 * u, 20 * v, 7);
  std::vector<uint8_t> raw(rgb.datastart, rgb.dataend);
  RawImage r;
  r.utime = 77;
  r.width = 5;
  r.height = 4;
  r.encoding = static_cast<int>(ImageEncoding::kRgb8);
  r.exposure_time = 0.01f;
  r.data = raw.data();
  r.size = raw.size();
  ColourImage out;
  std::string error;
  ASSERT_TRUE(decodeColourImage(r, 5, 4, &out, &error)) << error;
  EXPECT_FALSE(out.grey());
  EXPECT_EQ(out.utime, 77);
  EXPECT_FLOAT_EQ(out.exposure_time, 0.01f);
  EXPECT_NEAR(out.sample(Eigen::Vector2d(2.5, 1.0))[0], 25.0f, 1e-4);
  EXPECT_NEAR(out.sample(Eigen::Vector2d(2.0, 1.5))[1], 30.0f, 1e-4);
  EXPECT_NEAR(out.sample(Eigen::Vector2d(4.0, 3.0))[2], 7.0f, 1e-4);  // the last pixel

  std::vector<uint8_t> grey(20);
  for (int k = 0; k < 20; ++k) grey[k] = static_cast<uint8_t>(10 * (k % 5) + k / 5);
  r.encoding = static_cast<int>(ImageEncoding::kGray8);
  r.data = grey.data();
  r.size = grey.size();
  r.exposure_time = -1.0f;  // unknown
  ASSERT_TRUE(decodeColourImage(r, 5, 4, &out, &error)) << error;
  EXPECT_TRUE(out.grey());
  EXPECT_EQ(out.exposure_time, 0.0f);
  EXPECT_TRUE(out.sample(Eigen::Vector2d(1.5, 2.5)).isApprox(Eigen::Vector3f::Constant(17.5f)));

  EXPECT_FALSE(decodeColourImage(r, 6, 4, &out, &error));  // not the rig's size
  EXPECT_NE(error.find("5x4"), std::string::npos) << error;
  r.width = r.height = 1;
  EXPECT_FALSE(decodeColourImage(r, 1, 1, &out, &error));  // too small to sample
  EXPECT_NE(error.find("2x2"), std::string::npos) << error;
}

TEST(MapFiles, PlyAndPcdLoadBack) {
  ColouredPoints pts;
  for (int i = 0; i < 1000; ++i) {
    pts.position.emplace_back(0.1f * i, -0.5f * i, 3.25f);
    pts.rgb.push_back({uint8_t(i), uint8_t(255 - i % 256), uint8_t(i * 7)});
  }
  for (const bool ply : {true, false}) {
    const std::string path = livo_test::tempPath(ply ? "map.ply" : "map.pcd");
    std::string error;
    ASSERT_TRUE(ply ? writePly(path, pts, &error) : writePcd(path, pts, &error)) << error;
    ColouredPoints back;
    ASSERT_TRUE(ply ? readPly(path, &back, &error) : readPcd(path, &back, &error)) << error;
    ASSERT_EQ(back.size(), pts.size());
    for (size_t i = 0; i < pts.size(); ++i) {
      EXPECT_EQ(back.position[i], pts.position[i]);
      EXPECT_EQ(back.rgb[i], pts.rgb[i]);
    }
  }
  std::string error;
  ColouredPoints none;
  EXPECT_FALSE(readPly(livo_test::tempPath("missing.ply"), &none, &error));
}

// Tiles written to disk come back with exactly the same points and colours, and a correction
// made while a tile is on disk moves its points when it comes back.
namespace {
std::vector<MapPoint> allPoints(const ColourMap& map) {
  std::vector<MapPoint> out;
  map.forEachPoint([&](const MapPoint& p) { out.push_back(p); });
  std::sort(out.begin(), out.end(), [](const MapPoint& a, const MapPoint& b) {
    return std::lexicographical_compare(a.position.data(), a.position.data() + 3, b.position.data(),
                                        b.position.data() + 3);
  });
  return out;
}
bool samePoint(const MapPoint& a, const MapPoint& b) {
  return a.position == b.position && a.colour == b.colour && a.count == b.count && a.rejected == b.rejected &&
         a.anchor == b.anchor;
}
}  // namespace

TEST(ColourMapTiles, SpilledTilesComeBackWithTheSamePointsAndColours) {
  ColourMap map(0.05, TileOptions{2.0, 1.0, ""});
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-5.f, 5.f), c(0.f, 255.f);
  map.setTime(1000000);
  AccumulationOptions acc;
  for (int i = 0; i < 3000; ++i) {
    const uint32_t id = map.addPoint(Eigen::Vector3f(u(rng), u(rng), 0.2f * u(rng)), i % 3);
    for (int k = 0; k < i % 4; ++k) map.accumulate(id, Eigen::Vector3f(c(rng), c(rng), c(rng)), acc);
  }
  const std::vector<MapPoint> before = allPoints(map);
  std::vector<MapPoint> coloured_before;
  for (const MapPoint& p : before)
    if (p.coloured()) coloured_before.push_back(p);
  const size_t coloured = map.colouredCount();
  ASSERT_EQ(coloured, coloured_before.size());
  ASSERT_GT(before.size(), 2500u);
  ASSERT_GT(coloured, 2000u);
  ASSERT_LT(coloured, before.size());
  EXPECT_TRUE(map.evictIdle(1500000).empty());  // used within idle_s
  const std::vector<uint32_t> freed = map.evictIdle(2500000);
  EXPECT_EQ(freed.size(), before.size());
  EXPECT_EQ(map.residentPoints(), 0u);
  EXPECT_EQ(map.residentTiles(), 0u);
  EXPECT_GE(map.spilledTiles(), 25u);  // 10 x 10 m in 2 m tiles
  EXPECT_EQ(map.colouredCount(), coloured);
  // on disk: the coloured points, exactly (one never coloured is not kept)
  std::vector<MapPoint> on_disk = allPoints(map);
  ASSERT_EQ(on_disk.size(), coloured_before.size());
  for (size_t i = 0; i < on_disk.size(); ++i) ASSERT_TRUE(samePoint(on_disk[i], coloured_before[i])) << i;
  // a point falling into each tile brings it back: every coloured voxel finds its old point, a
  // voxel never coloured is measured anew
  map.setTime(3000000);
  for (const MapPoint& p : before) {
    bool created = false;
    const uint32_t id = map.addPoint(p.position, 99, &created);
    EXPECT_EQ(created, !p.coloured());
    if (p.coloured())
      ASSERT_TRUE(samePoint(map.point(id), p));
    else
      EXPECT_EQ(map.point(id).anchor, 99);
  }
  EXPECT_EQ(map.spilledTiles(), 0u);
  EXPECT_EQ(map.spilledBytes(), 0u);  // every record was given back
  EXPECT_GT(map.spillWrittenBytes(), 40u * coloured);
  EXPECT_EQ(map.residentPoints(), before.size());
  EXPECT_TRUE(map.takeMovedOnReload().empty());  // nothing moved
}

// Beyond max_resident_points the least recently used tiles go to disk before they are idle, but
// never one an image may still need (used within min_idle_s); they come back as they were.
TEST(ColourMapTiles, BeyondTheResidentBudgetTheLeastRecentlyUsedTilesGoToDisk) {
  TileOptions tiles{2.0, 100.0, ""};
  tiles.max_resident_points = 2500;
  tiles.min_idle_s = 1.5;
  ColourMap map(0.05, tiles);
  AccumulationOptions acc;
  std::vector<MapPoint> tile_a;
  // three 2 m tiles of 1,000 coloured points each, used at 1, 2 and 3 s
  for (int tile = 0; tile < 3; ++tile) {
    map.setTime((tile + 1) * 1000000);
    for (int i = 0; i < 1000; ++i) {
      const uint32_t id =
          map.addPoint(Eigen::Vector3f(2.0f * tile + 0.05f * (i % 40) + 0.01f, 0.05f * (i / 40) + 0.01f, 0.5f), tile);
      map.accumulate(id, Eigen::Vector3f(10.0f * tile, 20.0f, 30.0f), acc);
      if (tile == 0) tile_a.push_back(map.point(id));
    }
  }
  ASSERT_EQ(map.residentPoints(), 3000u);
  EXPECT_TRUE(map.evictIdle(3000000).size() == 1000u);  // the oldest tile: the budget holds again
  EXPECT_EQ(map.residentPoints(), 2000u);
  EXPECT_EQ(map.tilesEvictedForMemory(), 1u);
  EXPECT_EQ(map.residentTiles(), 2u);
  // over budget again, but the other two were used within min_idle_s: they stay
  map.setTime(3200000);
  for (int i = 0; i < 1000; ++i)
    map.addPoint(Eigen::Vector3f(6.01f + 0.05f * (i % 40), 0.05f * (i / 40) + 0.01f, 0.5f), 3);
  EXPECT_TRUE(map.evictIdle(3300000).empty());
  EXPECT_EQ(map.residentPoints(), 3000u);
  // the first tile comes back exactly as it went
  map.setTime(4000000);
  bool created = true;
  const uint32_t id = map.addPoint(tile_a[17].position, 9, &created);
  EXPECT_FALSE(created);
  EXPECT_TRUE(samePoint(map.point(id), tile_a[17]));
  EXPECT_EQ(map.residentPoints(), 4000u);
  // a save settles the tiles on disk a correction made stale: each comes back within the budget
  // (the least recently used resident tiles make room first), and every point is still there
  map.evictIdle(4000000);
  ASSERT_LE(map.residentPoints(), 3000u);
  map.transform([](int64_t, Pose3* T) {
    *T = Pose3::Identity();
    return true;
  });
  // the re-indexing sizes the voxel index for the budget below the load it grows at: 3,000 live
  // points in 4,096 slots (sized for half load it took 8,192: 128 MB instead of 64 near the
  // default 2.5 M budget)
  EXPECT_EQ(map.indexBytes(), 4096u * 16u);
  map.setTime(10000000);
  const size_t coloured = map.colouredCount(), evicted = map.tilesEvictedForMemory();
  map.settleSpilledTiles();
  // 3,000 resident + the stale tile's 1,000: two resident tiles went first (without: a peak of 4,000)
  EXPECT_EQ(map.tilesEvictedForMemory(), evicted + 2);
  EXPECT_LE(map.residentPoints(), 2500u);
  EXPECT_EQ(map.colouredCount(), coloured);
}

// A correction neither brings a tile on disk back nor keeps one in memory: points it moves into a
// tile on disk join that tile there, and the files still hold one point per voxel.
TEST(ColourMapTiles, ACorrectionLeavesTilesOnDisk) {
  ColourMap map(0.05, TileOptions{2.0, 1.0, ""});
  map.setAnchorPose(0, Pose3::Identity());
  map.setAnchorPose(1, Pose3::Identity());
  AccumulationOptions acc;
  // tile x in [0, 2): anchor 0, goes to disk; tile x in [2, 4): anchor 1, stays
  map.setTime(1000000);
  for (int i = 0; i < 20; ++i)
    map.accumulate(map.addPoint(Eigen::Vector3f(0.1f * i + 0.025f, 0.025f, 0.025f), 0),
                   Eigen::Vector3f(0.f, 0.f, 100.f), acc);
  map.setTime(3000000);
  std::vector<uint32_t> ids;
  for (int i = 0; i < 20; ++i) {
    ids.push_back(map.addPoint(Eigen::Vector3f(2.0f + 0.1f * i + 0.025f, 0.025f, 0.025f), 1));
    map.accumulate(ids.back(), Eigen::Vector3f(0.f, 0.f, 200.f), acc);
  }
  map.evictIdle(2500000);
  ASSERT_EQ(map.spilledTiles(), 1u);
  ASSERT_EQ(map.residentPoints(), 20u);
  // anchor 1 moves 1 m back in x: its first 10 points land in the tile on disk, all of them in
  // voxels it holds (x 1.025 .. 1.925, all occupied by anchor 0's points)
  Pose3 moved = Pose3::Identity();
  moved.translation() = Vec3(-1.0, 0.0, 0.0);
  map.setAnchorPose(1, moved);
  map.setTime(3500000);
  map.transform([&](int64_t anchor, Pose3* T) {
    if (anchor != 1) return false;
    *T = moved;
    return true;
  });
  EXPECT_EQ(map.spilledTiles(), 1u);
  EXPECT_EQ(map.residentPoints(), 10u);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(map.lastRemap()[ids[i]] == ColourMap::kGone, i < 10) << i;
  EXPECT_EQ(map.colouredCount(), 40u);
  // the correction was no use of the resident tile: it goes to disk on its own schedule
  EXPECT_EQ(map.evictIdle(4500000).size(), 10u);
  EXPECT_EQ(map.residentPoints(), 0u);
  // the files: one point per voxel, the 10 overlapping voxels merged (colours weighted)
  map.settleSpilledTiles();
  const std::vector<MapPoint> pts = allPoints(map);
  ASSERT_EQ(pts.size(), 30u);
  int merged = 0;
  for (const MapPoint& p : pts) {
    if (p.count == 2) {
      ++merged;
      EXPECT_FLOAT_EQ(p.colour.z(), 150.f);
    }
  }
  EXPECT_EQ(merged, 10);
}

TEST(ColourMapTiles, ACorrectionMovesTilesOnDiskWhenTheyComeBack) {
  ColourMap map(0.05, TileOptions{2.0, 1.0, ""});
  map.setAnchorPose(0, Pose3::Identity());
  map.setAnchorPose(1, Pose3::Identity());
  map.setTime(1000000);
  AccumulationOptions acc;
  for (int i = 0; i < 200; ++i) {
    const uint32_t id = map.addPoint(Eigen::Vector3f(0.1f * i + 0.025f, 0.525f, 0.025f), i < 100 ? 0 : 1);
    map.accumulate(id, Eigen::Vector3f(10.f, 20.f, float(i)), acc);
  }
  map.evictIdle(5000000);
  ASSERT_EQ(map.residentPoints(), 0u);
  Pose3 moved = Pose3::Identity();
  moved.translation() = Vec3(0.0, 0.5, 0.0);  // anchor 1 moves 0.5 m in y
  map.setAnchorPose(1, moved);
  map.transform([&](int64_t anchor, Pose3* T) {
    if (anchor != 1) return false;
    *T = moved;
    return true;
  });
  std::vector<MapPoint> pts = allPoints(map);
  ASSERT_EQ(pts.size(), 200u);
  for (const MapPoint& p : pts) EXPECT_NEAR(p.position.y(), p.anchor == 1 ? 1.025 : 0.525, 1e-6);
  // the files: settled tiles hold the moved points once, in the tiles they now lie in
  map.settleSpilledTiles();
  EXPECT_EQ(map.residentPoints(), 0u);
  pts = allPoints(map);
  ASSERT_EQ(pts.size(), 200u);
  for (const MapPoint& p : pts) EXPECT_NEAR(p.position.y(), p.anchor == 1 ? 1.025 : 0.525, 1e-6);
  EXPECT_EQ(map.colouredCount(), 200u);
  // coming back on a new point: the moved point is found where it now is
  map.setTime(6000000);
  bool created = true;
  const uint32_t id = map.addPoint(Eigen::Vector3f(15.025f, 1.03f, 0.03f), 7, &created);
  EXPECT_FALSE(created);
  EXPECT_EQ(map.point(id).anchor, 1);
  EXPECT_FLOAT_EQ(map.point(id).colour.z(), 150.f);
}

// The cone's shortcuts decide every point as the exact test (an atan2 and an asin) does, also right
// at the bound, at the travel radius, at the centre, and for cones up to and beyond pi.
TEST(ViewCone, TheShortcutsDecideAsTheExactTest) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0), frac(0.0, 1.0);
  int mismatches = 0, inside = 0, outside = 0, at_bound_inside = 0, at_bound_outside = 0;
  const double half_angles[] = {0.0, 1e-7, 0.005, 0.3,         0.785,        1.05,        1.5,  M_PI_2,
                                1.6, 2.5,  3.0,   M_PI - 0.02, M_PI - 0.005, M_PI - 1e-9, M_PI, 4.0};
  const double travels[] = {0.0, 1e-6, 0.2, 0.8, 3.0, 40.0};
  for (const double half_angle : half_angles) {
    for (const double travel : travels) {
      ViewCone cone;
      cone.centre = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
      cone.axis = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized();
      cone.half_angle = half_angle;
      cone.travel = travel;
      cone.prepare();
      // a frame around the axis: points at a chosen angle and range
      const Eigen::Vector3d side = cone.axis.unitOrthogonal();
      auto at = [&](double angle, double r, double roll) {
        const Eigen::Vector3d dir =
            Eigen::AngleAxisd(roll, cone.axis) * (std::cos(angle) * cone.axis + std::sin(angle) * side);
        return Eigen::Vector3d(cone.centre + r * dir);
      };
      auto check = [&](const Eigen::Vector3d& p) {
        const bool exact = cone.containsExactly(p);
        if (cone.contains(p) != exact && ++mismatches <= 5)
          ADD_FAILURE() << "half angle " << half_angle << " travel " << travel << " point " << p.transpose();
        ++(exact ? inside : outside);
        return exact;
      };
      check(cone.centre);
      for (int i = 0; i < 2000; ++i) {
        const double r = travel * 6.0 * frac(rng) + 0.05 * frac(rng);
        check(at(M_PI * frac(rng), r, 2 * M_PI * frac(rng)));
        // on and next to the bound (half_angle + asin(travel / r)), and at the travel radius
        const double r_out = travel + 0.01 + 10.0 * frac(rng);
        const double bound = half_angle + std::asin(std::min(1.0, travel / r_out));
        if (bound < M_PI) {
          for (const double off : {-1e-6, -1e-9, -1e-12, 0.0, 1e-12, 1e-9, 1e-6}) {
            const bool in = check(at(std::clamp(bound + off, 0.0, M_PI), r_out, 2 * M_PI * frac(rng)));
            if (off == -1e-6 && bound > 1e-6) at_bound_inside += in;
            if (off == 1e-6 && bound + 1e-6 < M_PI) at_bound_outside += !in;
          }
        }
        for (const double dr : {-1e-12, 0.0, 1e-12}) check(at(M_PI * frac(rng), travel + dr, 0.0));
      }
    }
  }
  EXPECT_EQ(mismatches, 0);
  // both answers came, also a hair either side of the bound
  EXPECT_GT(inside, 10000);
  EXPECT_GT(outside, 10000);
  EXPECT_GT(at_bound_inside, 1000);
  EXPECT_GT(at_bound_outside, 1000);
}

// Splatting only each cell's nearest centred point leaves the buffer splatting every point does.
TEST(DepthBuffer, SplattingTheNearestPerCellLeavesTheBufferOfEverySplat) {
  DepthBufferOptions o;
  DepthBuffer every(640, 480, 500.0, o), nearest(640, 480, 500.0, o);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 639.0), v(0.0, 479.0), depth(0.2, 30.0);
  std::vector<std::pair<Eigen::Vector2d, double>> points;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector2d px(u(rng), v(rng));
    points.emplace_back(px, depth(rng));
    // crowd cells: more points in the same cell, nearer, farther and at the same depth
    for (const double dz : {-0.05, 0.0, 0.0, 0.3})
      points.emplace_back(px + Eigen::Vector2d(0.4, -0.3), std::max(0.2, points.back().second + dz));
  }
  for (int image = 0; image < 2; ++image) {  // twice: the buffer's working set is reset between images
    every.clear();
    nearest.clear();
    for (const auto& [px, z] : points) every.splat(px, z);
    nearest.splatNearest(points, [](const std::pair<Eigen::Vector2d, double>& p) { return p; });
    for (int y = 0; y < 480; y += 2)
      for (int x = 0; x < 640; x += 2) {
        const Eigen::Vector2d px(x, y);
        ASSERT_EQ(nearest.nearest(px), every.nearest(px)) << x << " " << y;
      }
    points.resize(points.size() / 3);
  }
}

// A batch of points gives the ids and the map of one addPoint each (free slots, tiles, repeats).
TEST(ColourMap, AddPointsMatchesOneAddPointEach) {
  ColourMap one(0.05, TileOptions{2.0, 1.0, ""}), batch(0.05, TileOptions{2.0, 1.0, ""});
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-4.f, 4.f);
  AccumulationOptions acc;
  for (int scan = 0; scan < 6; ++scan) {
    std::vector<Eigen::Vector3f> pts;
    for (int i = 0; i < 4000; ++i) {
      pts.emplace_back(u(rng) + 10.f * float(scan % 3), u(rng), 0.3f * u(rng));  // a region comes back every third
      if (i % 5 == 0) pts.push_back(pts.back());                                 // the same voxel again
    }
    const int64_t utime = 1000000 + scan * 800000;
    one.setTime(utime);
    batch.setTime(utime);
    std::vector<uint32_t> ids_one, ids_batch;
    for (const Eigen::Vector3f& p : pts) ids_one.push_back(one.addPoint(p, scan));
    batch.addPoints(pts, scan, &ids_batch);
    ASSERT_EQ(ids_batch, ids_one);
    for (size_t k = 0; k < ids_one.size(); k += 3) {
      one.accumulate(ids_one[k], Eigen::Vector3f(10, 20, 30), acc);
      batch.accumulate(ids_batch[k], Eigen::Vector3f(10, 20, 30), acc);
    }
    // free slots for the next batch to reuse, and tiles to disk and back
    auto odd = [](uint32_t id) { return id % 2 == 1; };
    EXPECT_EQ(batch.removeUncoloured(odd), one.removeUncoloured(odd));
    EXPECT_EQ(batch.evictIdle(utime), one.evictIdle(utime));
  }
  ASSERT_EQ(batch.size(), one.size());
  for (uint32_t id = 0; id < one.size(); ++id) {
    const MapPoint &a = one.point(id), &b = batch.point(id);
    ASSERT_EQ(a.position, b.position);
    ASSERT_EQ(a.colour, b.colour);
    ASSERT_EQ(a.count, b.count);
    ASSERT_EQ(a.rejected, b.rejected);
    ASSERT_EQ(a.anchor, b.anchor);
  }
  EXPECT_GT(batch.spilledTiles(), 0u);
}
