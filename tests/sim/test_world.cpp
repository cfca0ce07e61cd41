// A world that moves and sees through things: a car crossing a static LiDAR's and camera's view
// is where its path says at each beam's and pixel's time; glass returns a LiDAR beam with its
// probability (else the wall behind answers) and tints what the camera sees behind it; vegetation
// returns at depths following the exponential free path of its leaf density.
#include <gtest/gtest.h>

#include <algorithm>

#include "livo/sim/camera_renderer.hpp"
#include "livo/sim/lidar_scanner.hpp"
#include "sim_test_support.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

// A 40 x 40 x 10 m hall seen from inside, the sensors at its centre, 1.2 m up.
const Vec3 kHallMin(-20, -20, 0), kHallMax(20, 20, 10);
const Vec3 kSensor(0.0, 0.0, 1.2);

double hallDistance(const Vec3& o, const Vec3& d) {
  double best = kInfinity;
  for (int i = 0; i < 3; ++i)
    if (d[i] != 0.0) best = std::min(best, ((d[i] > 0 ? kHallMax[i] : kHallMin[i]) - o[i]) / d[i]);
  return best;
}

TextureOptions uniformTexture(double level) {
  TextureOptions t;
  t.pattern = TexturePattern::kUniform;
  t.color_a = Eigen::Vector3d::Constant(level);
  t.grain = 0.0;
  t.variation = 0.0;
  return t;
}

/// The hall (texture 0, grey level 0.2) and the textures 1 (0.9) and 2 (0.5) for what is added.
Scene hall() {
  Scene scene;
  scene.lighting.ambient = 1.0;
  scene.lighting.diffuse = 0.0;
  scene.addTexture(uniformTexture(0.2));
  scene.addTexture(uniformTexture(0.9));
  scene.addTexture(uniformTexture(0.5));
  Shape box;
  box.type = ShapeType::kBox;
  box.center = 0.5 * (kHallMin + kHallMax);
  box.half_size = 0.5 * (kHallMax - kHallMin);
  scene.addShape("hall", box, Material{});
  return scene;
}

LidarRig staticLidar() {
  LidarRig rig;
  rig.model = "VLP-16";
  rig.rate_hz = 10.0;
  rig.min_range = 0.3;
  rig.max_range = 100.0;
  rig.range_noise_std = 0.0;
  rig.dropout_probability = 0.0;
  return rig;  // T_I_L = identity
}

Pose3 at(const Vec3& p) {
  Pose3 T = Pose3::Identity();
  T.translation() = p;
  return T;
}

// The car: 4.5 x 1.8 x 1.5 m, driving y = 6 from x = -12 to x = 12 and back at 8 m/s.
constexpr double kCarSpeed = 8.0, kCarY = 6.0;
const Vec3 kCarHalf(2.25, 0.9, 0.75);

/// The car as the path says at time t < 3 s (the first leg): centre x = -12 + 8 t, heading +x.
Shape carAt(double t) {
  Shape s;
  s.type = ShapeType::kBox;
  s.center = Vec3(-12.0 + kCarSpeed * t, kCarY, kCarHalf.z());
  s.half_size = kCarHalf;
  return s;
}

void addCar(Scene* scene) {
  Shape body;
  body.type = ShapeType::kBox;
  body.half_size = kCarHalf;
  MoverPath path;
  path.waypoints = {Vec3(-12, kCarY, 0), Vec3(12, kCarY, 0)};
  path.speed = kCarSpeed;
  Material m;
  m.texture = 1;
  m.reflectivity = 0.8;
  scene->addMover("car", MovingObject(body, path), m);
}

}  // namespace

