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
#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <iostream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "livo/command_line.hpp"
#include "livo/config.hpp"
#include "livo/latency_stats.hpp"
#include "livo/lio/lio_config.hpp"
#include "livo/lio/lio_estimator.hpp"
#include "livo/lio/lio_messages.hpp"
#include "livo/point_cloud_t.hpp"
#include "simulation_setup.hpp"
#include "simulator.hpp"
#include "umeyama.hpp"

namespace {

using livo::Pose3;
using livo::Vec3;
using livo::lio::LioEstimator;
using livo::lio::ScanResult;

double heapInUseMb() {
  const struct mallinfo2 mi = mallinfo2();
  return static_cast<double>(mi.uordblks + mi.hblkhd) / (1024.0 * 1024.0);
}

/// One line of the periodic report.
struct Sample {
  double sim_s = 0.0;
  double rss_mb = 0.0, peak_mb = 0.0, heap_mb = 0.0;
  size_t voxels = 0, map_points = 0, keyframes = 0, keyframe_points = 0;
  int64_t sweeps = 0;
  double median_ms = 0.0, p90_ms = 0.0;
  double position_error = 0.0;
};

/// The simulator's sink: feeds the LIO in time order, like the livo-lio node's watermarks (a sweep
/// waits until the filter has an IMU sample, and with wheels a wheel reading, past its end).
class LioFeeder : public livo::sim::SensorDataSink {
 public:
  /// Sweeps starting in [outage_begin, outage_end) (sim seconds) are not fed: a LiDAR outage.
  LioFeeder(const livo::sim::SimulationSetup& setup, const livo::lio::LioNodeOptions& options, size_t expected_sweeps,
            double outage_begin = 0.0, double outage_end = 0.0)
      : setup_(setup),
        wheel_enabled_(options.lio.wheel.enabled),
        lio_(options.lio),
        outage_begin_(setup.start_utime + static_cast<int64_t>(std::llround(outage_begin * 1e6))),
        outage_end_(setup.start_utime + static_cast<int64_t>(std::llround(outage_end * 1e6))) {
    est_.reserve(expected_sweeps);  // reserved up front: the ATE record must not look like a leak
    gt_.reserve(expected_sweeps);
  }

  void write(const livo::sim::ImuReading& m) override {
    livo::lio::ImuSample s;
    s.utime = m.utime;
    s.gyro = m.angular_velocity;
    s.accel = m.linear_acceleration;
    std::string why;
    if (!lio_.addImu(s, &why)) ++refused_imu_;
    newest_imu_ = m.utime;
    processReady();
  }
  void write(const livo::sim::WheelReading& m) override {
    if (!wheel_enabled_) return;  // the node does not subscribe to WHEEL then
    livo::lio::WheelSample w;
    w.utime = m.utime;
    w.left_speed = m.left_speed;
    w.right_speed = m.right_speed;
    lio_.addWheel(w);
    newest_wheel_ = m.utime;
    processReady();
  }
  void write(const livo::sim::PoseReading&) override {}  // ground truth is read from the trajectory
  void write(const livo::sim::CameraImage&) override {}
  void write(const livo::sim::LidarSweep& m) override {
    if (m.utime >= outage_begin_ && m.utime < outage_end_) return;
    // the node's own conversion: the point_cloud_t the sim's LogWriter would have written
    livo::point_cloud_t msg;
    msg.utime = m.utime;
    msg.frame = "L";
    msg.pattern = m.solid_state ? livo::point_cloud_t::PATTERN_SOLID_STATE : livo::point_cloud_t::PATTERN_SPINNING;
    msg.num_rings = static_cast<int16_t>(m.num_rings);
    msg.sweep_duration = static_cast<float>(m.duration);
    msg.num_points = static_cast<int32_t>(m.size());
    msg.x = m.x;
    msg.y = m.y;
    msg.z = m.z;
    msg.intensity = m.intensity;
    msg.time_offset = m.time_offset;
    msg.ring = m.ring;
    livo::lio::LidarScan scan;
    std::string why;
    if (!livo::lio::fromMessage(msg, &scan, &why)) throw std::runtime_error("sweep conversion: " + why);
    pending_.push_back(std::move(scan));
    processReady();
  }

