// The RGB-D camera's depth image: the renderer's z-depth against the geometry, the sensor model
// (noise growing with range, working range, holes at discontinuities and in blobs, none on sky)
// against its own formulas, determinism, and a log with depth whose other channels are byte for
// byte those of the same run without it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include <lcm/lcm-cpp.hpp>

#include "livo/camera_projection.hpp"
#include "livo/image_t.hpp"
#include "livo/sim/camera_renderer.hpp"
#include "livo/sim/depth_effects.hpp"
#include "livo/sim/log_writer.hpp"
#include "livo/sim/simulation_setup.hpp"
#include "livo/sim/simulator.hpp"
#include "sim_test_support.hpp"
#include "temp_path.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

CameraRig depthCamera() {
  CameraRig c;
  c.width = 320;
  c.height = 240;
  c.fx = c.fy = 200.0;
  c.cx = 159.5;
  c.cy = 119.5;
  c.distortion = {-0.1, 0.02, 0.0, 0.0};
  c.rate_hz = 20;
  c.depth = true;
  return c;
}

/// Planes facing the camera (which looks along world z from the origin) at the given depths, each
/// `half` wide, centred at `x`.
struct Wall {
  double z, x, half;
};
Scene wallScene(const std::vector<Wall>& walls) {
  Scene scene;
  TextureOptions t;
  t.pattern = TexturePattern::kNoise;
  scene.addTexture(t);
  for (size_t i = 0; i < walls.size(); ++i) {
    Shape plane;
    plane.type = ShapeType::kPlane;
    plane.center = Vec3(walls[i].x, 0.0, walls[i].z);
    plane.half_size = Vec3(walls[i].half, walls[i].half, 0.0);
    scene.addShape("wall" + std::to_string(i), plane, Material{});
  }
  scene.build();
  return scene;
}

/// The exact z-depth the renderer gives for a camera at the world origin looking along world z.
std::vector<float> exactDepth(const Scene& scene, const CameraRig& rig, int motion_blur_samples = 1) {
  CameraEffects e = test::plainEffects();
  e.motion_blur_samples = motion_blur_samples;
  CameraRenderer renderer(rig, e);
  test::ConstantMotion still(Pose3::Identity());
  std::vector<float> z;
  renderer.render(scene, still, 0.0, 1, Random(1, 4), ExposureSetting{e.exposure_time, 1.0}, &z);
  return z;
}

}  // namespace

// The z-depth of every pixel is where its ray (the camera model's) meets the geometry, along the
// optical axis: a plane facing the camera at 3 m is 3 m deep at every pixel, and beside it, where
// nothing is hit (sky), there is no depth.
TEST(DepthImage, RendererDepthIsTheRayCastGeometry) {
  const CameraRig rig = depthCamera();
  const Scene scene = wallScene({{3.0, 0.0, 1.5}});
  const std::vector<float> z = exactDepth(scene, rig);
  ASSERT_EQ(z.size(), 320u * 240u);
  const CameraProjection camera(rig);
  int on_wall = 0, sky = 0;
  for (int v = 0; v < rig.height; ++v)
    for (int u = 0; u < rig.width; ++u) {
      const Vec3 ray = camera.pixelRay(Eigen::Vector2d(u, v));
      const Vec3 p = ray * (3.0 / ray.z());  // on the plane z = 3
      const float d = z[static_cast<size_t>(v) * rig.width + u];
      if (std::abs(p.x()) < 1.49 && std::abs(p.y()) < 1.49) {
        ASSERT_NEAR(d, 3.0, 2e-6) << u << ", " << v;
        ++on_wall;
      } else if (std::abs(p.x()) > 1.51 || std::abs(p.y()) > 1.51) {
        ASSERT_EQ(d, 0.0f) << u << ", " << v;
        ++sky;
      }
    }
  EXPECT_GT(on_wall, 20000);
  EXPECT_GT(sky, 20000);
  // two sub-frames have none at mid-exposure: the depth comes from a pass of its own, the same
  EXPECT_EQ(exactDepth(scene, rig, 2), z);
}

