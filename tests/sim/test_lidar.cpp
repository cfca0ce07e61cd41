// LiDAR: ranges against analytic distances in a box room, per-point times and directions against
// the beam/azimuth schedule, noise and dropout statistics, motion distortion, and the solid-state
// rosette.
#include <gtest/gtest.h>

#include <set>

#include "livo/sim/lidar_scanner.hpp"
#include "sim_test_support.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

constexpr double kDeg = M_PI / 180.0;

// A 10 x 8 x 4 m box room seen from inside.
const Vec3 kRoomMin(-5, -4, 0), kRoomMax(5, 4, 4);

Scene boxRoom() {
  Scene scene;
  TextureOptions t;
  scene.addTexture(t);
  Shape room;
  room.type = ShapeType::kBox;
  room.center = 0.5 * (kRoomMin + kRoomMax);
  room.half_size = 0.5 * (kRoomMax - kRoomMin);
  Material m;
  m.reflectivity = 0.5;
  scene.addShape("room", room, m);
  scene.build();
  return scene;
}

/// Distance from o along unit d to the inside of the room, and the face normal there.
double roomDistance(const Vec3& o, const Vec3& d, Vec3* normal = nullptr) {
  double best = kInfinity;
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0.0) continue;
    const double t = ((d[i] > 0 ? kRoomMax[i] : kRoomMin[i]) - o[i]) / d[i];
    if (t < best) {
      best = t;
      if (normal) *normal = -Vec3::Unit(i) * (d[i] > 0 ? 1.0 : -1.0);
    }
  }
  return best;
}

/// Distance of a world point to the room's surface.
double offSurface(const Vec3& p) {
  const Vec3 a = (p - kRoomMin).cwiseAbs(), b = (kRoomMax - p).cwiseAbs();
  return std::min(a.minCoeff(), b.minCoeff());
}

LidarRig rigFor(const std::string& model) {
  LidarRig rig;
  rig.model = model;
  rig.rate_hz = 10.0;
  rig.min_range = 0.3;
  rig.max_range = 100.0;
  rig.range_noise_std = 0.0;
  rig.dropout_probability = 0.0;
  rig.T_I_L.translation() = Vec3(0.1, -0.05, 0.2);
  rig.T_I_L.linear() = so3::Exp(Vec3(0.02, -0.03, 0.3));
  return rig;
}

Pose3 bodyPose() {
  Pose3 T = Pose3::Identity();
  T.translation() = Vec3(0.7, -0.4, 1.3);
  T.linear() = so3::Exp(Vec3(0.05, 0.04, 0.8));
  return T;
}

double wrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

}  // namespace

TEST(Lidar, RangesMatchAnalyticDistancesInABox) {
  const Scene scene = boxRoom();
  const LidarRig rig = rigFor("VLP-16");
  LidarScanner scanner(rig, {});
  test::ConstantMotion still(bodyPose());
  const LidarSweep sweep = scanner.scan(scene, still, 0.0, 1000, 0.0, Random(1, 3));
  ASSERT_EQ(sweep.size(), 1808u * 16u);  // every beam hits the room
  const Pose3 T_W_L = bodyPose() * rig.T_I_L;
  for (size_t j = 0; j < sweep.size(); ++j) {
    const Vec3 p(sweep.x[j], sweep.y[j], sweep.z[j]);
    const Vec3 d_W = T_W_L.linear() * p.normalized();
    Vec3 n;
    const double expected = roomDistance(T_W_L.translation(), d_W, &n);
    ASSERT_NEAR(p.norm(), expected, 2e-5 * expected) << "point " << j;
    EXPECT_NEAR(sweep.intensity[j], 255.0 * 0.5 * std::abs(n.dot(d_W)), 1e-3);
  }
}

