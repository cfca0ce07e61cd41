// map-bars --config config/sim/room.yaml [--duration S]: the colour and OctoMap bars on a simulated
// run, in-process. An exact stand-in LIO turns each simulated sweep into a REGISTERED_SCAN
// (every point moved to the world with the true LiDAR pose at its own firing time; body pose at
// the sweep end) and ground-truth poses stand in for ODOMETRY. Measured:
//  - colour error: |map colour - true colour| per channel / 255, mean over coloured points; the
//    true colour is the scene's texture at the surface point the point's beam hit, shaded by the
//    scene light and scaled to the camera's nominal exposure (what an ideal camera records);
//  - occlusion rate: coloured points of which any accepted sample came from a pixel whose camera
//    ray hits another surface more than 0.1 m nearer than the point;
//  - OctoMap precision / recall at the map's resolution against the true scene (see
//    processes/octomap/README.md): a voxel is a surface voxel if the true surface passes through
//    its closed cube (tested by casting a 4x4 grid of segments along each axis through the cube,
//    grown by 1 mm: a surface lying on a voxel face belongs to both voxels it bounds, and noisy
//    hits land in either). Precision: occupied voxels that are surface voxels. Recall: of the
//    surface voxels that were observed (within one voxel of a noise-free beam hit, and holding a
//    hit or known in the map), those occupied; a surface lying on a face between two voxels
//    counts once, found if either is occupied. The older figures against "voxels holding a noise-free hit" are printed
//    too;
//  - CPU time per scan and per image of each core.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <unordered_map>
#include <unordered_set>

#include "livo/colour/colour_config.hpp"
#include "livo/colour/colouring_pipeline.hpp"
#include "livo/command_line.hpp"
#include "livo/octomap/octomap_builder.hpp"
#include "livo/octomap/octomap_config.hpp"
#include "livo/sim/simulation_setup.hpp"
#include "livo/sim/simulator.hpp"

using namespace livo;