// The measured depth against the truth at near, middle and far range: the error's spread is the
// model's sigma(z) = noise_floor + noise_per_m2 z^2 within 4 % (about 70,000 pixels each), its
// mean within a tenth of it. Holes are switched off here.
TEST(DepthImage, NoiseGrowsWithRangeAsTheModelSays) {
  const CameraRig rig = depthCamera();
  DepthEffects e;
  e.hole_fraction = 0.0;
  e.edge_hole_px = 0;
  for (const double range : {1.0, 3.0, 6.0}) {
    const std::vector<float> z = exactDepth(wallScene({{range, 0.0, 50.0}}), rig);
    const std::vector<uint16_t> mm = measureDepth(z, rig.width, rig.height, e, Random(7, 6, 0));
    double sum = 0.0, sum2 = 0.0;
    int n = 0;
    for (size_t k = 0; k < z.size(); ++k) {
      ASSERT_GT(mm[k], 0) << "a wall in range has depth everywhere without holes";
      const double err = mm[k] * 1e-3 - z[k];
      sum += err, sum2 += err * err, ++n;
    }
    const double mean = sum / n, sigma = std::sqrt(sum2 / n - mean * mean), model = e.sigmaAt(range);
    std::printf("depth noise at %.0f m: measured %.2f mm, model %.2f mm (mean %+.2f mm, %d pixels)\n", range,
                sigma * 1e3, model * 1e3, mean * 1e3, n);
    EXPECT_NEAR(sigma / model, 1.0, 0.04) << range << " m";
    EXPECT_LT(std::abs(mean), 0.1 * model) << range << " m";
  }
}

// Outside the working range there is no depth; inside, none is lost but to holes.
TEST(DepthImage, NoDepthOutsideTheWorkingRange) {
  const CameraRig rig = depthCamera();
  DepthEffects e;
  e.hole_fraction = 0.0;
  e.edge_hole_px = 0;
  for (const double range : {0.15, 12.0}) {
    const std::vector<float> z = exactDepth(wallScene({{range, 0.0, 50.0}}), rig);
    const std::vector<uint16_t> mm = measureDepth(z, rig.width, rig.height, e, Random(7, 6, 0));
    for (uint16_t d : mm) ASSERT_EQ(d, 0) << range << " m";
  }
}

// A near wall in front of a far one, sky around both: every pixel within edge_hole_px of a
// discontinuity (a jump to the near wall or to the sky) is a hole; elsewhere the random blobs take
// hole_fraction of the pixels (2 %; over 20 frames, about 100 blobs, within 1.4-2.6 %). Sky never
// has depth.
TEST(DepthImage, HolesAtDiscontinuitiesAndInBlobsNoneOnSky) {
  const CameraRig rig = depthCamera();
  const DepthEffects e;
  const std::vector<float> z = exactDepth(wallScene({{5.0, 0.0, 2.5}, {2.0, -0.4, 0.5}}), rig);
  const int w = rig.width, h = rig.height;
  // the band: pixels within edge_hole_px - 1 (Chebyshev) of one across a jump
  std::vector<uint8_t> edge(z.size(), 0), band(z.size(), 0);
  for (int v = 1; v + 1 < h; ++v)
    for (int u = 1; u + 1 < w; ++u) {
      const size_t k = static_cast<size_t>(v) * w + u;
      edge[k] = z[k] > 0.0f && (std::abs(z[k + 1] - z[k]) > 0.5 || std::abs(z[k - 1] - z[k]) > 0.5 ||
                                std::abs(z[k + w] - z[k]) > 0.5 || std::abs(z[k - w] - z[k]) > 0.5);
    }
  const int r = e.edge_hole_px - 1;
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u)
      if (edge[static_cast<size_t>(v) * w + u])
        for (int j = std::max(0, v - r); j <= std::min(h - 1, v + r); ++j)
          for (int i = std::max(0, u - r); i <= std::min(w - 1, u + r); ++i) band[static_cast<size_t>(j) * w + i] = 1;
  int64_t with_truth = 0, holes = 0, in_band = 0, band_holes = 0, interior = 0, interior_holes = 0, sky = 0;
  for (uint64_t frame = 0; frame < 20; ++frame) {
    const std::vector<uint16_t> mm = measureDepth(z, w, h, e, Random(3, 6, frame));
    for (int v = 1; v + 1 < h; ++v)
      for (int u = 1; u + 1 < w; ++u) {
        const size_t k = static_cast<size_t>(v) * w + u;
        if (z[k] == 0.0f) {
          ASSERT_EQ(mm[k], 0) << "sky at " << u << ", " << v;
          ++sky;
          continue;
        }
        ++with_truth, holes += mm[k] == 0;
        if (band[k])
          ++in_band, band_holes += mm[k] == 0;
        else
          ++interior, interior_holes += mm[k] == 0;
      }
  }
  const double blob_share = static_cast<double>(interior_holes) / interior;
  std::printf(
      "depth holes: %.2f %% of the pixels with depth in range (band at jumps %.2f %% of them, all holes; "
      "blobs %.2f %% of the rest); sky %lld pixels\n",
      100.0 * holes / with_truth, 100.0 * in_band / with_truth, 100.0 * blob_share, static_cast<long long>(sky));
  EXPECT_GT(sky, 20000);
  EXPECT_GT(in_band, 20000);
  EXPECT_EQ(band_holes, in_band) << "every pixel within edge_hole_px of a discontinuity is a hole";
  EXPECT_GT(blob_share, 0.014);
  EXPECT_LT(blob_share, 0.026);
}

