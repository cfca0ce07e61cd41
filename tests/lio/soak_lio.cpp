// livo_lio_soak: memory of the LIO over a long run (issue 6: "peak RSS flat, within 20 %, between
// the 5th and the 30th minute of a 30-minute run"). A 30-minute log would be several GB, so the
// simulator (livo_sim) is driven in this process and its IMU, wheel and LiDAR data go straight
// into a LioEstimator: no LCM, no log file, no camera rendering. The sim's procedural trajectories
// (handheld, car, uav) never end (car and handheld paths are closed B-spline loops driven lap after
// lap), so any duration works; config/sim/campus_loop_long.yaml is the campus loop for 30 minutes.
//
// Every `--report-every` simulated seconds it prints sim time, VmRSS, VmHWM, the heap in use
// (mallinfo2, to tell live data from allocator slack), the LIO's map (voxels, points), stored
// keyframes and their points, the median per-sweep time of the period and the position error
// against the simulator's exact ground truth (first output pose aligned with the truth: the LIO's
// world frame has its own origin and yaw). At the end: RSS and peak at 5 min and at the end,
// their ratios, and the ATE (position RMSE after SE(3) Umeyama alignment) of the whole run.
//
//   build/bin/livo_lio_soak --config config/sim/campus_loop_long.yaml --duration 1800
//   build/bin/livo_lio_soak --duration 900 --lidar-outage 120,600   # no sweeps for 10 minutes
//
// The LIO options come from the config's rig: and lio: sections, as livo-lio reads them; a sweep is
// processed once IMU (and, with a wheel, wheel data) past its end has been added, as the node does.
// Measured memory is the whole process: the simulator's scene is built once and stays constant.
// The driver, memory figures and end-of-run figures are shared with livo_vio_soak (tests/sim_soak.hpp).
#include <cmath>
#include <cstdio>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "livo/command_line.hpp"
#include "livo/config.hpp"
#include "livo/latency_stats.hpp"
#include "livo/lio/lio_config.hpp"
#include "livo/lio/lio_estimator.hpp"
#include "sim_soak.hpp"

