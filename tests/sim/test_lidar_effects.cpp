// LiDAR receiver effects (lidar_effects.*): range noise against its range/reflectivity model on
// flat walls, detection rates against the detection probability, mixed pixels and strongest
// returns at a step edge within the beam footprint, and, switched off, the former sweeps bit for bit.
#include <gtest/gtest.h>

#include <cstring>

#include "livo/sim/lidar_scanner.hpp"
#include "livo/sim/simulation_setup.hpp"
#include "livo/sim/simulator.hpp"
#include "sim_test_support.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

constexpr double kMrad = 1e-3;

/// Normal cdf, written out here rather than taken from the code under test.
double phi(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

/// A bounded box given by its corners.
void addBox(Scene* scene, const std::string& name, const Vec3& lo, const Vec3& hi, double reflectivity) {
  Shape box;
  box.type = ShapeType::kBox;
  box.center = 0.5 * (lo + hi);
  box.half_size = 0.5 * (hi - lo);
  Material m;
  m.reflectivity = reflectivity;
  scene->addShape(name, box, m);
}

/// A wall facing the sensor at the origin: the plane x = distance, as the front of a slab.
Scene wallAt(double distance, double reflectivity) {
  Scene scene;
  scene.addTexture(TextureOptions{});
  addBox(&scene, "wall", Vec3(distance, -1000, -1000), Vec3(distance + 1, 1000, 1000), reflectivity);
  scene.build();
  return scene;
}

/// A sensor standing at the origin, L = I = W.
LidarRig rigAtOrigin(const std::string& model) {
  LidarRig rig;
  rig.model = model;
  rig.min_range = 0.3;
  rig.max_range = 150.0;
  rig.range_noise_std = 0.0;
  rig.dropout_probability = 0.0;
  return rig;
}

std::vector<LidarSweep> sweeps(const LidarScanner& scanner, const Scene& scene, int n, uint64_t seed) {
  test::ConstantMotion still(Pose3::Identity());
  std::vector<LidarSweep> out;
  for (int k = 0; k < n; ++k)
    out.push_back(scanner.scan(scene, still, 0.1 * k, 100000 * k, 0.1 * k, Random(seed, 3, static_cast<uint64_t>(k))));
  return out;
}

Vec3 point(const LidarSweep& s, size_t j) { return Vec3(s.x[j], s.y[j], s.z[j]); }

uint64_t digest(const LidarSweep& s) {
  uint64_t h = mix64(s.size());
  auto add = [&](float f) {
    uint32_t b;
    std::memcpy(&b, &f, 4);
    h = mix64(h ^ b);
  };
  for (size_t j = 0; j < s.size(); ++j) {
    add(s.x[j]), add(s.y[j]), add(s.z[j]), add(s.intensity[j]), add(s.time_offset[j]);
    h = mix64(h ^ static_cast<uint16_t>(s.ring[j]));
  }
  return h;
}

}  // namespace

TEST(LidarEffects, SwitchedOffTheSweepsAreTheFormerModelsBitForBit) {
  // a room with a darker post, a moving sensor, noise and dropouts on; the digests were taken
  // with the scanner as it was before the effects existed
  Scene scene;
  scene.addTexture(TextureOptions{});
  addBox(&scene, "room", Vec3(-5, -4, 0), Vec3(5, 4, 4), 0.5);
  Shape post;
  post.type = ShapeType::kCylinder;
  post.center = Vec3(2, 1, 1);
  post.half_size = Vec3(0.3, 0.3, 1.0);
  Material dark;
  dark.reflectivity = 0.2;
  scene.addShape("post", post, dark);
  scene.build();
  Pose3 T = Pose3::Identity();
  T.translation() = Vec3(0.7, -0.4, 1.3);
  T.linear() = so3::Exp(Vec3(0.05, 0.04, 0.8));
  test::ConstantMotion moving(T, Vec3(1.0, 0.5, 0.0), Vec3(0.0, 0.0, 0.5));
  struct Case {
    std::string model;
    size_t points;
    uint64_t digest;
  };
  LidarEffects off_but_tuned;  // parameters that only matter once an effect is on
  off_but_tuned.noise_reflectivity_exponent = 1.0;
  off_but_tuned.detection_softness = 0.5;
  off_but_tuned.echo_separation_m = 0.3;
  for (const Case& k : {Case{"VLP-16", 27418, 0x2da6a71b200920fcULL}, Case{"OS1-64", 62223, 0x34e33afb81423700ULL},
                        Case{"livox-avia", 22726, 0x0fe0197c06912d73ULL}}) {
    LidarRig rig;
    rig.model = k.model;
    rig.min_range = 0.3;
    rig.range_noise_std = 0.02;
    rig.dropout_probability = 0.05;
    rig.T_I_L.translation() = Vec3(0.1, -0.05, 0.2);
    rig.T_I_L.linear() = so3::Exp(Vec3(0.02, -0.03, 0.3));
    for (const LidarEffects& effects : {LidarEffects{}, off_but_tuned}) {
      ASSERT_FALSE(effects.any());
      const LidarSweep s = LidarScanner(rig, {}, effects).scan(scene, moving, 0.2, 0, 0.2, Random(7, 3, 2));
      EXPECT_EQ(s.size(), k.points) << k.model;
      EXPECT_EQ(digest(s), k.digest) << k.model;
    }
  }
}