  const LioEstimator& lio() const { return lio_; }
  int64_t sweeps() const { return sweeps_; }
  int64_t resets() const { return resets_; }
  int64_t refusedImu() const { return refused_imu_; }
  int64_t count(ScanResult::Status s) const { return status_count_[static_cast<int>(s)]; }
  double lastPositionError() const { return last_error_; }
  int64_t lastUtime() const { return last_utime_; }
  const std::vector<Vec3>& estimated() const { return est_; }
  const std::vector<Vec3>& groundTruth() const { return gt_; }

  /// Per-sweep time statistics since the last call.
  livo::LatencyStats takePeriodStats() {
    livo::LatencyStats s = period_;
    period_ = livo::LatencyStats();
    return s;
  }
  const livo::LatencyStats& totalStats() const { return total_; }

 private:
  void processReady() {
    while (!pending_.empty()) {
      const int64_t t_end = lio_.scanEndUtime(pending_.front());
      if (newest_imu_ <= t_end) return;
      if (wheel_enabled_ && newest_wheel_ <= t_end) return;
      process(pending_.front());
      pending_.pop_front();
    }
  }

  void process(const livo::lio::LidarScan& scan) {
    const bool was_initialized = lio_.initialized();
    const auto t0 = std::chrono::steady_clock::now();
    const ScanResult r = lio_.addScan(scan);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++status_count_[static_cast<int>(r.status)];
    if (was_initialized && !lio_.initialized()) {
      ++resets_;
      std::cerr << "livo_lio_soak: the LIO re-initialised at sweep " << sweeps_ << ": " << r.message << "\n";
    }
    if (!r.hasOutput()) return;
    ++sweeps_;
    period_.add(s);
    total_.add(s);
    const Pose3 truth = setup_.trajectory->at(setup_.trajectoryTime(r.utime)).T_W_I;
    // the LIO's world frame is its own (gravity-aligned, yaw and origin arbitrary): the running
    // error is taken after aligning the first output pose with the truth
    if (est_.empty()) T_truth_est_ = truth * r.state.pose().inverse();
    est_.push_back(r.state.pos);
    gt_.push_back(truth.translation());
    last_error_ = (T_truth_est_ * r.state.pos - truth.translation()).norm();
    last_utime_ = r.utime;
  }