TEST(Lidar, TimesAndDirectionsFollowTheVlp16Schedule) {
  const Scene scene = boxRoom();
  const LidarRig rig = rigFor("VLP-16");
  LidarScanner scanner(rig, {});
  test::ConstantMotion still(bodyPose());
  const LidarSweep sweep = scanner.scan(scene, still, 0.0, 1000, 0.0, Random(1, 3));
  ASSERT_EQ(sweep.num_rings, 16);
  EXPECT_FALSE(sweep.solid_state);
  EXPECT_DOUBLE_EQ(sweep.duration, 0.1);
  const int columns = 1808;  // 0.1 s / 55.296 us firing cycle
  const double column_period = 0.1 / columns;
  for (int c = 0; c < columns; c += 7) {
    for (int id = 0; id < 16; ++id) {  // laser ids in firing order
      const size_t j = static_cast<size_t>(c) * 16 + id;
      const double t = c * column_period + id * 2.304e-6;
      ASSERT_NEAR(sweep.time_offset[j], t, 1e-7);
      // VLP-16: even ids -15, -13, .. -1 deg; odd ids 1, 3, .. 15 deg; rings bottom to top
      const int ring = id % 2 == 0 ? id / 2 : 8 + id / 2;
      ASSERT_EQ(sweep.ring[j], ring);
      const Vec3 p(sweep.x[j], sweep.y[j], sweep.z[j]);
      EXPECT_NEAR(std::asin(p.z() / p.norm()), (-15.0 + 2.0 * ring) * kDeg, 1e-6);
      // clockwise from 180 deg at the sweep start, one turn per sweep
      const double azimuth = M_PI - 2.0 * M_PI * t / 0.1;
      EXPECT_NEAR(wrapAngle(std::atan2(p.y(), p.x()) - azimuth), 0.0, 1e-6);
    }
  }
  for (size_t j = 1; j < sweep.size(); ++j) ASSERT_GT(sweep.time_offset[j], sweep.time_offset[j - 1]);
  EXPECT_LT(sweep.time_offset.back(), 0.1f);
}

TEST(Lidar, BeamTablesOfTheOtherSpinningModels) {
  const Scene scene = boxRoom();
  test::ConstantMotion still(bodyPose());
  struct Case {
    std::string model;
    int beams, columns;
    double min_el, max_el;
  };
  for (const Case& k : {Case{"OS1-16", 16, 1024, -16.6, 16.6}, Case{"OS1-64", 64, 1024, -16.6, 16.6},
                        Case{"HDL-64E", 64, 2083, -24.33, 2.0}}) {
    const LidarRig rig = rigFor(k.model);
    LidarScanner scanner(rig, {});
    const LidarSweep sweep = scanner.scan(scene, still, 0.0, 0, 0.0, Random(1, 3));
    ASSERT_EQ(sweep.num_rings, k.beams) << k.model;
    ASSERT_EQ(scanner.pattern().columns(), k.columns) << k.model;
    ASSERT_EQ(sweep.size(), static_cast<size_t>(k.beams) * k.columns) << k.model;
    double lo = 90, hi = -90;
    std::set<int> rings;
    for (size_t j = 0; j < sweep.size(); ++j) {
      const Vec3 p(sweep.x[j], sweep.y[j], sweep.z[j]);
      const double el = std::asin(p.z() / p.norm()) / kDeg;
      lo = std::min(lo, el), hi = std::max(hi, el);
      rings.insert(sweep.ring[j]);
      const int b = static_cast<int>(j % k.beams), c = static_cast<int>(j / k.beams);
      const double t = scanner.pattern().firingTime(c, b);
      ASSERT_NEAR(sweep.time_offset[j], t, 1e-7);
      double az = M_PI - 2.0 * M_PI * t / 0.1;
      if (k.model == "OS1-64") az += std::vector<double>{3.164, 1.055, -1.055, -3.164}[b % 4] * kDeg;
      ASSERT_NEAR(wrapAngle(std::atan2(p.y(), p.x()) - az), 0.0, 1e-6) << k.model << " point " << j;
    }
    EXPECT_NEAR(lo, k.min_el, 1e-4) << k.model;
    EXPECT_NEAR(hi, k.max_el, 1e-4) << k.model;
    EXPECT_EQ(static_cast<int>(rings.size()), k.beams);
  }
}

