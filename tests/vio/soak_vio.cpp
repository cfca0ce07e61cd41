// livo_vio_soak: memory of the LIO + VIO over a long run (issue 7: "memory of the point-patch map
// bounded on a 30-minute run"), the LIVO counterpart of livo_lio_soak (tests/lio/soak_lio.cpp,
// whose driver it shares: tests/sim_soak.hpp). The simulator (livo_sim) runs in this process and
// its IMU, wheel, LiDAR and camera data go straight into a LioEstimator and a VioEstimator composed
// exactly as the livo-lio and livo-vio nodes compose them over LCM, with no LCM at all:
//   - sweeps and image times in time order (the earlier of the next image time and the next sweep
//     end first, each once IMU past it has been added: livo-lio's advance());
//   - a sweep with output: its registered world points (toRegisteredScan, checked with
//     registeredScanProblem, as floats) go to VioEstimator::addScan (REGISTERED_SCAN);
//   - an image time while the LIO tracks: propagateTo, the prior as a filter_state_t (STATE_PRIOR),
//     the image decoded to grey and checked as livo-vio does, processImage, the answer as
//     livo-vio's STATE_POSTERIOR (valid or the prior kept) and adoptPosterior if valid.
// The sim's procedural trajectories never end (the car drives the closed campus loop lap after
// lap), so --duration 1800 on config/sim/campus_loop.yaml (VLP-16, 640x480 camera) is 30 minutes.
//
// Rendering costs about 36 ms of CPU per 640x480 image; --camera-rate (default 10 Hz, the rig's
// rate in campus_loop.yaml) sets the simulated camera's rate to keep a run affordable: 30 minutes
// at 10 Hz is 18,000 renders, about 11 minutes of CPU for the images alone.
//
// Every `--report-every` simulated seconds it prints sim time, VmRSS, VmHWM, the heap in use
// (mallinfo2), the VIO map (points, stored patches, its own byte estimate), the LIO map (voxels)
// and stored keyframes, the images handed off in the period, the median processImage and
// per-sweep times of the period, the fraction of the period's priors the VIO updated (valid) and
// the position error against the exact ground truth (first output pose aligned). At the end: RSS,
// peak and heap at 5 min and at the end and their ratios, the hand-off counts and the ATE
// (SE(3) Umeyama alignment) of the per-sweep output.
//
//   build/bin/livo_vio_soak --config config/sim/campus_loop.yaml --duration 1800 --camera-rate 10
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "livo/command_line.hpp"
#include "livo/config.hpp"
#include "livo/filter_state_message.hpp"
#include "livo/latency_stats.hpp"
#include "livo/lio/lio_config.hpp"
#include "livo/lio/lio_estimator.hpp"
#include "livo/lio/lio_messages.hpp"
#include "livo/message_checks.hpp"
#include "livo/messages.hpp"
#include "livo/time.hpp"
#include "livo/vio/grey_image.hpp"
#include "livo/vio/vio_config.hpp"
#include "livo/vio/vio_estimator.hpp"
#include "livo/vio/vio_messages.hpp"
#include "sim_soak.hpp"

namespace {

using livo::filter_state_t;
using livo::lio::ScanResult;
using livo::vio::VioEstimator;

/// LIO and VIO in one process, wired as the two nodes are (see the file comment).
class LivoDriver : public livo_soak::SimLioDriver {
 public:
  LivoDriver(const livo::sim::SimulationSetup& setup, const livo::lio::LioNodeOptions& lio_options,
             const livo::vio::VioNodeOptions& vio_options, const Options& o)
      : SimLioDriver(setup, lio_options.core, o),
        lio_name_(lio_options.name),
        vio_opts_(vio_options),
        vio_(vio_options.core, vio_options.camera),
        vio_offset_us_(livo::toUtime(vio_options.camera_time_offset_s)),
        tolerance_us_(livo::toUtime(vio_options.time_tolerance_s)) {}

  const VioEstimator& vio() const { return vio_; }
  int64_t priors() const { return priors_; }
  int64_t adopted() const { return adopted_; }
  int64_t vioUpdated() const { return vio_updated_; }
  int64_t scansRefused() const { return scans_refused_; }
  const std::map<std::string, int64_t>& keptReasons() const { return kept_reasons_; }
  const livo::LatencyStats& imageStats() const { return image_total_; }
  const livo::LatencyStats& vioScanStats() const { return vio_scan_total_; }

  struct Period {
    livo::LatencyStats image;
    int64_t priors = 0, adopted = 0;
  };
  Period takePeriod() { return std::exchange(period_, Period()); }