  const livo::sim::SimulationSetup& setup_;
  const bool wheel_enabled_;
  LioEstimator lio_;
  const int64_t outage_begin_, outage_end_;
  std::deque<livo::lio::LidarScan> pending_;
  int64_t newest_imu_ = std::numeric_limits<int64_t>::min();
  int64_t newest_wheel_ = std::numeric_limits<int64_t>::min();
  int64_t sweeps_ = 0, resets_ = 0, refused_imu_ = 0;
  int64_t status_count_[5] = {0, 0, 0, 0, 0};
  livo::LatencyStats period_, total_;
  std::vector<Vec3> est_, gt_;
  Pose3 T_truth_est_ = Pose3::Identity();
  double last_error_ = 0.0;
  int64_t last_utime_ = 0;
};

Sample takeSample(double sim_s, LioFeeder& feeder) {
  Sample s;
  s.sim_s = sim_s;
  s.rss_mb = livo::currentRssMb();
  s.peak_mb = livo::peakRssMb();
  s.heap_mb = heapInUseMb();
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
  std::printf("%8.0f %9.1f %9.1f %9.1f %8zu %9zu %5zu %9zu %7lld %8.2f %7.2f %8.3f\n", s.sim_s, s.rss_mb, s.peak_mb,
              s.heap_mb, s.voxels, s.map_points, s.keyframes, s.keyframe_points, static_cast<long long>(s.sweeps),
              s.median_ms, s.p90_ms, s.position_error);
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
    livo::sim::SimOverrides overrides;
    overrides.duration_s = cli.getDouble("--duration");
    overrides.threads = static_cast<int>(cli.getInt("--sim-threads"));
    if (cli.has("--seed")) overrides.seed = static_cast<uint64_t>(cli.getInt("--seed"));
    const double report_every = cli.getDouble("--report-every");
    const double early = cli.getDouble("--early");
    double outage_begin = 0.0, outage_end = 0.0;
    if (cli.has("--lidar-outage")) {
      const std::string v = cli.get("--lidar-outage");
      const size_t comma = v.find(',');
      if (comma == std::string::npos) throw std::invalid_argument("--lidar-outage takes S,D");
      outage_begin = std::stod(v.substr(0, comma));
      outage_end = outage_begin + std::stod(v.substr(comma + 1));
    }
    if (!(report_every > 0.0)) throw std::invalid_argument("--report-every must be > 0");

    const std::string config_file = cli.get("--config");
    livo::sim::SimulationSetup setup = livo::sim::loadSimulation(config_file, overrides);
    if (!setup.rig.lidar) throw std::invalid_argument(config_file + ": the rig has no LiDAR");
    if (!std::isinf(setup.trajectory->duration()) && setup.trajectory->duration() < setup.options.duration_s)
      throw std::invalid_argument(config_file + ": the trajectory ends before --duration");
    setup.rig.camera.reset();  // no rendering: the LIO does not use images
    const livo::lio::LioNodeOptions options = livo::lio::readLioNodeOptions(livo::Config::load(config_file));

    std::cerr << "livo_lio_soak: " << config_file << ", " << setup.options.duration_s << " s, "
              << setup.trajectory_description << "\n";
    livo::lio::printOptions(options, std::cerr);
    std::cerr << "  max stored keyframes " << options.lio.max_stored_keyframes << "\n";

    const size_t expected_sweeps =
        static_cast<size_t>(std::ceil(setup.options.duration_s * setup.rig.lidar->rate_hz)) + 16;
    LioFeeder feeder(setup, options, expected_sweeps, outage_begin, outage_end);
    std::vector<Sample> samples;
    samples.reserve(static_cast<size_t>(setup.options.duration_s / report_every) + 4);
    printHeader();
    double next_report = report_every;
    livo::sim::Simulator simulator(setup);
    const auto stats = simulator.run(feeder, [&](double done, double total, const livo::sim::SimulationStats&) {
      if (done + 1e-9 < next_report && done < total) return;
      if (!samples.empty() && done <= samples.back().sim_s + 1e-9) return;  // the sim's closing chunk
      samples.push_back(takeSample(done, feeder));
      printSample(samples.back());
      while (next_report <= done + 1e-9) next_report += report_every;
    });

    // the figures of the bar: the sample at (or first after) `early` seconds and the last one
    const Sample* at_early = nullptr;
    for (const auto& s : samples)
      if (s.sim_s + 1e-9 >= early) {
        at_early = &s;
        break;
      }
    const Sample& last = samples.back();
    std::printf("\nsimulated %.0f s in %.0f s wall; %lld sweeps with output (%lld tracked, %lld predicted, %lld "
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
      std::printf("RSS  at %.0f s: %.1f MB, at %.0f s: %.1f MB, ratio %.3f\n", at_early->sim_s, at_early->rss_mb,
                  last.sim_s, last.rss_mb, last.rss_mb / at_early->rss_mb);
      std::printf("peak at %.0f s: %.1f MB, at %.0f s: %.1f MB, ratio %.3f (bar: <= 1.20)\n", at_early->sim_s,
                  at_early->peak_mb, last.sim_s, last.peak_mb, last.peak_mb / at_early->peak_mb);
      std::printf("heap at %.0f s: %.1f MB, at %.0f s: %.1f MB, ratio %.3f\n", at_early->sim_s, at_early->heap_mb,
                  last.sim_s, last.heap_mb, last.heap_mb / at_early->heap_mb);
    } else {
      std::printf("the run is shorter than --early (%.0f s): no ratio\n", early);
    }
    const auto& est = feeder.estimated();
    const auto& gt = feeder.groundTruth();
    if (est.size() >= 3) {
      const auto align = livo::evaluation::umeyamaAlignment(est, gt, false);
      double sq = 0.0;
      for (size_t i = 0; i < est.size(); ++i) sq += (align.apply(est[i]) - gt[i]).squaredNorm();
      std::printf("ATE (SE(3)-aligned position RMSE over %zu sweeps): %.3f m; final position error (first pose aligned): %.3f m\n",
                  est.size(), std::sqrt(sq / static_cast<double>(est.size())), feeder.lastPositionError());
    }
  } catch (const std::exception& e) {
    std::cerr << "livo_lio_soak: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