TEST(MovingObject, WalksItsLoopAtItsSpeedWithItsPhase) {
  Shape body;
  body.type = ShapeType::kCylinder;
  body.half_size = Vec3(0.25, 0.25, 0.875);
  MoverPath path;
  path.waypoints = {Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(4, 3, 0)};  // a 3-4-5 triangle, 12 m round
  path.speed = 1.5;
  path.phase = 0.25;  // 3 m along at t = 0
  const MovingObject walker(body, path);
  EXPECT_DOUBLE_EQ(walker.loopLength(), 12.0);
  double heading;
  EXPECT_LT((walker.groundPointAt(0.0, &heading) - Vec3(3, 0, 0)).norm(), 1e-12);
  EXPECT_NEAR(heading, 0.0, 1e-12);
  EXPECT_LT((walker.groundPointAt(2.0, &heading) - Vec3(4, 2, 0)).norm(), 1e-12);  // 6 m along
  EXPECT_NEAR(heading, M_PI / 2, 1e-12);
  EXPECT_LT((walker.groundPointAt(5.0, &heading) - Vec3(1.2, 0.9, 0)).norm(), 1e-12);  // 3.5 m down the hypotenuse
  EXPECT_NEAR(heading, std::atan2(-3.0, -4.0), 1e-12);
  EXPECT_LT((walker.groundPointAt(8.0) - walker.groundPointAt(0.0)).norm(), 1e-12);  // one lap
  const Shape s = walker.shapeAt(2.0);
  EXPECT_LT((s.center - Vec3(4, 2, 0.875)).norm(), 1e-12);  // stands on the ground
  EXPECT_THROW(MovingObject(body, MoverPath{{Vec3(1, 1, 0)}, 1.0, 0.0}), std::invalid_argument);
}

TEST(MovingObject, ACarCrossingAStaticLidarIsWhereItsPathSaysAtTheBeamTimes) {
  Scene scene = hall();
  addCar(&scene);
  scene.build();
  LidarScanner scanner(staticLidar(), {});
  test::ConstantMotion still(at(kSensor));
  for (double t0 : {0.6, 1.2, 1.8}) {
    const LidarSweep sweep = scanner.scan(scene, still, t0, 0, t0, Random(1, 3, static_cast<uint64_t>(t0 * 10)));
    ASSERT_EQ(sweep.size(), 1808u * 16u);
    int on_car = 0;
    double car_x = 0.0, expected_x = 0.0;
    for (size_t j = 0; j < sweep.size(); ++j) {
      const Vec3 q(sweep.x[j], sweep.y[j], sweep.z[j]);
      Ray ray;
      ray.origin = kSensor;
      ray.direction = q.normalized();
      const double t = t0 + sweep.time_offset[j];
      double expected = hallDistance(kSensor, ray.direction), t_car;
      int face;
      const bool car = intersectShape(carAt(t), ray, 1e-6, expected, &t_car, &face);
      if (car) expected = t_car;
      ASSERT_NEAR(q.norm(), expected, 1e-4) << "sweep at " << t0 << " point " << j;
      if (car) {
        ++on_car;
        car_x += kSensor.x() + q.x();
        expected_x += carAt(t).center.x();
      }
    }
    // the car is seen, around where the path puts it (its near side and ends are what is seen)
    ASSERT_GT(on_car, 100) << t0;
    EXPECT_NEAR(car_x / on_car, expected_x / on_car, 1.5) << t0;
  }
}

TEST(MovingObject, TheCameraSeesTheCarAtThePixelsOfItsPathAtTheImageTime) {
  Scene scene = hall();
  addCar(&scene);
  scene.build();
  CameraRig rig;
  rig.width = 160;
  rig.height = 120;
  rig.fx = rig.fy = 80.0;
  rig.cx = 79.5;
  rig.cy = 59.5;
  rig.distortion = {0, 0, 0, 0};
  CameraEffects e;
  e.exposure_variation = 0.0;
  e.noise_std = 0.0;
  e.vignetting = 0.0;
  CameraRenderer renderer(rig, e);
  // camera z along world +y (towards the car), x along +x, y down
  Pose3 T = at(kSensor);
  T.linear() << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  test::ConstantMotion still(T);
  for (double t : {1.2, 1.5}) {
    const CameraImage img = renderer.render(scene, still, t, 0, Random(1, 4));
    int car_pixels = 0;
    for (int v = 0; v < rig.height; ++v)
      for (int u = 0; u < rig.width; ++u) {
        Ray ray;
        ray.origin = kSensor;
        ray.direction = T.linear() * renderer.camera().pixelRay(Eigen::Vector2d(u, v)).cast<float>().cast<double>();
        double t_car;
        int face;
        const bool car = intersectShape(carAt(t), ray, 1e-6, hallDistance(ray.origin, ray.direction), &t_car, &face);
        car_pixels += car;
        ASSERT_NEAR(img.data[static_cast<size_t>(v) * rig.width + u], car ? 230 : 51, 1) << "pixel " << u << ", " << v;
      }
    EXPECT_GT(car_pixels, 500) << t;
  }
}

