// map-bars --config config/sim/room.yaml [--duration S]: the colour and OctoMap bars on a simulated
// run, in-process. An exact stand-in LIO turns each simulated sweep into a REGISTERED_SCAN
// (every point moved to the world with the true LiDAR pose at its own firing time; body pose at
// the sweep end) and ground-truth poses stand in for ODOMETRY. Measured:
//  - colour error: |map colour - true colour| per channel / 255, mean over coloured points; the
//    true colour is the scene's texture at the surface point the point's beam hit, shaded by the
//    scene light and scaled to the camera's nominal exposure (what an ideal camera records);
//  - occlusion rate: coloured points of which any accepted sample came from a pixel whose camera
//    ray hits another surface more than 0.1 m nearer than the point;
//  - OctoMap precision / recall against the voxels that hold a noise-free beam hit (the true
//    geometry the sensor saw);
//  - CPU time per scan and per image of each core.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <unordered_map>
#include <unordered_set>

#include "colouring_pipeline.hpp"
#include "livo/command_line.hpp"
#include "octomap_builder.hpp"
#include "simulation_setup.hpp"
#include "simulator.hpp"

using namespace livo;

namespace {

uint64_t voxelKey(const Eigen::Vector3d& p, double res) {
  auto k = [res](double v) { return static_cast<uint64_t>(static_cast<int64_t>(std::floor(v / res)) + (1 << 20)) & 0x1FFFFF; };
  return (k(p.x()) << 42) | (k(p.y()) << 21) | k(p.z());
}
uint64_t bitsOf(const Eigen::Vector3f& p) {
  uint32_t a, b, c;
  std::memcpy(&a, &p.x(), 4), std::memcpy(&b, &p.y(), 4), std::memcpy(&c, &p.z(), 4);
  return (uint64_t(a) * 0x9E3779B97F4A7C15ull) ^ (uint64_t(b) * 0xC2B2AE3D27D4EB4Full) ^ c;
}
double cpuSeconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

class BarSink : public sim::SensorDataSink {
 public:
  BarSink(const sim::SimulationSetup& setup, const colour::ColourOptions& co, const octomap_export::OctomapOptions& oo)
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
    colour::ScanView cv;
    cv.utime = end;
    cv.cloud_utime = s.utime;
    cv.T_W_I = T_end;
    cv.num_points = static_cast<int>(s.size());
    cv.x = x.data(), cv.y = y.data(), cv.z = z.data(), cv.time_offset = s.time_offset.data();
    const size_t before = colour_.map().size();
    std::string error;
    double c0 = cpuSeconds();
    colour_.addScan(cv, &error);
    colour_cpu_ += cpuSeconds() - c0;
    for (size_t id = before; id < colour_.map().size(); ++id) {
      const Eigen::Vector3f& p = colour_.map().point(id).position;
      auto it = origin_of.find(bitsOf(p));
      if (it != origin_of.end()) truth_[id] = trueColour(it->second, p.cast<double>());
    }
    octomap_export::RegisteredScanView ov;
    ov.utime = end;
    ov.cloud_utime = s.utime;
    ov.T_W_I = T_end;
    ov.num_points = cv.num_points;
    ov.x = x.data(), ov.y = y.data(), ov.z = z.data(), ov.time_offset = s.time_offset.data();
    c0 = cpuSeconds();
    octo_.addScan(ov, &error);
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
    for (const auto& [id, truth] : truth_) {
      const colour::MapPoint& p = colour_.map().point(id);
      if (!p.coloured()) continue;
      err += (p.colour - truth).cwiseAbs().mean();
      ++n;
      occluded += occluded_.count(id);
    }
    const auto occupied = octo_.map().occupiedVoxels();
    size_t tp = 0;
    std::unordered_set<uint64_t> occupied_keys;
    for (const Eigen::Vector3d& c : occupied) {
      const uint64_t k = voxelKey(c, res_);
      occupied_keys.insert(k);
      tp += truth_voxels_.count(k);
    }
    size_t found = 0;
    for (uint64_t k : truth_voxels_) found += occupied_keys.count(k);
    const auto& st = colour_.stats();
    std::printf("scans %lld, images %lld (without pose %lld), map points %zu, coloured %zu (with truth %zu)\n",
                (long long)scans_, (long long)st.images, (long long)st.images_without_pose, colour_.map().size(),
                colour_.map().colouredCount(), n);
    std::printf("colour: mean error %.2f/255 (bar < 10), occluder-coloured points %.3f %% (bar < 1 %%), "
                "samples accepted %lld, occluded %lld, outliers %lld, gain estimates %lld\n",
                n ? err / n : 0.0, n ? 100.0 * occluded / n : 0.0, (long long)st.accepted, (long long)st.occluded,
                (long long)st.outliers, (long long)st.gain_estimates);
    std::printf("octomap: occupied voxels %zu, truth voxels %zu, precision %.4f, recall %.4f (bars >= 0.9)\n",
                occupied.size(), truth_voxels_.size(), occupied.empty() ? 0.0 : double(tp) / occupied.size(),
                truth_voxels_.empty() ? 0.0 : double(found) / truth_voxels_.size());
    std::printf("cpu: colour %.2f ms per scan+2 images (%.1f %% of one core at 10 Hz), octomap %.2f ms per scan\n",
                scans_ ? 1e3 * colour_cpu_ / scans_ : 0.0, scans_ ? 100.0 * colour_cpu_ / (scans_ * 0.1) : 0.0,
                scans_ ? 1e3 * octo_cpu_ / scans_ : 0.0);
  }

 private:
  Eigen::Vector3f trueColour(const Eigen::Vector3d& origin, const Eigen::Vector3d& p) const {
    sim::Ray ray;
    ray.origin = origin;
    const double d = (p - origin).norm();
    ray.direction = (p - origin) / d;
    const sim::RayHit hit = setup_.scene->cast(ray);
    if (!hit.valid()) return Eigen::Vector3f::Constant(-1000.f);
    const sim::SurfacePoint sp = setup_.scene->surface(ray, hit);
    const sim::Scene& scene = *setup_.scene;
    const double light = scene.lighting.ambient + scene.lighting.diffuse * std::max(0.0, -sp.normal.dot(scene.lighting.direction));
    const double footprint = hit.t / setup_.rig.camera->fx;
    const sim::Texture& tex = scene.texture(scene.material(hit.object).texture);
    const double gain = 255.0 * setup_.options.camera.brightness * light;
    if (!setup_.rig.camera->color) return Eigen::Vector3f::Constant(float(gain * tex.sampleLuminance(sp.u, sp.v, footprint)));
    return tex.sample(sp.u, sp.v, footprint) * float(gain);
  }

  const sim::SimulationSetup& setup_;
  colour::ColouringPipeline colour_;
  octomap_export::OctomapBuilder octo_;
  double res_;
  std::unordered_map<uint32_t, Eigen::Vector3f> truth_;
  std::unordered_set<uint32_t> occluded_;
  std::unordered_set<uint64_t> truth_voxels_;
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
    colour::ColourOptions co;  // the bar's photometric calibration: the simulator's camera model
    co.vignetting = setup.options.camera.vignetting;
    co.reference_exposure_s = setup.options.camera.exposure_time;
    octomap_export::OctomapOptions oo;
    oo.resolution = 0.1;
    oo.max_range = setup.rig.lidar->max_range;
    colour::printColourOptions(co, std::cout);
    octomap_export::printOctomapOptions(oo, std::cout);
    BarSink sink(setup, co, oo);
    sim::Simulator(setup).run(sink);
    sink.report();
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "map-bars: " << e.what() << std::endl;
    return 1;
  }
}
