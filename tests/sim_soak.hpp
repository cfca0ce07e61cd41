// Shared pieces of the long-run (soak) benchmarks tests/lio/soak_lio.cpp (livo_lio_soak, issue 6)
// and tests/vio/soak_vio.cpp (livo_vio_soak, issue 7): the simulator library (livo_sim) driven
// straight into the estimators for tens of simulated minutes, no LCM and no log file.
//
// - loadLongRun(): a sim config with its duration overridden. The sim's procedural trajectories
//   (handheld, car, uav) never end (car and handheld paths are closed B-spline loops driven lap
//   after lap), so any duration works; a recorded trajectory must last the run.
// - SimLioDriver: the simulator's sink feeding a LioEstimator in time order like the livo-lio
//   node's watermarks (a sweep is processed once IMU, and with a wheel a wheel reading, past its
//   end has been added; with image times queued, the earlier of the next image time and the next
//   sweep end goes first, an image once IMU past it has been added, as the node's camera hand-off).
//   It records per-sweep time, status counts and the trajectory against the exact ground truth.
// - memory figures (VmRSS, VmHWM, heap in use), the periodic report trigger, the 5-vs-end ratios
//   and the ATE (SE(3) Umeyama alignment) printed at the end.
#pragma once

#include <malloc.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <iostream>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "livo/evaluate/umeyama.hpp"
#include "livo/latency_stats.hpp"
#include "livo/lio/lio_estimator.hpp"
#include "livo/lio/lio_messages.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/sim/log_writer.hpp"
#include "livo/sim/simulation_setup.hpp"
#include "livo/sim/simulator.hpp"

namespace livo_soak {

/// Heap in use (mallinfo2: arena and mmapped blocks), MB: live data, as against allocator slack in RSS.
inline double heapInUseMb() {
  const struct mallinfo2 mi = mallinfo2();
  return static_cast<double>(mi.uordblks + mi.hblkhd) / (1024.0 * 1024.0);
}

struct Memory {
  double rss_mb = 0.0, peak_mb = 0.0, heap_mb = 0.0;
};

inline Memory memoryNow() {
  Memory m;
  m.rss_mb = livo::currentRssMb();
  m.peak_mb = livo::peakRssMb();
  m.heap_mb = heapInUseMb();
  return m;
}

/// `config` with its duration (and optionally seed, simulator threads) overridden; throws if the
/// rig has no LiDAR or the trajectory ends before the run does.
inline livo::sim::SimulationSetup loadLongRun(const std::string& config, double duration_s,
                                              std::optional<uint64_t> seed, int sim_threads) {
  livo::sim::SimOverrides overrides;
  overrides.duration_s = duration_s;
  overrides.threads = sim_threads;
  overrides.seed = seed;
  livo::sim::SimulationSetup setup = livo::sim::loadSimulation(config, overrides);
  if (!setup.rig.lidar) throw std::invalid_argument(config + ": the rig has no LiDAR");
  if (!std::isinf(setup.trajectory->duration()) && setup.trajectory->duration() < setup.options.duration_s)
    throw std::invalid_argument(config + ": the trajectory ends before --duration");
  return setup;
}

/// Feeds the simulator's IMU, wheel and LiDAR data (and, if enabled, image times) to a LioEstimator
/// in the order the livo-lio node would process them. Derived classes see every sweep result
/// (onSweep) and every image due for the camera hand-off (handOff).
class SimLioDriver : public livo::sim::SensorDataSink {
 public:
  struct Options {
    size_t expected_sweeps = 0;    // the trajectory record is reserved up front: it must not look like a leak
    bool images = false;           // queue images for handOff() (the node's camera_handoff)
    int64_t camera_offset_us = 0;  // image utime + this = IMU time (rig.camera.time_offset_s)
    double outage_begin_s = 0.0;   // sweeps starting in [begin, end) (sim seconds) are not fed: a LiDAR outage
    double outage_end_s = 0.0;
  };

  SimLioDriver(const livo::sim::SimulationSetup& setup, const livo::lio::LioOptions& lio_options, const Options& o)
      : setup_(setup),
        wheel_enabled_(lio_options.wheel.enabled),
        images_enabled_(o.images),
        camera_offset_us_(o.camera_offset_us),
        lio_(lio_options),
        outage_begin_(setup.start_utime + static_cast<int64_t>(std::llround(o.outage_begin_s * 1e6))),
        outage_end_(setup.start_utime + static_cast<int64_t>(std::llround(o.outage_end_s * 1e6))) {
    est_.reserve(o.expected_sweeps);
    gt_.reserve(o.expected_sweeps);
  }