namespace {

uint64_t indexKey(int64_t i, int64_t j, int64_t k) {
  auto u = [](int64_t v) { return static_cast<uint64_t>(v + (1 << 20)) & 0x1FFFFF; };
  return (u(i) << 42) | (u(j) << 21) | u(k);
}
uint64_t voxelKey(const Eigen::Vector3d& p, double res) {
  return indexKey(static_cast<int64_t>(std::floor(p.x() / res)), static_cast<int64_t>(std::floor(p.y() / res)),
                  static_cast<int64_t>(std::floor(p.z() / res)));
}
Eigen::Vector3d voxelCentre(uint64_t key, double res) {
  auto v = [res](uint64_t u) {
    return (static_cast<double>(static_cast<int64_t>(u & 0x1FFFFF) - (1 << 20)) + 0.5) * res;
  };
  return {v(key >> 42), v(key >> 21), v(key)};
}
uint64_t bitsOf(const Eigen::Vector3f& p) {
  uint32_t a, b, c;
  std::memcpy(&a, &p.x(), 4), std::memcpy(&b, &p.y(), 4), std::memcpy(&c, &p.z(), 4);
  return (uint64_t(a) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(b) * 0xC2B2AE3D27D4EB4Full) ^ c;
}
double cpuSeconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

class BarSink : public sim::SensorDataSink {
 public:
  BarSink(const sim::SimulationSetup& setup, const colour::ColourOptions& co, const livo::octomap::OctomapOptions& oo)
      : setup_(setup), colour_(co, *setup.rig.camera), octo_(oo, setup.rig.lidar->T_I_L), res_(oo.resolution) {
    colour_.setObserver([this](const colour::Observation& o) {
      const Eigen::Vector3d p = colour_.map().point(o.point).position.cast<double>();
      sim::Ray ray;
      ray.origin = o.camera_center;
      const double dist = (p - o.camera_center).norm();
      ray.direction = (p - o.camera_center) / dist;
      const sim::RayHit hit = setup_.scene->cast(ray);
      if (hit.valid() && hit.t < dist - 0.1) occluded_.insert(o.point);
    });
  }
  void write(const sim::ImuReading&) override {}
  void write(const sim::WheelReading&) override {}
  void write(const sim::PoseReading& m) override { colour_.addPose(m.utime, m.T_W_I); }
  void write(const sim::LidarSweep& s) override {
    const int64_t end = s.utime + static_cast<int64_t>(std::llround(s.duration * 1e6));
    std::vector<float> x(s.size()), y(s.size()), z(s.size());
    std::unordered_map<uint64_t, Eigen::Vector3d> origin_of;
    origin_of.reserve(s.size());
    for (size_t j = 0; j < s.size(); ++j) {
      const double t = setup_.trajectoryTime(s.utime) + s.time_offset[j];
      const Pose3 T_W_L = setup_.trajectory->at(t).T_W_I * setup_.rig.lidar->T_I_L;
      const Eigen::Vector3d p = T_W_L * Eigen::Vector3d(s.x[j], s.y[j], s.z[j]);
      x[j] = float(p.x()), y[j] = float(p.y()), z[j] = float(p.z());
      origin_of[bitsOf(Eigen::Vector3f(x[j], y[j], z[j]))] = T_W_L.translation();
      // the true surface point of this beam, for the OctoMap truth
      sim::Ray ray;
      ray.origin = T_W_L.translation();
      ray.direction = (p - ray.origin).normalized();
      const sim::RayHit hit = setup_.scene->cast(ray);
      if (hit.valid()) truth_voxels_.insert(voxelKey(ray.origin + hit.t * ray.direction, res_));
    }
    const Pose3 T_end = setup_.trajectory->at(setup_.trajectoryTime(end)).T_W_I;
    RegisteredScanView cv;
    cv.utime = end;
    cv.cloud_utime = s.utime;
    cv.T_W_I = T_end;
    cv.num_points = static_cast<int>(s.size());
    cv.x = x.data(), cv.y = y.data(), cv.z = z.data(), cv.time_offset = s.time_offset.data();
    std::string error;
    double c0 = cpuSeconds();
    colour_.addScan(cv, &error);
    colour_cpu_ += cpuSeconds() - c0;
    // the points this scan created: new slots, and freed ones (points that left the map
    // uncoloured) taken again, which hold another position now
    truth_.resize(colour_.map().size());
    for (size_t id = 0; id < colour_.map().size(); ++id) {
      const colour::MapPoint& mp = colour_.map().point(id);
      const uint64_t bits = bitsOf(mp.position);
      if (!mp.live() || (truth_[id].set && truth_[id].bits == bits)) continue;
      auto it = origin_of.find(bits);
      truth_[id].set = true;
      truth_[id].known = it != origin_of.end();
      truth_[id].bits = bits;
      if (truth_[id].known) truth_[id].colour = trueColour(it->second, mp.position.cast<double>());
    }
    c0 = cpuSeconds();
    octo_.addScan(cv, &error);  // the same view
    octo_cpu_ += cpuSeconds() - c0;
    ++scans_;
  }
  void write(const sim::CameraImage& m) override {
    colour::ColourImage img;
    img.utime = m.utime;
    img.exposure_time = m.exposure_time;
    img.pixels = cv::Mat(m.height, m.width, m.color ? CV_8UC3 : CV_8UC1, const_cast<uint8_t*>(m.data.data())).clone();
    std::string error;
    const double c0 = cpuSeconds();
    colour_.addImage(std::move(img), &error);
    colour_cpu_ += cpuSeconds() - c0;
    ++images_;
  }

