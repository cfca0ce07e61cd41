// Graded ground (terrain.hpp) and the car on it: the ground's gradient and Hessian are the
// derivatives of its height; the car pitches with a ramp's grade and rolls with a deck's camber,
// its wheels stay on the ground, its position, velocity, acceleration, attitude, rate and angular
// acceleration are derivatives of each other; the rendered surface is where h says.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "livo/sim/car_trajectory.hpp"
#include "livo/sim/scene_config.hpp"
#include "livo/sim/simulation_setup.hpp"
#include "livo/sim/terrain.hpp"
#include "sim_test_support.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

constexpr double kGrade = 0.05, kCamber = 0.02, kWheelbase = 2.7, kTrack = 1.1, kHeight = 1.45, kSpeed = 5.0;

/// 5 % up from x = 50 to 100 m (2.5 m), 20 m vertical curves at both ends.
GradeProfile ramp() {
  GradeProfile p;
  p.stations = {50.0, 100.0};
  p.heights = {0.0, 2.5};
  p.curve_length = 20.0;
  return p;
}

/// A deck 10 m wide along x crowned on y = 0, 2 % to each side, 1 m rounding, flat beyond.
GradeProfile crown() {
  GradeProfile p;
  p.direction_deg = 90.0;
  p.stations = {-5.0, 0.0, 5.0};
  p.heights = {-5.0 * kCamber, 0.0, -5.0 * kCamber};
  p.curve_length = 1.0;
  return p;
}

std::shared_ptr<const Terrain> terrain(std::vector<GradeProfile> profiles, std::vector<ReliefWave> relief = {}) {
  TerrainOptions o;
  o.profiles = std::move(profiles);
  o.relief = std::move(relief);
  return std::make_shared<const Terrain>(o);
}

/// East along y = -2.2 (the right lane) from x = -100 to 300 m, back along y = +2.2.
const std::vector<Vec3> kLoop = {
    {-100, -2.2, kHeight}, {300, -2.2, kHeight}, {300, 2.2, kHeight}, {-100, 2.2, kHeight}};

CarTrajectory car(std::shared_ptr<const Terrain> ground, double shake, const Pose3& T_I_B = Pose3::Identity()) {
  CarTrajectoryOptions o;
  o.start_still_s = 0.5;
  o.ramp_s = 2.0;
  o.shake = carShake(shake);
  o.T_I_B = T_I_B;
  o.ground = std::move(ground);
  o.wheelbase = kWheelbase;
  o.track_width = kTrack;
  return CarTrajectory(std::make_unique<BSplineLoopPath>(kLoop, kSpeed, 4.0), o);
}

/// Time at which the rear axle of car() passes x on the eastward straight (full speed from 2.5 s,
/// path time s = t - 1.5).
double timeAtX(double x) {
  static const BSplineLoopPath path(kLoop, kSpeed, 4.0);
  double lo = 0.0, hi = 395.0 / kSpeed;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (path.at(mid).p.x() < x ? lo : hi) = mid;
  }
  return 1.5 + 0.5 * (lo + hi);
}

/// Nose-up pitch and roll of the car frame (R = Rz(yaw) Ry(-pitch) Rx(roll)).
double pitchOf(const Mat3& R) { return std::asin(R(2, 0)); }
double rollOf(const Mat3& R) { return std::atan2(R(2, 1), R(2, 2)); }

/// The wheels' contact points: the car frame's (0 or wheelbase, +-track/2, -clearance).
std::vector<Vec3> contacts(const CarFrame& f, double clearance) {
  std::vector<Vec3> out;
  for (double ahead : {0.0, kWheelbase})
    for (double left : {0.5 * kTrack, -0.5 * kTrack}) out.push_back(f.p + f.R * Vec3(ahead, left, -clearance));
  return out;
}

double worstContactError(const CarTrajectory& c, const Terrain& ground, double x0, double x1) {
  double worst = 0.0;
  for (double x = x0; x <= x1; x += 0.25)
    for (const Vec3& p : contacts(c.frame(timeAtX(x)), kHeight))
      worst = std::max(worst, std::abs(p.z() - ground.height(p.x(), p.y())));
  return worst;
}

}  // namespace