  void write(const livo::sim::ImuReading& m) override {
    livo::ImuSample s;
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
    livo::WheelSample w;
    w.utime = m.utime;
    w.left_speed = m.left_speed;
    w.right_speed = m.right_speed;
    lio_.addWheel(w);
    newest_wheel_ = m.utime;
    processReady();
  }
  void write(const livo::sim::PoseReading&) override {}  // ground truth is read from the trajectory
  void write(const livo::sim::CameraImage& m) override {
    if (!images_enabled_) return;
    const int64_t t = m.utime + camera_offset_us_;
    // the node's onCamera: an image the filter is already past is skipped
    if (lio_.initialized() && t <= lio_.utime()) {
      ++images_skipped_;
      return;
    }
    images_.emplace_back(t, m);
    processReady();
  }
  void write(const livo::sim::LidarSweep& m) override {
    if (m.utime >= outage_begin_ && m.utime < outage_end_) return;
    Pending p;
    p.msg = livo::sim::toPointCloud(m);  // what the sim's log holds for the sweep
    std::string why;
    if (!livo::fromMessage(p.msg, &p.scan, &why)) throw std::runtime_error("sweep conversion: " + why);
    p.t_end = lio_.scanEndUtime(p.scan);
    pending_.push_back(std::move(p));
    processReady();
  }

  const livo::lio::LioEstimator& lio() const { return lio_; }
  int64_t sweeps() const { return sweeps_; }
  int64_t resets() const { return resets_; }
  int64_t refusedImu() const { return refused_imu_; }
  int64_t imagesSkipped() const { return images_skipped_; }
  int64_t count(livo::lio::ScanResult::Status s) const { return status_count_[static_cast<int>(s)]; }
  double lastPositionError() const { return last_error_; }
  const std::vector<livo::Vec3>& estimated() const { return est_; }
  const std::vector<livo::Vec3>& groundTruth() const { return gt_; }

  /// Per-sweep time statistics since the last call.
  livo::LatencyStats takePeriodStats() { return std::exchange(period_, livo::LatencyStats()); }
  const livo::LatencyStats& totalStats() const { return total_; }

 protected:
  /// After each sweep with output (the node publishes ODOMETRY and REGISTERED_SCAN then).
  virtual void onSweep(const livo::lio::ScanResult&, const livo::point_cloud_t&) {}
  /// An image at IMU time t is due: the filter is tracking and behind t, IMU past t has been added.
  virtual void handOff(int64_t, const livo::sim::CameraImage&) {}

  livo::lio::LioEstimator& mutableLio() { return lio_; }
  /// The node's resetAll(): the filter and everything waiting for it.
  void resetAll(const std::string& why) {
    std::cerr << "soak: " << why << ": re-initialising\n";
    ++resets_;
    lio_.reset();
    pending_.clear();
    images_.clear();
  }

 private:
  struct Pending {
    livo::point_cloud_t msg;
    livo::LidarScan scan;
    int64_t t_end = 0;
  };

  void processReady() {
    while (true) {
      // the earlier of the next image time and the next sweep end (livo-lio's advance())
      if (!images_.empty() && (pending_.empty() || images_.front().first <= pending_.front().t_end)) {
        const int64_t t = images_.front().first;
        if (newest_imu_ <= t) return;  // no IMU past the image yet
        const std::pair<int64_t, livo::sim::CameraImage> image = std::move(images_.front());
        images_.pop_front();
        if (!lio_.tracking() || t <= lio_.utime()) {
          ++images_skipped_;
          continue;
        }
        handOff(t, image.second);
        continue;
      }
      if (pending_.empty()) return;
      const int64_t t_end = pending_.front().t_end;
      if (newest_imu_ <= t_end) return;
      if (wheel_enabled_ && newest_wheel_ <= t_end) return;
      const Pending p = std::move(pending_.front());
      pending_.pop_front();
      process(p);
    }
  }