TEST(LidarEffects, RangeNoiseGrowsWithRangeAndFallingReflectivity) {
  const double base = 0.01, per_m = 0.002;
  LidarRig rig = rigAtOrigin("OS1-64");
  rig.range_noise_std = base;
  LidarEffects effects;
  effects.range_noise_per_m = per_m;  // quoted for 50 % at normal incidence, shot-noise exponent 0.5
  const LidarScanner scanner(rig, {}, effects);
  struct Case {
    double distance, reflectivity, expected_std;  // std of near-normal returns, from the datasheet-style model
  };
  // hypot(1 cm, 2 mm/m * D * sqrt(0.5 / reflectivity))
  for (const Case& k :
       {Case{4, 0.5, 0.012806}, Case{16, 0.5, 0.033526}, Case{40, 0.5, 0.080623}, Case{16, 0.125, 0.064777}}) {
    const Scene scene = wallAt(k.distance, k.reflectivity);
    double sq_normal = 0, sq_scaled = 0;
    size_t n_normal = 0, n = 0;
    for (const LidarSweep& s : sweeps(scanner, scene, 8, 11)) {
      for (size_t j = 0; j < s.size(); ++j) {
        const Vec3 p = point(s, j);
        const double cos_incidence = p.x() / p.norm();
        const double truth = k.distance / cos_incidence, e = p.norm() - truth;
        // every return against its own model std (range and incidence vary across the wall)
        const double model = std::hypot(base, per_m * truth * std::sqrt(0.5 / (k.reflectivity * cos_incidence)));
        sq_scaled += (e / model) * (e / model), ++n;
        if (cos_incidence > 0.995) sq_normal += e * e, ++n_normal;
      }
    }
    ASSERT_GT(n_normal, 3000u);
    // near-normal returns: range within 0.5 % of D, reflectivity penalty within 0.25 %
    EXPECT_NEAR(std::sqrt(sq_normal / n_normal) / k.expected_std, 1.0, 4.0 / std::sqrt(2.0 * n_normal) + 0.006)
        << "wall at " << k.distance << " m, reflectivity " << k.reflectivity;
    EXPECT_NEAR(std::sqrt(sq_scaled / n), 1.0, 4.0 / std::sqrt(2.0 * n)) << "wall at " << k.distance << " m";
  }
  // switched off, the noise is the rig's constant std at every range
  EXPECT_DOUBLE_EQ(rangeNoiseStd(LidarEffects{}, 0.03, 80.0, 0.05), 0.03);
}