TEST(Lidar, RangeNoiseAndDropoutStatistics) {
  const Scene scene = boxRoom();
  LidarRig rig = rigFor("OS1-64");
  rig.range_noise_std = 0.02;
  rig.dropout_probability = 0.1;
  LidarScanner scanner(rig, {});
  test::ConstantMotion still(bodyPose());
  const LidarSweep sweep = scanner.scan(scene, still, 0.0, 0, 0.0, Random(9, 3));
  const Pose3 T_W_L = bodyPose() * rig.T_I_L;
  double sum = 0, sq = 0;
  for (size_t j = 0; j < sweep.size(); ++j) {
    const Vec3 p(sweep.x[j], sweep.y[j], sweep.z[j]);
    const double e = p.norm() - roomDistance(T_W_L.translation(), T_W_L.linear() * p.normalized());
    sum += e, sq += e * e;
  }
  const double n = static_cast<double>(sweep.size());
  EXPECT_NEAR(n / (64.0 * 1024.0), 0.9, 0.006);
  EXPECT_NEAR(sum / n, 0.0, 4 * 0.02 / std::sqrt(n));
  EXPECT_NEAR(std::sqrt(sq / n) / 0.02, 1.0, 0.02);
}

TEST(Lidar, MovingSensorProducesMotionDistortion) {
  const Scene scene = boxRoom();
  const LidarRig rig = rigFor("VLP-16");
  LidarScanner scanner(rig, {});
  // 4 m/s along x and 1.5 rad/s of yaw during the sweep
  test::ConstantMotion moving(bodyPose(), Vec3(4.0, 0.5, 0.0), Vec3(0.0, 0.0, 1.5));
  const double t0 = 0.2;
  const LidarSweep sweep = scanner.scan(scene, moving, t0, 0, t0, Random(1, 3));
  double worst_own = 0, worst_start = 0;
  const Pose3 start = moving.at(t0).T_W_I * rig.T_I_L;
  for (size_t j = 0; j < sweep.size(); ++j) {
    const Vec3 p(sweep.x[j], sweep.y[j], sweep.z[j]);
    const Pose3 own = moving.at(t0 + sweep.time_offset[j]).T_W_I * rig.T_I_L;
    worst_own = std::max(worst_own, offSurface(own * p));
    worst_start = std::max(worst_start, offSurface(start * p));
  }
  EXPECT_LT(worst_own, 1e-4);   // each point is exact at its own firing time
  EXPECT_GT(worst_start, 0.3);  // a single pose for the whole sweep is badly off
}

TEST(Lidar, SolidStateRosetteIsNonRepetitive) {
  const Scene scene = boxRoom();
  const LidarRig rig = rigFor("livox-avia");
  LidarScanner scanner(rig, {});
  test::ConstantMotion still(bodyPose());
  const LidarSweep a = scanner.scan(scene, still, 0.0, 0, 0.0, Random(1, 3, 0));
  const LidarSweep b = scanner.scan(scene, still, 0.1, 100000, 0.1, Random(1, 3, 1));
  ASSERT_TRUE(a.solid_state);
  ASSERT_EQ(a.num_rings, 6);
  ASSERT_EQ(a.size(), 24000u);  // 240k points/s at 10 Hz
  for (size_t j = 0; j < a.size(); ++j) {
    ASSERT_NEAR(a.time_offset[j], static_cast<double>(j / 6) * 25e-6, 1e-8);
    ASSERT_EQ(a.ring[j], static_cast<int>(j % 6));
    const Vec3 p(a.x[j], a.y[j], a.z[j]);
    ASSERT_LT(std::acos(p.x() / p.norm()), (38.6 + 2.1) * kDeg);  // inside the field of view
  }
  // coverage of the field of view in 1-degree cells grows when the next sweep is added
  auto cells = [](const LidarSweep& s, std::set<std::pair<int, int>>* out) {
    for (size_t j = 0; j < s.size(); ++j)
      out->insert({static_cast<int>(std::floor(std::atan2(s.y[j], s.x[j]) / kDeg)),
                   static_cast<int>(std::floor(std::atan2(s.z[j], s.x[j]) / kDeg))});
  };
  std::set<std::pair<int, int>> one, two;
  cells(a, &one);
  two = one;
  cells(b, &two);
  EXPECT_GT(two.size(), one.size() * 11 / 10);
}