namespace {

using livo::lio::LioEstimator;
using livo::lio::ScanResult;
using livo_soak::SimLioDriver;

/// One line of the periodic report.
struct Sample {
  double sim_s = 0.0;
  livo_soak::Memory mem;
  size_t voxels = 0, map_points = 0, keyframes = 0, keyframe_points = 0;
  int64_t sweeps = 0;
  double median_ms = 0.0, p90_ms = 0.0;
  double position_error = 0.0;
};

Sample takeSample(double sim_s, SimLioDriver& feeder) {
  Sample s;
  s.sim_s = sim_s;
  s.mem = livo_soak::memoryNow();
  const LioEstimator& lio = feeder.lio();
  s.voxels = lio.map().numVoxels();
  s.map_points = lio.map().numPoints();
  s.keyframes = lio.keyframes().size();
  for (const auto& kf : lio.keyframes()) s.keyframe_points += kf.cloud.size();
  const livo::LatencyStats period = feeder.takePeriodStats();
  s.sweeps = period.count();
  s.median_ms = period.medianMs();
  s.p90_ms = period.p90Ms();
  s.position_error = feeder.lastPositionError();
  return s;
}

void printHeader() {
  std::printf("%8s %9s %9s %9s %8s %9s %5s %9s %7s %8s %7s %8s\n", "sim_s", "rss_mb", "peak_mb", "heap_mb", "voxels",
              "map_pts", "kfs", "kf_pts", "sweeps", "med_ms", "p90_ms", "err_m");
}

void printSample(const Sample& s) {
  std::printf("%8.0f %9.1f %9.1f %9.1f %8zu %9zu %5zu %9zu %7lld %8.2f %7.2f %8.3f\n", s.sim_s, s.mem.rss_mb,
              s.mem.peak_mb, s.mem.heap_mb, s.voxels, s.map_points, s.keyframes, s.keyframe_points,
              static_cast<long long>(s.sweeps), s.median_ms, s.p90_ms, s.position_error);
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  livo::CommandLine cli("livo_lio_soak",
                        "Drives the simulator straight into the LIO estimator for a long run and reports memory "
                        "(VmRSS, VmHWM), map and keyframe sizes, per-sweep time and position error every period.");
  cli.option("--config", "FILE", "sim config with rig:, sim: and optional lio: sections",
             std::string(LIVO_SOURCE_DIR) + "/config/sim/campus_loop_long.yaml")
      .option("--duration", "S", "simulated seconds", "1800")
      .option("--report-every", "S", "simulated seconds between report lines", "60")
      .option("--early", "S", "the early reference point of the flatness ratio (issue 6: the 5th minute)", "300")
      .option("--seed", "N", "random seed (default: sim.seed)")
      .option("--lidar-outage", "S,D", "feed no LiDAR sweep from S for D seconds of sim time (IMU goes on)")
      .option("--sim-threads", "N", "simulator worker threads", "1");
  if (!cli.parse(argc, argv)) return cli.exitCode();
  try {
    const double early = cli.getDouble("--early");
    double outage_begin = 0.0, outage_end = 0.0;
    if (cli.has("--lidar-outage")) {
      const std::string v = cli.get("--lidar-outage");
      const size_t comma = v.find(',');
      if (comma == std::string::npos) throw std::invalid_argument("--lidar-outage takes S,D");
      outage_begin = std::stod(v.substr(0, comma));
      outage_end = outage_begin + std::stod(v.substr(comma + 1));
    }
    livo_soak::PeriodicReport report(cli.getDouble("--report-every"));

    const std::string config_file = cli.get("--config");
    livo::sim::SimulationSetup setup = livo_soak::loadLongRun(
        config_file, cli.getDouble("--duration"),
        cli.has("--seed") ? std::optional<uint64_t>(static_cast<uint64_t>(cli.getInt("--seed"))) : std::nullopt,
        static_cast<int>(cli.getInt("--sim-threads")));
    setup.rig.camera.reset();  // no rendering: the LIO does not use images
    const livo::lio::LioNodeOptions options = livo::lio::readLioNodeOptions(livo::Config::load(config_file));

    std::cerr << "livo_lio_soak: " << config_file << ", " << setup.options.duration_s << " s, "
              << setup.trajectory_description << "\n";
    livo::lio::printOptions(options, std::cerr);
    std::cerr << "  max stored keyframes " << options.core.max_stored_keyframes << "\n";

    SimLioDriver::Options driver;
    driver.expected_sweeps = static_cast<size_t>(std::ceil(setup.options.duration_s * setup.rig.lidar->rate_hz)) + 16;
    driver.outage_begin_s = outage_begin;
    driver.outage_end_s = outage_end;
    SimLioDriver feeder(setup, options.core, driver);
    std::vector<Sample> samples;
    samples.reserve(static_cast<size_t>(setup.options.duration_s / cli.getDouble("--report-every")) + 4);
    printHeader();
    livo::sim::Simulator simulator(setup);
    const auto stats = simulator.run(feeder, [&](double done, double total, const livo::sim::SimulationStats&) {
      if (!report.due(done, total)) return;
      samples.push_back(takeSample(done, feeder));
      printSample(samples.back());
    });

    // the figures of the bar: the sample at (or first after) `early` seconds and the last one
    const Sample* at_early = livo_soak::sampleAtOrAfter(samples, early);
    const Sample& last = samples.back();
    std::printf(
        "\nsimulated %.0f s in %.0f s wall; %lld sweeps with output (%lld tracked, %lld predicted, %lld "
        "rejected, %lld initialising); %lld re-initialisations; %lld IMU samples refused\n",
        stats.sim_seconds, stats.wall_seconds, static_cast<long long>(feeder.sweeps()),
        static_cast<long long>(feeder.count(ScanResult::Status::kTracked)),
        static_cast<long long>(feeder.count(ScanResult::Status::kPredicted)),
        static_cast<long long>(feeder.count(ScanResult::Status::kRejected)),
        static_cast<long long>(feeder.count(ScanResult::Status::kInitializing)),
        static_cast<long long>(feeder.resets()), static_cast<long long>(feeder.refusedImu()));
    std::printf("per sweep: median %.2f ms, p90 %.2f ms, max %.2f ms\n", feeder.totalStats().medianMs(),
                feeder.totalStats().p90Ms(), feeder.totalStats().maxMs());
    if (at_early && at_early != &last) {
      livo_soak::printMemoryRatios(at_early->sim_s, at_early->mem, last.sim_s, last.mem);
    } else {
      std::printf("the run is shorter than --early (%.0f s): no ratio\n", early);
    }
    if (feeder.estimated().size() >= 3) {
      std::printf(
          "ATE (SE(3)-aligned position RMSE over %zu sweeps): %.3f m; final position error (first pose aligned): %.3f "
          "m\n",
          feeder.estimated().size(), livo_soak::ateRmse(feeder.estimated(), feeder.groundTruth()),
          feeder.lastPositionError());
    }
  } catch (const std::exception& e) {
    std::cerr << "livo_lio_soak: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