TEST(Terrain, GradientAndHessianAreTheHeightsDerivatives) {
  const auto ground = terrain({ramp(), crown()}, {{0.8, 120.0, 30.0, 20.0}, {0.1, 35.0, -70.0, 0.0}});
  const double e = 1e-4;
  double worst_gradient = 0.0, worst_hessian = 0.0;
  for (double x = -20.0; x < 130.0; x += 3.7) {
    for (double y = -7.0; y < 7.0; y += 0.9) {
      const GroundJet g = ground->at(x, y);
      const Vec2 fd((ground->height(x + e, y) - ground->height(x - e, y)) / (2 * e),
                    (ground->height(x, y + e) - ground->height(x, y - e)) / (2 * e));
      worst_gradient = std::max(worst_gradient, (g.gradient - fd).norm());
      Eigen::Matrix2d fh;
      fh.col(0) = (ground->at(x + e, y).gradient - ground->at(x - e, y).gradient) / (2 * e);
      fh.col(1) = (ground->at(x, y + e).gradient - ground->at(x, y - e).gradient) / (2 * e);
      worst_hessian = std::max(worst_hessian, (g.hessian - fh).norm());
    }
  }
  EXPECT_LT(worst_gradient, 1e-7);
  EXPECT_LT(worst_hessian, 1e-6);
  // the profile: flat, curve, 5 % grade, curve, flat 2.5 m higher
  const auto r = terrain({ramp()});
  EXPECT_EQ(r->height(39.0, 3.0), 0.0);
  EXPECT_NEAR(r->height(50.0, 0.0), 20.0 * kGrade / 8.0, 1e-12);  // the curve's middle ordinate, A L / 8
  EXPECT_NEAR(r->at(75.0, 0.0).gradient.x(), kGrade, 1e-15);
  EXPECT_NEAR(r->height(75.0, 0.0), 1.25, 1e-12);
  EXPECT_NEAR(r->at(45.0, 0.0).hessian(0, 0), kGrade / 20.0, 1e-15);
  EXPECT_NEAR(r->at(105.0, 0.0).hessian(0, 0), -kGrade / 20.0, 1e-15);
  EXPECT_EQ(r->height(111.0, 0.0), 2.5);
  EXPECT_NEAR(r->maxGrade(), kGrade, 1e-15);
  EXPECT_NEAR(r->maxCurvature(), kGrade / 20.0, 1e-15);
  EXPECT_THROW(Terrain({0.0, {GradeProfile{0.0, Vec2::Zero(), {0.0, 10.0}, {0.0, 1.0}, 20.0}}, {}}),
               std::invalid_argument);
}