TEST(Glass, ALidarBeamReturnsFromTheGlassWithItsProbabilityElseFromBehind) {
  Scene scene = hall();
  Shape pane;  // a 1 cm pane at x = 5, across the hall
  pane.type = ShapeType::kBox;
  pane.center = Vec3(5.0, 0.0, 5.0);
  pane.half_size = Vec3(0.005, 20.0, 5.0);
  Material glass;
  glass.texture = 2;
  glass.kind = MaterialKind::kGlass;
  glass.glass_return_probability = 0.3;
  scene.addShape("pane", pane, glass);
  scene.build();
  LidarScanner scanner(staticLidar(), {});
  test::ConstantMotion still(at(kSensor));
  int crossing = 0, from_glass = 0;
  for (int k = 0; k < 3; ++k) {
    const LidarSweep sweep = scanner.scan(scene, still, 0.1 * k, 0, 0.1 * k, Random(2, 3, k));
    ASSERT_EQ(sweep.size(), 1808u * 16u);
    for (size_t j = 0; j < sweep.size(); ++j) {
      const Vec3 q(sweep.x[j], sweep.y[j], sweep.z[j]);
      const Vec3 d = q.normalized();
      const double behind = hallDistance(kSensor, d);
      if (!(d.x() > 0.0 && kSensor.x() + behind * d.x() > 4.995)) {  // does not reach the pane
        ASSERT_NEAR(q.norm(), behind, 1e-4);
        continue;
      }
      ++crossing;
      const double at_glass = (4.995 - kSensor.x()) / d.x();
      if (std::abs(q.norm() - at_glass) < 1e-4)
        ++from_glass;
      else
        ASSERT_NEAR(q.norm(), behind, 1e-4) << "neither the glass nor the wall behind";
    }
  }
  ASSERT_GT(crossing, 10000);
  const double p = 0.3, sigma = std::sqrt(p * (1 - p) / crossing);
  EXPECT_NEAR(static_cast<double>(from_glass) / crossing, p, 4 * sigma);
}

TEST(Glass, TheCameraSeesThroughItTintedByEachSurface) {
  Scene scene = hall();
  Shape pane;  // a pane 2 m in front of the camera, filling its view
  pane.type = ShapeType::kBox;
  pane.center = Vec3(0.0, 2.0, 5.0);
  pane.half_size = Vec3(20.0, 0.005, 5.0);
  Material glass;
  glass.texture = 1;  // 0.9: a bright reflection
  glass.kind = MaterialKind::kGlass;
  glass.glass_transmission = 0.8;
  scene.addShape("pane", pane, glass);
  scene.build();
  CameraRig rig;
  rig.width = 64;
  rig.height = 48;
  rig.fx = rig.fy = 40.0;
  rig.cx = 31.5;
  rig.cy = 23.5;
  CameraEffects e;
  e.exposure_variation = 0.0;
  e.noise_std = 0.0;
  e.vignetting = 0.0;
  Pose3 T = at(kSensor);
  T.linear() << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  test::ConstantMotion still(T);
  const CameraImage img = CameraRenderer(rig, e).render(scene, still, 0.0, 0, Random(1, 4));
  // two surfaces: (1 - T) g + T (1 - T) g + T^2 wall
  const double T2 = 0.8 * 0.8, g = 0.9, wall = 0.2;
  const double expected = 255.0 * ((1 - 0.8) * g + 0.8 * (1 - 0.8) * g + T2 * wall);
  for (uint8_t v : img.data) ASSERT_NEAR(v, expected, 0.5 + 1e-3);
}