TEST(LidarEffects, DetectionRateFollowsRangeAndReflectivity) {
  const double rated = 40.0, softness = 0.2;
  const LidarRig rig = rigAtOrigin("OS1-64");
  LidarEffects effects;
  effects.max_range_at_10pct = rated;
  effects.detection_softness = softness;
  const LidarScanner scanner(rig, {}, effects);
  const LidarPattern& pattern = scanner.pattern();
  struct Case {
    double distance, reflectivity, normal_rate;  // detection rate at normal incidence
  };
  // Phi(ln(reflectivity / 0.1 * (40 / D)^2) / 0.2 + 1.2816)
  for (const Case& k : {Case{30, 0.1, 0.99998}, Case{40, 0.1, 0.9}, Case{50, 0.1, 0.17109}, Case{50, 0.15, 0.85936},
                        Case{50, 0.4, 1.0}, Case{20, 0.02, 0.56586}}) {
    const Scene scene = wallAt(k.distance, k.reflectivity);
    const int n_sweeps = 12;
    // the model's expectation over every beam that meets the wall
    double expected = 0, variance = 0, expected_normal = 0;
    int beams_normal = 0;
    for (int c = 0; c < pattern.columns(); ++c) {
      for (int b = 0; b < pattern.beams(); ++b) {
        const Vec3 d = pattern.direction(b, pattern.firingTime(c, b), 0.0);
        if (d.x() <= 0.0 || k.distance / d.x() > rig.max_range) continue;
        const double r = k.distance / d.x();
        const double p = phi(std::log(k.reflectivity * d.x() / 0.1 * (rated / r) * (rated / r)) / softness + 1.2815516);
        expected += p, variance += p * (1 - p);
        if (d.x() > 0.998) expected_normal += p, ++beams_normal;
      }
    }
    size_t detected = 0, detected_normal = 0;
    for (const LidarSweep& s : sweeps(scanner, scene, n_sweeps, 5)) {
      detected += s.size();
      for (size_t j = 0; j < s.size(); ++j) detected_normal += point(s, j).normalized().x() > 0.998;
    }
    EXPECT_NEAR(static_cast<double>(detected), n_sweeps * expected, 4 * std::sqrt(n_sweeps * variance) + 1)
        << "wall at " << k.distance << " m, reflectivity " << k.reflectivity;
    const double n_normal = n_sweeps * beams_normal;
    ASSERT_GT(n_normal, 2000);
    const double rate = detected_normal / n_normal;
    // within 3.6 deg of the normal the power is within 1.2 % of the normal-incidence power
    EXPECT_NEAR(rate, k.normal_rate, 4 * std::sqrt(0.25 / n_normal) + 0.012) << "wall at " << k.distance << " m";
    EXPECT_NEAR(rate, expected_normal / beams_normal, 4 * std::sqrt(0.25 / n_normal));
  }
}

namespace {

/// A board whose left edge is the vertical line y = 0 at depth `board`, in front of a wall at
/// depth `wall` (0: no wall, the board against the sky).
Scene stepEdge(double board, double wall) {
  Scene scene;
  scene.addTexture(TextureOptions{});
  addBox(&scene, "board", Vec3(board, 0, -10), Vec3(board + 0.2, 30, 10), 0.5);
  if (wall > 0) addBox(&scene, "wall", Vec3(wall, -1000, -1000), Vec3(wall + 1, 1000, 1000), 0.5);
  scene.build();
  return scene;
}

struct EdgeReturns {
  int board = 0, wall = 0, mixed = 0, other = 0;
  int board_left_of_edge = 0;  // centre on the wall side, range of the board
  int outside_footprint = 0;   // not a pure return of the side the beam centre is on
  double widest_mixed = 0.0;   // largest |azimuth| * cos(elevation) of a mixed return (rad)
};

/// Classifies the returns within 10 deg of the edge: pure board, pure wall, or between.
EdgeReturns edgeReturns(const LidarSweep& s, double board, double wall, double half_footprint) {
  EdgeReturns r;
  for (size_t j = 0; j < s.size(); ++j) {
    const Vec3 p = point(s, j), d = p.normalized();
    const double az = std::atan2(d.y(), d.x()), cos_el = std::hypot(d.x(), d.y());
    if (std::abs(az) > 10 * M_PI / 180) continue;
    const double range = p.norm(), r_board = board / d.x(), r_wall = wall / d.x();
    const bool is_board = std::abs(range - r_board)<1e-4, is_wall = wall> 0 && std::abs(range - r_wall) < 1e-4;
    const bool between = range > r_board + 1e-3 && range < r_wall - 1e-3;
    r.board += is_board, r.wall += is_wall, r.mixed += between, r.other += !(is_board || is_wall || between);
    r.board_left_of_edge += is_board && az < 0;
    if (between) r.widest_mixed = std::max(r.widest_mixed, std::abs(az) * cos_el);
    // a sub-ray leaves the beam axis by at most half the divergence, so beams farther than that
    // from the edge see one surface only: the one on their side
    if (std::abs(az) * cos_el > half_footprint * 1.01 + 1e-7) r.outside_footprint += az > 0 ? !is_board : !is_wall;
  }
  return r;
}

LidarScanner edgeScanner(double divergence_h_mrad, double divergence_v_mrad) {
  LidarPatternOptions pattern;
  pattern.columns = 4096;                      // 1.53 mrad apart
  pattern.start_azimuth_deg = 180.0 - 0.0229;  // a column 0.4 mrad right of the edge, the next 1.13 mrad left
  LidarEffects effects;
  effects.beam_divergence_mrad = {{divergence_h_mrad, divergence_v_mrad}};
  effects.echo_separation_m = 1.0;
  return LidarScanner(rigAtOrigin("OS1-16"), pattern, effects);
}

}  // namespace