/// The error names what is wrong: stations out of order are not "too close", NaN is refused.
TEST(Terrain, RefusesStationsOutOfOrderAndNonFiniteNumbers) {
  const auto message = [](const TerrainOptions& o) {
    try {
      Terrain t(o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message({0.0, {GradeProfile{0.0, Vec2::Zero(), {100.0, 0.0}, {0.0, 1.0}, 20.0}}, {}}).find("must increase"),
            std::string::npos);
  EXPECT_NE(message({0.0, {GradeProfile{0.0, Vec2::Zero(), {0.0, 100.0}, {0.0, NAN}, 20.0}}, {}}).find("non-finite"),
            std::string::npos);
  EXPECT_NE(message({0.0, {}, {ReliefWave{NAN, 100.0, 0.0, 0.0}}}).find("finite"), std::string::npos);
  EXPECT_NE(message({NAN, {}, {}}).find("base"), std::string::npos);
  EXPECT_EQ(message({0.0, {ramp()}, {ReliefWave{0.1, 50.0, 30.0, 10.0}}}), "accepted");
}

TEST(CarOnTerrain, PitchesWithAFivePercentRampAndClimbsIt) {
  const auto ground = terrain({ramp()});
  const CarTrajectory c = car(ground, 0.0);
  double worst_flat = 0.0, worst_ramp = 0.0;
  for (double x = -60.0; x <= 40.0 - kWheelbase; x += 0.5)
    worst_flat = std::max(worst_flat, std::abs(pitchOf(c.frame(timeAtX(x)).R)));
  for (double x = 60.0; x <= 90.0 - kWheelbase; x += 0.5)
    worst_ramp = std::max(worst_ramp, std::abs(pitchOf(c.frame(timeAtX(x)).R) - std::atan(kGrade)));
  EXPECT_LT(worst_flat, 1e-12);
  EXPECT_LT(worst_ramp, 1e-6);
  // rising over the vertical curves in between, never beyond the grade
  double last = 0.0;
  for (double x = 38.0; x <= 112.0; x += 0.25) {
    const double p = pitchOf(c.frame(timeAtX(x)).R);
    if (x < 75.0) {
      EXPECT_GE(p, last - 1e-12) << "x = " << x;
    }
    EXPECT_LE(p, std::atan(kGrade) + 1e-12);
    last = p;
  }
  const double climbed = c.at(timeAtX(130.0)).T_W_I.translation().z() - c.at(timeAtX(20.0)).T_W_I.translation().z();
  EXPECT_NEAR(climbed, 2.5, 1e-9);
  EXPECT_NEAR(c.at(timeAtX(20.0)).T_W_I.translation().z(), kHeight, 1e-12);
}

TEST(CarOnTerrain, RollsWithTheDeckCamber) {
  // the right lane of a crowned deck: the left wheels (nearer the crown) 2 % higher; on the ramp
  // tan(roll) = 0.02 cos(pitch)
  const auto ground = terrain({ramp(), crown()});
  const CarTrajectory c = car(ground, 0.0);
  for (double x = -60.0; x <= 37.0; x += 0.5) {
    const Mat3 R = c.frame(timeAtX(x)).R;
    ASSERT_NEAR(rollOf(R), std::atan(kCamber), 1e-12) << "x = " << x;
    ASSERT_NEAR(pitchOf(R), 0.0, 1e-12) << "x = " << x;
  }
  for (double x = 60.0; x <= 87.0; x += 0.5) {
    const CarFrame f = c.frame(timeAtX(x));
    ASSERT_NEAR(rollOf(f.R), std::atan(kCamber * std::cos(std::atan(kGrade))), 1e-12) << "x = " << x;
    ASSERT_NEAR(pitchOf(f.R), std::atan(kGrade), 1e-12) << "x = " << x;
    // the rear axle rolls along the car's x axis on the inclined, cambered plane (no side slip)
    const Vec3 v_B = f.R.transpose() * f.v;
    ASSERT_LT(std::abs(v_B.y()) + std::abs(v_B.z()), 1e-9) << "x = " << x;
    ASSERT_NEAR(v_B.x(), kSpeed / std::cos(std::atan(kGrade)), 1e-9) << "x = " << x;  // speed is horizontal
  }
}

TEST(CarOnTerrain, WheelsStayOnTheGround) {
  const auto ground = terrain({ramp(), crown()});
  const CarTrajectory c = car(ground, 0.0);
  // exact where the ground under the car is a plane: the flat, the grade, the camber
  EXPECT_LT(worstContactError(c, *ground, -60.0, 40.0 - kWheelbase), 1e-9);
  EXPECT_LT(worstContactError(c, *ground, 60.0, 90.0 - kWheelbase), 1e-9);
  EXPECT_LT(worstContactError(c, *ground, 110.0, 250.0), 1e-9);
  // a rigid car spanning a vertical curve touches it to within its foreshortening
  const double on_curves = worstContactError(c, *ground, 30.0, 112.0);
  RecordProperty("contact_error_on_vertical_curves_m", std::to_string(on_curves));
  std::printf("worst contact error on the 20 m vertical curves: %.3g m\n", on_curves);
  EXPECT_LT(on_curves, 1e-4);
}

TEST(CarOnTerrain, SpecificForceOnAConstantGradeHasGravityAlongTheCar) {
  const auto ground = terrain({ramp(), crown()});
  const CarTrajectory c = car(ground, 0.0);
  const double g = 9.81, pitch = std::atan(kGrade), roll = std::atan(kCamber * std::cos(pitch));
  for (double x = 60.0; x <= 87.0; x += 1.0) {
    const BodyState s = c.at(timeAtX(x));
    ASSERT_LT(s.acceleration.norm(), 1e-9);
    const Vec3 f = specificForce(s, g);
    ASSERT_NEAR(f.x(), g * std::sin(pitch), 1e-9) << "x = " << x;
    ASSERT_NEAR(f.y(), g * std::cos(pitch) * std::sin(roll), 1e-9) << "x = " << x;
    ASSERT_NEAR(f.z(), g * std::cos(pitch) * std::cos(roll), 1e-9) << "x = " << x;
  }
}

TEST(CarOnTerrain, MotionIsConsistentWithItsNumericDerivatives) {
  // ramp, camber and an oblique swell under a shaking car with a lever arm, on the straight, the
  // vertical curves and through the turn at x = 300 m
  const auto ground = terrain({ramp(), crown()}, {{0.6, 90.0, 35.0, 10.0}});
  Pose3 T_I_B = Pose3::Identity();
  T_I_B.linear() = so3::Exp(Vec3(0.01, -0.02, 0.03));
  T_I_B.translation() = Vec3(-1.2, 0.05, -1.15);
  const CarTrajectory c = car(ground, 1.0, T_I_B);
  const double h = 1e-4;
  double worst_v = 0.0, worst_a = 0.0, worst_w = 0.0, worst_dw = 0.0;
  int checked = 0;
  for (double t : {timeAtX(-20.0) + 0.013, timeAtX(45.0) + 0.017, timeAtX(52.0) + 0.011, timeAtX(73.0) + 0.019,
                   timeAtX(104.0) + 0.007, timeAtX(280.0) + 0.021, timeAtX(285.0) + 3.0, timeAtX(285.0) + 4.6, 2.1}) {
    const BodyState s = c.at(t), s0 = c.at(t - h), s1 = c.at(t + h);
    const Vec3 v_fd = (s1.T_W_I.translation() - s0.T_W_I.translation()) / (2 * h);
    const Vec3 a_fd = (s1.velocity - s0.velocity) / (2 * h);
    const Vec3 w_fd = so3::Log(s0.T_W_I.linear().transpose() * s1.T_W_I.linear()) / (2 * h);
    worst_v = std::max(worst_v, (s.velocity - v_fd).norm());
    worst_a = std::max(worst_a, (s.acceleration - a_fd).norm());
    worst_w = std::max(worst_w, (s.angular_velocity - w_fd).norm());
    // the car frame's angular acceleration: hat(dw) = dR^T dR + R^T ddR (skew part)
    const CarFrame f = c.frame(t), f0 = c.frame(t - h), f1 = c.frame(t + h);
    const auto omega = [](const CarFrame& x) {
      const Mat3 A = x.R.transpose() * x.dR;
      return so3::vee(0.5 * (A - A.transpose()));
    };
    const Mat3 B = f.dR.transpose() * f.dR + f.R.transpose() * f.ddR;
    const Vec3 dw = so3::vee(0.5 * (B - B.transpose()));
    worst_dw = std::max(worst_dw, (dw - (omega(f1) - omega(f0)) / (2 * h)).norm());
    // and the frame's own position derivatives
    worst_v = std::max(worst_v, (f.v - (f1.p - f0.p) / (2 * h)).norm());
    worst_a = std::max(worst_a, (f.a - (f1.v - f0.v) / (2 * h)).norm());
    ++checked;
  }
  std::printf(
      "worst |analytic - numeric|: velocity %.2g m/s, acceleration %.2g m/s^2, rate %.2g rad/s, "
      "angular acceleration %.2g rad/s^2 (%d times, h = %g s)\n",
      worst_v, worst_a, worst_w, worst_dw, checked, h);
  EXPECT_LT(worst_v, 1e-6);
  EXPECT_LT(worst_a, 1e-5);
  EXPECT_LT(worst_w, 1e-6);
  EXPECT_LT(worst_dw, 1e-5);
}

TEST(CarOnTerrain, LevelGroundGivesTheLevelCar) {
  // a terrain with nothing on it is the plane z = 0: the same motion as without one
  const CarTrajectory level = car(nullptr, 1.0), flat = car(terrain({}), 1.0);
  for (double t = 0.0; t < 120.0; t += 0.37) {
    const BodyState a = level.at(t), b = flat.at(t);
    ASSERT_LT((a.T_W_I.translation() - b.T_W_I.translation()).norm(), 1e-9) << "t = " << t;
    ASSERT_LT((a.T_W_I.linear() - b.T_W_I.linear()).norm(), 1e-12) << "t = " << t;
    ASSERT_LT((a.velocity - b.velocity).norm(), 1e-9) << "t = " << t;
    ASSERT_LT((a.acceleration - b.acceleration).norm(), 1e-9) << "t = " << t;
    ASSERT_LT((a.angular_velocity - b.angular_velocity).norm(), 1e-12) << "t = " << t;
  }
}

namespace {

const char* kTerrainScene = R"(
textures:
  asphalt: {pattern: noise, scale: 1.0, color: [0.4, 0.4, 0.4], octaves: 3}
terrain:
  profiles:
    ramp: {stations: [50, 100], heights: [0, 2.5], curve_length: 20}
    crown: {direction_deg: 90, stations: [-5, 0, 5], heights: [-0.1, 0, -0.1], curve_length: 1}
  relief:
    swell: {amplitude: 0.6, wavelength: 90, direction_deg: 35, phase_deg: 10}
  surface: {center: [60, 0], size: [160, 16], resolution: 0.25, texture: asphalt, reflectivity: 0.2}
objects:
  post: {type: cylinder, center: [0, 7, 1], radius: 0.1, height: 2, texture: asphalt}
)";

}  // namespace

TEST(TerrainScene, RaysHitTheRenderedGroundWhereHSaysIt) {
  const auto scene = readScene(Config::fromString(kTerrainScene, "terrain_scene.yaml"));
  ASSERT_TRUE(scene->terrain);
  const Terrain& ground = *scene->terrain;
  // the triangles' bound: max curvature x cell^2 / 4
  const double bound = ground.maxCurvature() * 0.25 * 0.25 / 4.0;
  double worst_down = 0.0, worst_lidar = 0.0;
  int hits = 0;
  for (double x = -10.0; x < 130.0; x += 1.37)
    for (double y = -7.0; y < 7.0; y += 0.53) {
      const RayHit hit = scene->cast(Ray{Vec3(x, y, 20.0), Vec3(0, 0, -1)});
      ASSERT_TRUE(hit.valid());
      worst_down = std::max(worst_down, std::abs(20.0 - hit.t - ground.height(x, y)));
    }
  // a VLP-16's lower beams (-15 .. -1 deg) from 1.65 m over the ground, all round, along the road
  for (double x = 0.0; x < 120.0; x += 10.0) {
    const Vec3 origin(x, -2.2, ground.height(x, -2.2) + 1.65);
    for (double elevation = -15.0; elevation <= -1.0; elevation += 2.0)
      for (double azimuth = 0.0; azimuth < 360.0; azimuth += 0.7) {
        const double e = elevation * M_PI / 180.0, a = azimuth * M_PI / 180.0;
        const Ray ray{origin, Vec3(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e))};
        const RayHit hit = scene->cast(ray);
        if (!hit.valid() || scene->objectName(hit.object) != "terrain") continue;
        const Vec3 p = ray.origin + hit.t * ray.direction;
        worst_lidar = std::max(worst_lidar, std::abs(p.z() - ground.height(p.x(), p.y())));
        ++hits;
      }
  }
  std::printf("rendered terrain against h: straight down %.3g m, LiDAR beams %.3g m over %d hits (bound %.3g m)\n",
              worst_down, worst_lidar, hits, bound);
  EXPECT_GT(hits, 10000);
  EXPECT_LT(worst_down, bound + 1e-9);
  EXPECT_LT(worst_lidar, bound + 1e-9);
  EXPECT_LT(bound, 1e-3);
}