 protected:
  // livo-lio publishes REGISTERED_SCAN; livo-vio's onScan
  void onSweep(const ScanResult& r, const livo::point_cloud_t& msg) override {
    const livo::registered_scan_t m = livo::lio::toRegisteredScan(r, msg, mutableLio().frame());
    if (!livo::registeredScanProblem(m).empty()) {
      ++scans_refused_;
      return;
    }
    const livo::point_cloud_t& c = m.cloud;
    const auto t0 = std::chrono::steady_clock::now();
    vio_.addScan(m.utime, c.x.data(), c.y.data(), c.z.data(), static_cast<size_t>(c.num_points));
    vio_scan_total_.add(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }

  // livo-lio's handOff and onPosterior around livo-vio's answer
  void handOff(int64_t t, const livo::sim::CameraImage& image) override {
    livo::lio::LioEstimator& lio = mutableLio();
    std::string note;
    if (!lio.propagateTo(t, &note)) {
      resetAll("propagation to the image time failed" + (note.empty() ? std::string() : " (" + note + ")"));
      return;
    }
    // with the body rate at the image (the camera's time shift and a rolling shutter need it)
    const filter_state_t prior =
        livo::toFilterState(t, lio.state(), lio.covariance(), next_request_id_++, lio_name_, lio.bodyRate());
    ++priors_;
    ++period_.priors;
    const filter_state_t posterior = answer(prior, image);
    livo::FilterState x;
    livo::StateCovariance P;
    std::string why;
    if (posterior.valid && livo::fromFilterState(posterior, &x, &P) &&
        lio.adoptPosterior(posterior.utime, x, P, &why)) {
      ++adopted_;
      ++period_.adopted;
    } else if (posterior.valid) {
      ++kept_reasons_["posterior refused by the LIO: " + why];
    }
  }

 private:
  // livo-vio: the image at the prior's time (onImage's decoding and checks), then process() / keep()
  filter_state_t answer(const filter_state_t& prior, const livo::sim::CameraImage& c) {
    livo::RawImage raw;
    raw.utime = c.utime;
    raw.width = c.width;
    raw.height = c.height;
    raw.row_stride = c.width * (c.color ? 3 : 1);
    raw.encoding = static_cast<int>(c.color ? livo::ImageEncoding::kRgb8 : livo::ImageEncoding::kGray8);
    raw.exposure_time = c.exposure_time;
    raw.data = c.data.data();
    raw.size = c.data.size();
    livo::vio::GreyImage grey;
    std::string problem;
    if (!livo::vio::readGreyImage(raw, vio_opts_.camera.width, vio_opts_.camera.height, vio_opts_.image_check, &grey,
                                  &problem))
      return keep(prior, "bad image at the prior's time: " + problem);
    grey.utime = c.utime + vio_offset_us_;
    if (std::llabs(grey.utime - prior.utime) > tolerance_us_) return keep(prior, "no image at the prior's time");
    livo::FilterState x;
    livo::StateCovariance P;
    std::string why;
    if (!livo::vio::priorFromMessage(prior, &x, &P, &why)) return keep(prior, why);
    const auto t0 = std::chrono::steady_clock::now();
    const livo::vio::ImageResult r = vio_.processImage(grey, x, P, livo::vec3From(prior.angular_velocity));
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    period_.image.add(s);
    image_total_.add(s);
    if (!r.valid) return keep(prior, r.why);
    ++vio_updated_;
    return livo::vio::toPosterior(prior, vio_opts_.name, r.state, r.covariance, true, r.iterations, r.num_measurements);
  }

  filter_state_t keep(const filter_state_t& prior, const std::string& why) {
    ++kept_reasons_[why.substr(0, why.find(" ("))];  // grouped like VioNode::keptReasons
    return livo::vio::keptPrior(prior, vio_opts_.name);
  }

  const std::string lio_name_;
  const livo::vio::VioNodeOptions vio_opts_;
  VioEstimator vio_;
  const int64_t vio_offset_us_, tolerance_us_;
  int64_t next_request_id_ = 0;
  int64_t priors_ = 0, adopted_ = 0, vio_updated_ = 0, scans_refused_ = 0;
  std::map<std::string, int64_t> kept_reasons_;
  Period period_;
  livo::LatencyStats image_total_, vio_scan_total_;
};

/// One line of the periodic report.
struct Sample {
  double sim_s = 0.0;
  livo_soak::Memory mem;
  size_t vio_points = 0, vio_patches = 0;
  double vio_map_mb = 0.0;
  size_t recent_scan_points = 0;
  size_t voxels = 0, keyframes = 0;
  int64_t images = 0, sweeps = 0;
  double image_ms = 0.0, sweep_ms = 0.0;
  double valid_fraction = 0.0;
  double position_error = 0.0;
};

Sample takeSample(double sim_s, LivoDriver& d) {
  Sample s;
  s.sim_s = sim_s;
  s.mem = livo_soak::memoryNow();
  s.vio_points = d.vio().map().size();
  s.vio_patches = d.vio().map().observationCount();
  s.vio_map_mb = static_cast<double>(d.vio().map().memoryBytes()) / (1024.0 * 1024.0);
  s.recent_scan_points = d.vio().recentScanPoints();
  s.voxels = d.lio().map().numVoxels();
  s.keyframes = d.lio().keyframes().size();
  const LivoDriver::Period p = d.takePeriod();
  const livo::LatencyStats sweeps = d.takePeriodStats();
  s.images = p.priors;
  s.sweeps = sweeps.count();
  s.image_ms = p.image.medianMs();
  s.sweep_ms = sweeps.medianMs();
  s.valid_fraction = p.priors > 0 ? static_cast<double>(p.adopted) / static_cast<double>(p.priors) : 0.0;
  s.position_error = d.lastPositionError();
  return s;
}

void printHeader() {
  std::printf("%6s %7s %7s %7s %7s %7s %6s %6s %7s %4s %5s %6s %6s %5s %6s\n", "sim_s", "rss_mb", "peak_mb", "heap_mb",
              "vio_pts", "patches", "vio_mb", "scan_p", "voxels", "kfs", "imgs", "img_ms", "swp_ms", "valid", "err_m");
}

void printSample(const Sample& s) {
  std::printf("%6.0f %7.1f %7.1f %7.1f %7zu %7zu %6.1f %6zu %7zu %4zu %5lld %6.2f %6.2f %5.3f %6.3f\n", s.sim_s,
              s.mem.rss_mb, s.mem.peak_mb, s.mem.heap_mb, s.vio_points, s.vio_patches, s.vio_map_mb,
              s.recent_scan_points, s.voxels, s.keyframes, static_cast<long long>(s.images), s.image_ms, s.sweep_ms,
              s.valid_fraction, s.position_error);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  livo::CommandLine cli("livo_vio_soak",
                        "Drives the simulator straight into the LIO and VIO estimators, composed as the livo-lio and "
                        "livo-vio nodes are, for a long run and reports memory (VmRSS, VmHWM, heap), the point-patch "
                        "and LIO map sizes, per-image and per-sweep time, the valid-update fraction and the position "
                        "error every period.");
  cli.option("--config", "FILE", "sim config with rig: (with a camera), sim: and optional lio:, vio: sections",
             std::string(LIVO_SOURCE_DIR) + "/config/sim/campus_loop.yaml")
      .option("--duration", "S", "simulated seconds", "1800")
      .option("--camera-rate", "HZ", "simulated camera rate (rendering costs ~36 ms CPU per 640x480 image)", "10")
      .option("--report-every", "S", "simulated seconds between report lines", "60")
      .option("--early", "S", "the early reference point of the flatness ratio (the 5th minute)", "300")
      .option("--seed", "N", "random seed (default: sim.seed)")
      .option("--sim-threads", "N", "simulator worker threads", "1");
  if (!cli.parse(argc, argv)) return cli.exitCode();
  try {
    const double early = cli.getDouble("--early");
    const double camera_rate = cli.getDouble("--camera-rate");
    if (!(camera_rate > 0.0 && camera_rate <= 100.0)) throw std::invalid_argument("--camera-rate must be in (0, 100]");
    livo_soak::PeriodicReport report(cli.getDouble("--report-every"));

    const std::string config_file = cli.get("--config");
    livo::sim::SimulationSetup setup = livo_soak::loadLongRun(
        config_file, cli.getDouble("--duration"),
        cli.has("--seed") ? std::optional<uint64_t>(static_cast<uint64_t>(cli.getInt("--seed"))) : std::nullopt,
        static_cast<int>(cli.getInt("--sim-threads")));
    if (!setup.rig.camera) throw std::invalid_argument(config_file + ": the rig has no camera");
    const double config_camera_rate = setup.rig.camera->rate_hz;
    setup.rig.camera->rate_hz = camera_rate;
    const livo::Config config = livo::Config::load(config_file);
    const livo::lio::LioNodeOptions lio_options = livo::lio::readLioNodeOptions(config);
    const livo::vio::VioNodeOptions vio_options = livo::vio::readVioNodeOptions(config);

    std::cerr << "livo_vio_soak: " << config_file << ", " << setup.options.duration_s << " s, "
              << setup.trajectory_description << "\n"
              << "  camera " << setup.rig.camera->width << "x" << setup.rig.camera->height << " at " << camera_rate
              << " Hz (the config says " << config_camera_rate << " Hz); hand-off at every image"
              << (lio_options.camera_handoff ? "" : " (lio.camera_handoff is off in the config: forced on here)")
              << "\n";
    livo::lio::printOptions(lio_options, std::cerr);
    livo::vio::printOptions(vio_options, std::cerr);

    LivoDriver::Options driver;
    driver.expected_sweeps = static_cast<size_t>(std::ceil(setup.options.duration_s * setup.rig.lidar->rate_hz)) + 16;
    driver.images = true;
    driver.camera_offset_us = livo::toUtime(lio_options.camera_time_offset_s);
    LivoDriver livo_driver(setup, lio_options, vio_options, driver);
    std::vector<Sample> samples;
    samples.reserve(static_cast<size_t>(setup.options.duration_s / cli.getDouble("--report-every")) + 4);
    std::printf("camera rate %.3g Hz\n", camera_rate);
    printHeader();
    livo::sim::Simulator simulator(setup);
    const auto stats = simulator.run(livo_driver, [&](double done, double total, const livo::sim::SimulationStats&) {
      if (!report.due(done, total)) return;
      samples.push_back(takeSample(done, livo_driver));
      printSample(samples.back());
    });

    const Sample* at_early = livo_soak::sampleAtOrAfter(samples, early);
    const Sample& last = samples.back();
    std::printf(
        "\nsimulated %.0f s in %.0f s wall, camera at %.3g Hz; %lld sweeps with output (%lld tracked, %lld "
        "predicted, %lld rejected, %lld initialising); %lld re-initialisations; %lld IMU samples refused\n",
        stats.sim_seconds, stats.wall_seconds, camera_rate, static_cast<long long>(livo_driver.sweeps()),
        static_cast<long long>(livo_driver.count(ScanResult::Status::kTracked)),
        static_cast<long long>(livo_driver.count(ScanResult::Status::kPredicted)),
        static_cast<long long>(livo_driver.count(ScanResult::Status::kRejected)),
        static_cast<long long>(livo_driver.count(ScanResult::Status::kInitializing)),
        static_cast<long long>(livo_driver.resets()), static_cast<long long>(livo_driver.refusedImu()));
    const int64_t priors = livo_driver.priors();
    std::printf(
        "images: %lld handed off (priors), %lld updated by the VIO, %lld adopted by the LIO (%.1f %%), %lld "
        "skipped (LIO not tracking or past them); %lld registered scans refused\n",
        static_cast<long long>(priors), static_cast<long long>(livo_driver.vioUpdated()),
        static_cast<long long>(livo_driver.adopted()),
        priors > 0 ? 100.0 * static_cast<double>(livo_driver.adopted()) / static_cast<double>(priors) : 0.0,
        static_cast<long long>(livo_driver.imagesSkipped()), static_cast<long long>(livo_driver.scansRefused()));
    for (const auto& [why, n] : livo_driver.keptReasons())
      std::printf("  prior kept %lld times: %s\n", static_cast<long long>(n), why.c_str());
    std::printf("per image (processImage): median %.2f ms, p90 %.2f ms, max %.2f ms\n",
                livo_driver.imageStats().medianMs(), livo_driver.imageStats().p90Ms(),
                livo_driver.imageStats().maxMs());
    std::printf("per sweep (LIO addScan): median %.2f ms, p90 %.2f ms, max %.2f ms; VIO addScan: median %.2f ms\n",
                livo_driver.totalStats().medianMs(), livo_driver.totalStats().p90Ms(), livo_driver.totalStats().maxMs(),
                livo_driver.vioScanStats().medianMs());
    if (at_early && at_early != &last) {
      livo_soak::printMemoryRatios(at_early->sim_s, at_early->mem, last.sim_s, last.mem);
      std::printf("VIO map at %.0f s: %zu points, %zu patches, %.1f MB; at %.0f s: %zu points, %zu patches, %.1f MB\n",
                  at_early->sim_s, at_early->vio_points, at_early->vio_patches, at_early->vio_map_mb, last.sim_s,
                  last.vio_points, last.vio_patches, last.vio_map_mb);
    } else {
      std::printf("the run is shorter than --early (%.0f s): no ratio\n", early);
    }
    if (livo_driver.estimated().size() >= 3) {
      std::printf(
          "ATE (SE(3)-aligned position RMSE over %zu sweeps): %.3f m; final position error (first pose aligned): %.3f "
          "m\n",
          livo_driver.estimated().size(), livo_soak::ateRmse(livo_driver.estimated(), livo_driver.groundTruth()),
          livo_driver.lastPositionError());
    }
  } catch (const std::exception& e) {
    std::cerr << "livo_vio_soak: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