TEST(LidarEffects, MixedPixelsLieBetweenTheSurfacesWithinTheFootprintOfAnEdge) {
  const LidarScanner scanner = edgeScanner(3.0, 1.5);  // VLP-16 / VLS-128 class beam
  const Scene scene = stepEdge(9.4, 10.0);             // 0.6 m step: one merged echo
  const EdgeReturns r = edgeReturns(sweeps(scanner, scene, 1, 1).front(), 9.4, 10.0, 1.5 * kMrad);
  EXPECT_EQ(r.other, 0);
  EXPECT_EQ(r.outside_footprint, 0);
  EXPECT_EQ(r.mixed, 2 * 16);  // the columns 0.4 and 1.13 mrad from the edge, every ring
  EXPECT_LE(r.widest_mixed, 1.5 * kMrad * 1.01);
  EXPECT_GT(r.board, 1000);
  EXPECT_GT(r.wall, 1000);
}

TEST(LidarEffects, FarApartSurfacesGiveTheStrongestReturnNotAMixture) {
  const LidarScanner scanner = edgeScanner(3.0, 1.5);
  const Scene scene = stepEdge(7.0, 10.0);  // 3 m step: two echoes, the stronger one is reported
  const EdgeReturns r = edgeReturns(sweeps(scanner, scene, 1, 1).front(), 7.0, 10.0, 1.5 * kMrad);
  EXPECT_EQ(r.other, 0);
  EXPECT_EQ(r.mixed, 0);
  EXPECT_EQ(r.outside_footprint, 0);
  // 0.4 mrad left of the edge, 3/8 of the beam on the board (at 7 m) outshines 5/8 on the wall
  // (at 10 m): 0.375 / 49 > 0.625 / 100, so the board grows by part of the footprint
  EXPECT_EQ(r.board_left_of_edge, 16);
}

TEST(LidarEffects, WithoutDivergenceAnEdgeIsSharp) {
  const LidarScanner scanner = edgeScanner(0.0, 0.0);
  ASSERT_FALSE(scanner.effects().footprint());
  const Scene scene = stepEdge(9.4, 10.0);
  const EdgeReturns r = edgeReturns(sweeps(scanner, scene, 1, 1).front(), 9.4, 10.0, 0.0);
  EXPECT_EQ(r.other, 0);
  EXPECT_EQ(r.mixed, 0);
  EXPECT_EQ(r.outside_footprint, 0);
  EXPECT_EQ(r.board_left_of_edge, 0);
}

TEST(LidarEffects, APartlyMissingFootprintWeakensTheReturn) {
  const LidarScanner scanner = edgeScanner(3.0, 1.5);
  const Scene scene = stepEdge(9.4, 0.0);  // the board against the sky
  const LidarSweep s = sweeps(scanner, scene, 1, 1).front();
  int edge_returns = 0;
  for (size_t j = 0; j < s.size(); ++j) {
    const Vec3 d = point(s, j).normalized();
    if (std::abs(std::atan2(d.y(), d.x())) > 10 * M_PI / 180) continue;
    const double full = 255.0 * 0.5 * d.x();  // the whole beam on the board at this incidence
    if (d.y() < 0) {
      // 0.4 mrad off the board: the three sub-rays right of the axis (3/8 of the energy) hit it
      EXPECT_NEAR(s.intensity[j] / full, 0.375, 0.002);
      ++edge_returns;
    } else if (std::atan2(d.y(), d.x()) > 1.6 * kMrad) {
      EXPECT_NEAR(s.intensity[j] / full, 1.0, 0.002);
    }
  }
  EXPECT_EQ(edge_returns, 16);
}