  void process(const Pending& p) {
    using livo::lio::ScanResult;
    const bool was_initialized = lio_.initialized();
    const auto t0 = std::chrono::steady_clock::now();
    const ScanResult r = lio_.addScan(p.scan);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ++status_count_[static_cast<int>(r.status)];
    if (was_initialized && !lio_.initialized()) {
      ++resets_;
      std::cerr << "soak: the LIO re-initialised at sweep " << sweeps_ << ": " << r.message << "\n";
    }
    if (!r.hasOutput()) return;
    ++sweeps_;
    period_.add(s);
    total_.add(s);
    const livo::Pose3 truth = setup_.trajectory->at(setup_.trajectoryTime(r.utime)).T_W_I;
    // the LIO's world frame is its own (gravity-aligned, yaw and origin arbitrary): the running
    // error is taken after aligning the first output pose with the truth
    if (est_.empty()) T_truth_est_ = truth * r.state.pose().inverse();
    est_.push_back(r.state.pos);
    gt_.push_back(truth.translation());
    last_error_ = (T_truth_est_ * r.state.pos - truth.translation()).norm();
    onSweep(r, p.msg);
  }

  const livo::sim::SimulationSetup& setup_;
  const bool wheel_enabled_, images_enabled_;
  const int64_t camera_offset_us_;
  livo::lio::LioEstimator lio_;
  const int64_t outage_begin_, outage_end_;
  std::deque<Pending> pending_;
  std::deque<std::pair<int64_t, livo::sim::CameraImage>> images_;  // (IMU time, image)
  int64_t newest_imu_ = std::numeric_limits<int64_t>::min();
  int64_t newest_wheel_ = std::numeric_limits<int64_t>::min();
  int64_t sweeps_ = 0, resets_ = 0, refused_imu_ = 0, images_skipped_ = 0;
  int64_t status_count_[5] = {0, 0, 0, 0, 0};
  livo::LatencyStats period_, total_;
  std::vector<livo::Vec3> est_, gt_;
  livo::Pose3 T_truth_est_ = livo::Pose3::Identity();
  double last_error_ = 0.0;
};

/// When the simulator's progress callback should take a report line: every `every` sim seconds,
/// and once at the end (the sim's closing chunk, already sampled, is not taken twice).
class PeriodicReport {
 public:
  explicit PeriodicReport(double every) : every_(every), next_(every) {
    if (!(every > 0.0)) throw std::invalid_argument("--report-every must be > 0");
  }
  bool due(double done, double total) {
    if (done + 1e-9 < next_ && done < total) return false;
    if (done <= last_ + 1e-9) return false;
    last_ = done;
    while (next_ <= done + 1e-9) next_ += every_;
    return true;
  }

 private:
  double every_, next_;
  double last_ = -1.0;
};

/// The first sample at or after `early` seconds (nullptr if none); T has `sim_s`.
template <class T>
const T* sampleAtOrAfter(const std::vector<T>& samples, double early) {
  for (const auto& s : samples)
    if (s.sim_s + 1e-9 >= early) return &s;
  return nullptr;
}

/// The flatness figures: RSS, peak and heap at the early point and at the end, and their ratios.
inline void printMemoryRatios(double early_s, const Memory& a, double last_s, const Memory& b) {
  std::printf("RSS  at %.0f s: %.1f MB, at %.0f s: %.1f MB, ratio %.3f\n", early_s, a.rss_mb, last_s, b.rss_mb,
              b.rss_mb / a.rss_mb);
  std::printf("peak at %.0f s: %.1f MB, at %.0f s: %.1f MB, ratio %.3f (bar: <= 1.20)\n", early_s, a.peak_mb, last_s,
              b.peak_mb, b.peak_mb / a.peak_mb);
  std::printf("heap at %.0f s: %.1f MB, at %.0f s: %.1f MB, ratio %.3f\n", early_s, a.heap_mb, last_s, b.heap_mb,
              b.heap_mb / a.heap_mb);
}

/// Position RMSE of `est` against `gt` after SE(3) Umeyama alignment; NaN with fewer than 3 poses.
inline double ateRmse(const std::vector<livo::Vec3>& est, const std::vector<livo::Vec3>& gt) {
  if (est.size() < 3) return std::numeric_limits<double>::quiet_NaN();
  const auto align = livo::evaluate::umeyamaAlignment(est, gt, false);
  double sq = 0.0;
  for (size_t i = 0; i < est.size(); ++i) sq += (align.apply(est[i]) - gt[i]).squaredNorm();
  return std::sqrt(sq / static_cast<double>(est.size()));
}

}  // namespace livo_soak