TEST(DepthImage, TheSameSeedGivesTheSameDepth) {
  const CameraRig rig = depthCamera();
  const std::vector<float> z = exactDepth(wallScene({{5.0, 0.0, 2.5}, {2.0, -0.4, 0.5}}), rig);
  const DepthEffects e;
  EXPECT_EQ(measureDepth(z, rig.width, rig.height, e, Random(3, 6, 1)),
            measureDepth(z, rig.width, rig.height, e, Random(3, 6, 1)));
  EXPECT_NE(measureDepth(z, rig.width, rig.height, e, Random(3, 6, 1)),
            measureDepth(z, rig.width, rig.height, e, Random(4, 6, 1)));
}

namespace {

std::string roomYaml(bool depth) {
  std::ifstream in(std::string(LIVO_SOURCE_DIR) + "/config/sim/room.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  if (depth) {
    const size_t at = yaml.find("    T_I_C:");
    EXPECT_NE(at, std::string::npos);
    yaml.insert(at, "    depth: true\n");
  }
  return yaml;
}

/// Channel -> the payloads of its events in order, and the log's event order by channel.
std::map<std::string, std::vector<std::vector<uint8_t>>> simulate(bool depth, uint64_t seed,
                                                                  std::vector<std::string>* order) {
  SimOverrides o;
  o.duration_s = 0.35;
  o.seed = seed;
  const SimulationSetup setup =
      loadSimulation(Config::fromString(roomYaml(depth), depth ? "room_depth.yaml" : "room.yaml"),
                     std::string(LIVO_SOURCE_DIR) + "/config/sim", o);
  const std::string path = livo_test::tempPath("depth_") + (depth ? "on" : "off") + std::to_string(seed) + ".lcmlog";
  {
    LogWriter writer(path, setup.rig.channels);
    Simulator(setup).run(writer);
  }
  std::map<std::string, std::vector<std::vector<uint8_t>>> out;
  lcm::LogFile log(path, "r");
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    const auto* b = static_cast<const uint8_t*>(ev->data);
    out[ev->channel].emplace_back(b, b + ev->datalen);
    order->push_back(ev->channel);
  }
  std::remove(path.c_str());
  return out;
}

}  // namespace

// Depth on: a DEPTH16 image on DEPTH after every camera image, with the same stamp and size; every
// other channel byte for byte as without depth (its noise has a random stream of its own); the
// same seed gives the same depth.
TEST(DepthImage, AddingDepthLeavesEveryOtherChannelByteIdentical) {
  std::vector<std::string> order_off, order_on, order_again;
  const auto off = simulate(false, 5, &order_off);
  const auto on = simulate(true, 5, &order_on);
  ASSERT_EQ(off.count("DEPTH"), 0u);
  ASSERT_EQ(on.count("DEPTH"), 1u);
  for (const auto& [channel, payloads] : off) EXPECT_TRUE(on.at(channel) == payloads) << channel;
  order_on.erase(std::remove(order_on.begin(), order_on.end(), "DEPTH"), order_on.end());
  EXPECT_EQ(order_on, order_off);
  const auto& depth = on.at("DEPTH");
  const auto& camera = on.at("CAMERA");
  ASSERT_EQ(depth.size(), camera.size());
  ASSERT_GE(depth.size(), 6u);
  for (size_t i = 0; i < depth.size(); ++i) {
    image_t d, c;
    ASSERT_EQ(d.decode(depth[i].data(), 0, static_cast<int>(depth[i].size())), static_cast<int>(depth[i].size()));
    ASSERT_EQ(c.decode(camera[i].data(), 0, static_cast<int>(camera[i].size())), static_cast<int>(camera[i].size()));
    EXPECT_EQ(d.encoding, int8_t{image_t::ENCODING_DEPTH16});
    EXPECT_EQ(d.utime, c.utime);
    EXPECT_EQ(d.width, c.width);
    EXPECT_EQ(d.height, c.height);
    EXPECT_EQ(d.row_stride, 2 * c.width);
    EXPECT_EQ(d.size, 2 * c.width * c.height);
    int valid = 0;
    for (int k = 0; k < d.width * d.height; ++k) valid += (d.data[2 * k] | d.data[2 * k + 1]) != 0;
    EXPECT_GT(valid, d.width * d.height / 2) << "a room is mostly within a depth camera's range";
  }
  EXPECT_TRUE(simulate(true, 5, &order_again).at("DEPTH") == depth);
}