  void report() {
    colour_.flush();
    double err = 0.0;
    size_t n = 0, occluded = 0;
    for (size_t id = 0; id < truth_.size(); ++id) {
      const colour::MapPoint& p = colour_.map().point(id);
      if (!truth_[id].known || !p.live() || !p.coloured()) continue;
      err += (p.colour - truth_[id].colour).cwiseAbs().mean();
      ++n;
      occluded += occluded_.count(id);
    }
    const auto occupied = octo_.map().occupiedVoxels();
    size_t tp = 0, tp_surface = 0;
    std::unordered_set<uint64_t> occupied_keys;
    for (const Eigen::Vector3d& c : occupied) {
      const uint64_t k = voxelKey(c, res_);
      occupied_keys.insert(k);
      tp += truth_voxels_.count(k);
      tp_surface += isSurface(k, true);
    }
    size_t found = 0;
    for (uint64_t k : truth_voxels_) found += occupied_keys.count(k);
    // observed surface voxels: within one voxel of a noise-free hit, surface, and observed
    std::unordered_set<uint64_t> candidates;
    for (uint64_t k : truth_voxels_) {
      const Eigen::Vector3d c = voxelCentre(k, res_);
      const int64_t i = std::llround(c.x() / res_ - 0.5), j = std::llround(c.y() / res_ - 0.5),
                    l = std::llround(c.z() / res_ - 0.5);
      for (int di = -1; di <= 1; ++di)
        for (int dj = -1; dj <= 1; ++dj)
          for (int dl = -1; dl <= 1; ++dl) candidates.insert(indexKey(i + di, j + dj, l + dl));
    }
    // A surface lying on a voxel face is one surface element shared by the two voxels it bounds
    // (noise puts its hits in either): it counts once, found if either is occupied.
    std::unordered_set<uint64_t> units;
    size_t surface_observed = 0, surface_found = 0;
    auto count = [&](uint64_t unit, bool found) {
      if (!units.insert(unit).second) return;
      ++surface_observed;
      surface_found += found;
    };
    for (uint64_t k : candidates) {
      if (!isSurface(k, true)) continue;
      if (!truth_voxels_.count(k) && octo_.map().classify(voxelCentre(k, res_)) < 0) continue;
      if (isSurface(k, false)) {
        count(k, occupied_keys.count(k) > 0);
        continue;
      }
      const Eigen::Vector3d c = voxelCentre(k, res_);
      for (int a = 0; a < 3; ++a)
        for (int sgn = -1; sgn <= 1; sgn += 2) {
          if (!surfaceOnFace(c, a, sgn)) continue;
          Eigen::Vector3d nc = c;
          nc[a] += sgn * res_;
          const uint64_t n = voxelKey(nc, res_);
          count(std::min(k, n) * 0x9E3779B97F4A7C15ull ^ std::max(k, n),
                occupied_keys.count(k) || occupied_keys.count(n));
        }
    }
    const auto& st = colour_.stats();
    std::printf("scans %lld, images %lld (without pose %lld), map points %zu, coloured %zu (with truth %zu)\n",
                (long long)scans_, (long long)st.images, (long long)st.images_without_pose, colour_.map().size(),
                colour_.map().colouredCount(), n);
    std::printf(
        "colour: mean error %.2f/255 (bar < 10), occluder-coloured points %.3f %% (bar < 1 %%), "
        "samples accepted %lld, occluded %lld, outliers %lld, gain estimates %lld\n",
        n ? err / n : 0.0, n ? 100.0 * occluded / n : 0.0, (long long)st.accepted, (long long)st.occluded,
        (long long)st.outliers, (long long)st.gain_estimates);
    std::printf(
        "octomap: occupied voxels %zu, observed surface voxels %zu, precision %.4f, recall %.4f (bars >= 0.9)\n",
        occupied.size(), surface_observed, occupied.empty() ? 0.0 : double(tp_surface) / occupied.size(),
        surface_observed ? double(surface_found) / surface_observed : 0.0);
    std::printf("octomap (old truth: voxels holding a noise-free hit, %zu): precision %.4f, recall %.4f\n",
                truth_voxels_.size(), occupied.empty() ? 0.0 : double(tp) / occupied.size(),
                truth_voxels_.empty() ? 0.0 : double(found) / truth_voxels_.size());
    std::printf("cpu: colour %.2f ms per scan+2 images (%.1f %% of one core at 10 Hz), octomap %.2f ms per scan\n",
                scans_ ? 1e3 * colour_cpu_ / scans_ : 0.0, scans_ ? 100.0 * colour_cpu_ / (scans_ * 0.1) : 0.0,
                scans_ ? 1e3 * octo_cpu_ / scans_ : 0.0);
  }