TEST(TerrainScene, BadTerrainKeysAreErrorsNamingTheKey) {
  const auto error = [](const std::string& yaml) {
    try {
      readScene(Config::fromString(yaml, "t.yaml"));
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const std::string head =
      "textures: {a: {pattern: uniform, color: [0.5, 0.5, 0.5]}}\nobjects: {p: {type: sphere, center: [0, 0, "
      "9], radius: 1, texture: a}}\n";
  const std::string surface = "  surface: {center: [0, 0], size: [100, 20], resolution: 0.25, texture: a}\n";
  EXPECT_NE(
      error(head + "terrain:\n  profiles: {r: {stations: [0, 10], heights: [0, 1], curve_length: 20}}\n" + surface)
          .find("terrain.profiles.r"),
      std::string::npos);
  EXPECT_NE(
      error(head + "terrain:\n  profiles: {r: {stations: [0, 100], heights: [0, 5], curve_lenght: 20}}\n" + surface)
          .find("curve_lenght"),
      std::string::npos);
  EXPECT_NE(error(head + "terrain:\n  profiles: {r: {stations: [0, 100], heights: [0, 5]}}\n" +
                  "  surface: {center: [0, 0], size: [100, 20], resolution: 2, texture: a}\n")
                .find("terrain.surface.resolution"),
            std::string::npos);
  EXPECT_NE(error(head + "terrain:\n  profiles: {r: {stations: [0, 100], heights: [0, 5]}}\n").find("terrain.surface"),
            std::string::npos);
}

TEST(TerrainScene, TheSimulatedCarDrivesOnTheScenesTerrain) {
  const std::string yaml = test::noiseFreeImuRig() + R"(
  wheel: {rate_hz: 50, track_width: 1.1, speed_noise_std: 0,
          T_I_B: {translation: [-0.8, 0, -1.15], rpy_deg: [0, 0, 0]}}
sim:
  duration_s: 5
  scene:
)" + [] {
    std::string s = kTerrainScene, out;
    size_t start = 0;
    while (start < s.size()) {  // indent the scene under sim.scene
      const size_t end = s.find('\n', start);
      const std::string line = s.substr(start, end - start);
      if (!line.empty()) out += "    " + line + "\n";
      start = end == std::string::npos ? s.size() : end + 1;
    }
    return out;
  }() + R"(
  trajectory:
    type: car
    waypoints: [-100, -2.2, 1.45,  300, -2.2, 1.45,  300, 2.2, 1.45,  -100, 2.2, 1.45]
    speed: 5
    shake: 0
    wheelbase: 2.7
)";
  const SimulationSetup setup = loadSimulation(Config::fromString(yaml, "terrain_car.yaml"), "");
  const Terrain& ground = *setup.scene->terrain;
  const Pose3 T_I_B = setup.rig.wheel->T_I_B;
  double worst = 0.0;
  for (double t = 20.0; t < 40.0; t += 0.1) {
    const Pose3 T_W_B = setup.trajectory->at(t).T_W_I * T_I_B;
    for (double left : {0.55, -0.55}) {
      // rear wheels: 0.3 m (1.45 - 1.15) below the axle
      const Vec3 p = T_W_B * Vec3(0.0, left, -0.3);
      worst = std::max(worst, std::abs(p.z() - ground.height(p.x(), p.y())));
    }
  }
  std::printf("rear wheels against h under an oblique 0.6 m / 90 m swell (4.2 %% grades): %.3g m\n", worst);
  EXPECT_LT(worst, 2e-3);  // the oblique swell twists the ground under the car by a little
  EXPECT_NE(setup.trajectory_description.find("on the scene's terrain"), std::string::npos);
}