TEST(Vegetation, LidarReturnDepthsFollowTheExponentialFreePath) {
  Scene scene = hall();
  // a crown slab 3 m deep (x in [3, 6]) across the hall, 2 leaves' extinction per 2.5 m
  Shape crown;
  crown.type = ShapeType::kBox;
  crown.center = Vec3(4.5, 0.0, 5.0);
  crown.half_size = Vec3(1.5, 20.0, 5.0);
  Material leaves;
  leaves.texture = 2;
  leaves.kind = MaterialKind::kVegetation;
  leaves.leaf_density = 0.8;  // free path 1.25 m
  scene.addShape("crown", crown, leaves);
  scene.build();
  LidarScanner scanner(staticLidar(), {});
  test::ConstantMotion still(at(kSensor));
  double expected_returns = 0.0, variance = 0.0;
  int returns = 0;
  std::vector<double> cdf;  // conditional CDF of each return's depth given it is inside the crown
  for (int k = 0; k < 3; ++k) {
    const LidarSweep sweep = scanner.scan(scene, still, 0.1 * k, 0, 0.1 * k, Random(3, 3, k));
    ASSERT_EQ(sweep.size(), 1808u * 16u);
    for (size_t j = 0; j < sweep.size(); ++j) {
      const Vec3 q(sweep.x[j], sweep.y[j], sweep.z[j]);
      const Vec3 d = q.normalized();
      const double behind = hallDistance(kSensor, d);
      if (!(d.x() > 0.0 && kSensor.x() + behind * d.x() > 3.0)) continue;  // misses the crown
      const double t_in = (3.0 - kSensor.x()) / d.x(), t_out = std::min((6.0 - kSensor.x()) / d.x(), behind);
      const double p_return = 1.0 - std::exp(-0.8 * (t_out - t_in));
      expected_returns += p_return;
      variance += p_return * (1.0 - p_return);
      const double r = q.norm();
      if (r < t_out - 1e-6) {
        ASSERT_GT(r, t_in);
        ++returns;
        cdf.push_back((1.0 - std::exp(-0.8 * (r - t_in))) / p_return);
      } else {
        ASSERT_NEAR(r, behind, 1e-4);  // passed through to the wall
      }
    }
  }
  ASSERT_GT(returns, 5000);
  EXPECT_NEAR(returns, expected_returns, 4.0 * std::sqrt(variance));
  // the conditional CDF values are uniform: Kolmogorov-Smirnov at the 1 % level
  std::sort(cdf.begin(), cdf.end());
  double ks = 0.0;
  const double n = static_cast<double>(cdf.size());
  for (size_t i = 0; i < cdf.size(); ++i) ks = std::max({ks, std::abs(cdf[i] - i / n), std::abs(cdf[i] - (i + 1) / n)});
  EXPECT_LT(ks, 1.63 / std::sqrt(n));
}

TEST(Vegetation, TheCameraSeesLeavesAtTheSameDepthDraw) {
  Scene scene = hall();
  Shape crown;
  crown.type = ShapeType::kCylinder;
  crown.center = Vec3(0.0, 5.0, 1.2);
  crown.half_size = Vec3(2.0, 2.0, 2.0);
  Material leaves;
  leaves.texture = 1;
  leaves.kind = MaterialKind::kVegetation;
  leaves.leaf_density = 1.0;
  const int object = scene.addShape("crown", crown, leaves);
  scene.build();
  // the same key gives the same depth; over many keys the crown is sometimes seen through
  Ray ray;
  ray.origin = kSensor;
  ray.direction = Vec3(0, 1, 0);
  int through = 0;
  double mean_depth = 0.0;
  int n_in = 0;
  for (uint64_t key = 1; key <= 4000; ++key) {
    const RayHit a = scene.cast(ray, CastContext::camera(0.0, key)), b = scene.cast(ray, CastContext::camera(0.0, key));
    ASSERT_EQ(a.t, b.t);
    if (a.object != object) {
      ++through;
      continue;
    }
    mean_depth += a.t - 3.0;
    ++n_in;
  }
  // 4 m of leaves at 1/m: exp(-4) pass; the depth of the others has the truncated exponential mean
  const double p = std::exp(-4.0), sigma = std::sqrt(p * (1 - p) / 4000);
  EXPECT_NEAR(through / 4000.0, p, 4 * sigma);
  const double truncated_mean = 1.0 - 4.0 * p / (1.0 - p);
  EXPECT_NEAR(mean_depth / n_in, truncated_mean, 4 * 1.0 / std::sqrt(n_in));
}