 private:
  // The true surface passes through the voxel: `closed` tests the closed cube grown by 1 mm (a
  // surface lying on a face belongs to both voxels it bounds: either may hold the noisy hits),
  // otherwise the interior (the cube shrunk by 1 mm).
  bool isSurface(uint64_t key, bool closed) {
    auto& cache = closed ? closed_cache_ : open_cache_;
    auto it = cache.find(key);
    if (it != cache.end()) return it->second;
    const double eps = closed ? 1e-3 : -1e-3, len = res_ + 2 * eps;
    const Eigen::Vector3d lo = voxelCentre(key, res_) - Eigen::Vector3d::Constant(0.5 * res_ + eps);
    bool hit = false;
    for (int a = 0; a < 3 && !hit; ++a) {
      const int b = (a + 1) % 3, c = (a + 2) % 3;
      for (int i = 0; i < 4 && !hit; ++i)
        for (int j = 0; j < 4 && !hit; ++j) {
          sim::Ray ray;
          ray.origin = lo;
          ray.origin[b] += len * i / 3.0;
          ray.origin[c] += len * j / 3.0;
          ray.direction = Eigen::Vector3d::Unit(a);
          hit = setup_.scene->cast(ray, 0.0, len).valid();
        }
    }
    cache[key] = hit;
    return hit;
  }
  // the true surface lies on the face of the voxel centred at c normal to axis a, side sgn
  // (2 mm probes across the face at a 3x3 grid)
  bool surfaceOnFace(const Eigen::Vector3d& c, int a, int sgn) const {
    const int b = (a + 1) % 3, d = (a + 2) % 3;
    for (int i = 1; i <= 3; ++i)
      for (int j = 1; j <= 3; ++j) {
        sim::Ray ray;
        ray.origin = c;
        ray.origin[a] += sgn * (0.5 * res_ - 1e-3);
        ray.origin[b] += res_ * (i / 4.0 - 0.5);
        ray.origin[d] += res_ * (j / 4.0 - 0.5);
        ray.direction = Eigen::Vector3d::Unit(a) * sgn;
        if (setup_.scene->cast(ray, 0.0, 2e-3).valid()) return true;
      }
    return false;
  }

  Eigen::Vector3f trueColour(const Eigen::Vector3d& origin, const Eigen::Vector3d& p) const {
    sim::Ray ray;
    ray.origin = origin;
    const double d = (p - origin).norm();
    ray.direction = (p - origin) / d;
    const sim::RayHit hit = setup_.scene->cast(ray);
    if (!hit.valid()) return Eigen::Vector3f::Constant(-1000.f);
    const sim::SurfacePoint sp = setup_.scene->surface(ray, hit);
    const sim::Scene& scene = *setup_.scene;
    const double light =
        scene.lighting.ambient + scene.lighting.diffuse * std::max(0.0, -sp.normal.dot(scene.lighting.direction));
    const double footprint = hit.t / setup_.rig.camera->fx;
    const sim::Texture& tex = scene.texture(scene.material(hit.object).texture);
    const double gain = 255.0 * setup_.options.camera.brightness * light;
    if (!setup_.rig.camera->color)
      return Eigen::Vector3f::Constant(float(gain * tex.sampleLuminance(sp.u, sp.v, footprint)));
    return tex.sample(sp.u, sp.v, footprint) * float(gain);
  }

  const sim::SimulationSetup& setup_;
  colour::ColouringPipeline colour_;
  livo::octomap::OctomapBuilder octo_;
  double res_;
  struct Truth {
    bool set = false, known = false;  // known: the point came from a beam of a scan
    uint64_t bits = 0;                // of the position it was computed for
    Eigen::Vector3f colour;
  };
  std::vector<Truth> truth_;  // per map point id
  std::unordered_set<uint32_t> occluded_;
  std::unordered_set<uint64_t> truth_voxels_;
  std::unordered_map<uint64_t, bool> closed_cache_, open_cache_;
  int64_t scans_ = 0, images_ = 0;
  double colour_cpu_ = 0.0, octo_cpu_ = 0.0;
};

}  // namespace

int main(int argc, char** argv) {
  CommandLine cli("map-bars", "colour and OctoMap bars on a simulated run (exact stand-in LIO)");
  cli.option("--config", "FILE", "sim config").option("--duration", "S", "seconds to simulate", "20");
  if (!cli.parse(argc, argv)) return cli.exitCode();
  try {
    sim::SimOverrides ov;
    ov.duration_s = cli.getDouble("--duration");
    const sim::SimulationSetup setup = sim::loadSimulation(cli.get("--config"), ov);
    const Config cfg = Config::load(cli.get("--config"));
    // the config's colour: section (defaults if absent) with the bar's photometric calibration:
    // the simulator's camera model
    colour::ColourOptions co = colour::readColourNodeOptions(cfg).core;
    co.vignetting = setup.options.camera.vignetting;
    co.reference_exposure_s = setup.options.camera.exposure_time;
    // the config's octomap: section (defaults if absent), at the bar's resolution and the sensor's range
    livo::octomap::OctomapOptions oo = livo::octomap::readOctomapNodeOptions(cfg).core;
    oo.resolution = 0.1;
    oo.max_range = setup.rig.lidar->max_range;
    colour::printOptions(co, std::cout);
    livo::octomap::printOptions(oo, std::cout);
    BarSink sink(setup, co, oo);
    sim::Simulator(setup).run(sink);
    sink.report();
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "map-bars: " << e.what() << std::endl;
    return 1;
  }
}