TEST(LidarEffects, ConfigKeysAreReadAndChecked) {
  const std::string rig = test::noiseFreeImuRig() +
                          "  lidar: {model: OS1-16, rate_hz: 10, min_range: 0.5, max_range: 80, range_noise_std: 0.01, "
                          "T_I_L: {translation: [0,0,0], rpy_deg: [0,0,0]}}\n";
  const std::string rest = test::boxRoomScene() + "  trajectory: {type: handheld, waypoints: [0,0,1, 2,0,1, 2,2,1]}\n";
  auto load = [&](const std::string& lidar) {
    return loadSimulation(Config::fromString(rig + "sim:\n  lidar: {" + lidar + "}\n" + rest, "fx.yaml"), "");
  };
  auto error = [&](const std::string& lidar) {
    try {
      load(lidar);
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_FALSE(load("columns: 512").options.lidar_effects.any());
  const LidarEffects e = load(
                             "range_noise_per_m: 0.001, noise_reflectivity_exponent: 1, max_range_at_10pct: 45, "
                             "detection_softness: 0.3, beam_divergence_mrad: [2.3, 2.3], echo_separation_m: 0.8")
                             .options.lidar_effects;
  EXPECT_EQ(e.range_noise_per_m, 0.001);
  EXPECT_EQ(e.noise_reflectivity_exponent, 1.0);
  EXPECT_EQ(e.max_range_at_10pct, 45.0);
  EXPECT_EQ(e.detection_softness, 0.3);
  EXPECT_EQ(e.beam_divergence_mrad[0], 2.3);
  EXPECT_EQ(e.beam_divergence_mrad[1], 2.3);
  EXPECT_EQ(e.echo_separation_m, 0.8);
  EXPECT_NE(error("range_noise_per_m: -0.01").find("fx.yaml: sim.lidar.range_noise_per_m: must be in [0, 0.1]"),
            std::string::npos);
  EXPECT_NE(error("beam_divergence_mrad: [3]").find("sim.lidar.beam_divergence_mrad: must be [horizontal, vertical]"),
            std::string::npos);
  EXPECT_NE(error("beam_divergence_mrad: [3, -1]").find("sim.lidar.beam_divergence_mrad: must be in [0, 50] mrad"),
            std::string::npos);
  EXPECT_NE(error("detection_softness: 0").find("sim.lidar.detection_softness: must be in (0, 2]"), std::string::npos);
  EXPECT_NE(error("max_range_at_10pc: 40").find("did you mean sim.lidar.max_range_at_10pct?"), std::string::npos);
}

TEST(LidarEffects, SameSeedGivesTheSameSweepsWhateverTheThreads) {
  const std::string yaml =
      test::noiseFreeImuRig() +
      "  lidar: {model: VLP-16, rate_hz: 10, min_range: 0.3, max_range: 100, range_noise_std: 0.01, "
      "dropout_probability: 0.02, T_I_L: {translation: [0,0,0.1], rpy_deg: [0,0,0]}}\n"
      "sim:\n  duration_s: 0.35\n  lidar: {range_noise_per_m: 0.002, max_range_at_10pct: 3, "
      "beam_divergence_mrad: [3, 1.5]}\n" +
      test::boxRoomScene() + "  trajectory: {type: handheld, waypoints: [0,0,1, 2,0,1, 2,2,1]}\n";
  std::vector<LidarSweep> runs[2];
  for (int i = 0; i < 2; ++i) {
    SimOverrides o;
    o.threads = i == 0 ? 1 : 3;
    const SimulationSetup setup = loadSimulation(Config::fromString(yaml, "fx.yaml"), "", o);
    test::CollectingSink sink;
    Simulator(setup).run(sink);
    runs[i] = sink.sweeps;
  }
  ASSERT_EQ(runs[0].size(), 3u);
  for (size_t k = 0; k < runs[0].size(); ++k) {
    EXPECT_GT(runs[0][k].size(), 1000u);
    EXPECT_LT(runs[0][k].size(), 0.9 * 1808 * 16);  // the 3 m rated range drops part of the far walls
    EXPECT_EQ(digest(runs[0][k]), digest(runs[1][k])) << "sweep " << k;
  }
}
