#include "livo/sim/simulator.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <thread>

#include "livo/sim/calibration_errors.hpp"
#include "livo/sim/camera_renderer.hpp"
#include "livo/sim/depth_effects.hpp"
#include "livo/sim/imu_model.hpp"
#include "livo/sim/lidar_scanner.hpp"
#include "livo/sim/random.hpp"
#include "livo/sim/wheel_model.hpp"

namespace livo::sim {

namespace {

// Random stream ids, one per sensor.
enum Stream : uint64_t {
  kImuStream = 1,
  kWheelStream = 2,
  kLidarStream = 3,
  kCameraStream = 4,
  kWheelSlipStream = 5,
  kDepthStream = 6,
};
// Order of messages that share a stamp.
enum Rank : int { kImuRank = 0, kWheelRank = 1, kGroundTruthRank = 2, kLidarRank = 3, kCameraRank = 4, kDepthRank = 5 };

constexpr int64_t kChunkUs = 1000000;

/// Stamp of sample k of a clock at rate_hz starting at start.
int64_t stampOf(int64_t start, int64_t k, double rate_hz, double phase = 0.0) {
  return start + static_cast<int64_t>(std::llround((static_cast<double>(k) + phase) * 1e6 / rate_hz));
}

/// Runs jobs on `threads` workers; each job writes only its own result slot.
void runJobs(const std::vector<std::function<void()>>& jobs, int threads) {
  if (jobs.empty()) return;
  const int n = std::min<int>(threads, static_cast<int>(jobs.size()));
  if (n <= 1) {
    for (const auto& j : jobs) j();
    return;
  }
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t i = next++; i < jobs.size(); i = next++) jobs[i]();
  };
  std::vector<std::thread> pool;
  for (int i = 1; i < n; ++i) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
}

struct Pending {
  int64_t utime;
  int rank;
  size_t index;
};

/// The messages of one chunk of sim time, and where each goes in the output order.
struct Chunk {
  int64_t end = 0;  // exclusive
  std::vector<ImuReading> imus;
  std::vector<PoseReading> poses;
  std::vector<WheelReading> wheels;
  std::vector<LidarSweep> sweeps;
  std::vector<CameraImage> images;
  std::vector<DepthImage> depths;  // with rig.camera.depth: one per image, in the same slot
  std::vector<Pending> pending;
  std::vector<std::function<void()>> jobs;  // fill the reserved sweep and image slots
};

/// One simulation run: the sensor models and their sample counters, carried from chunk to chunk.
class SimulationRun {
 public:
  explicit SimulationRun(const SimulationSetup& setup)
      : s_(setup),
        rig_(setup.rig),
        mounted_(trueRig(setup.rig, setup.calibration_errors)),
        errors_(setup.calibration_errors),
        options_(setup.options),
        start_(setup.start_utime),
        end_(setup.endUtime()),
        imu_noise_(rig_.imu, options_.initial_gyro_bias, options_.initial_accel_bias,
                   Random(options_.seed, kImuStream)) {
    stats_.sim_seconds = options_.duration_s;
    for (const std::string& ch : {rig_.channels.imu, rig_.channels.ground_truth}) stats_.messages[ch] = 0;
    if (rig_.wheel) {
      stats_.messages[rig_.channels.wheel] = 0;
      wheel_noise_.emplace(*rig_.wheel, options_.wheel_left_scale, options_.wheel_right_scale,
                           Random(options_.seed, kWheelStream));
      // a stream of its own: with slip on, the readings outside its episodes are those without it
      if (options_.wheel_slip.enabled())
        wheel_slip_.emplace(options_.wheel_slip, Random(options_.seed, kWheelSlipStream));
    }
    if (rig_.lidar) {
      stats_.messages[rig_.channels.lidar] = 0;
      scanner_ = std::make_unique<LidarScanner>(*mounted_.lidar, options_.lidar, options_.lidar_effects);
      sweep_us_ = static_cast<int64_t>(std::llround(scanner_->pattern().sweepDuration() * 1e6));
    }
    if (rig_.camera && options_.images) {
      stats_.messages[rig_.channels.camera] = 0;
      if (rig_.camera->depth) stats_.messages[rig_.channels.depth] = 0;
      renderer_ = std::make_unique<CameraRenderer>(*mounted_.camera, options_.camera);
      camera_offset_us_ = static_cast<int64_t>(std::llround(rig_.camera->time_offset_s * 1e6));
      if (options_.camera.auto_exposure.enabled)
        auto_exposure_.emplace(options_.camera.auto_exposure, options_.camera.exposure_time);
    }
    if (s_.replaysRecordedImu()) {
      while (recorded_k_ < s_.recorded_imu.size() && s_.recorded_imu[recorded_k_].stamp_ns < start_ * 1000)
        ++recorded_k_;
    }
  }

  int64_t start() const { return start_; }
  int64_t end() const { return end_; }
  SimulationStats& stats() { return stats_; }

  /// IMU: the recording's own samples, or exact readings of the motion through the IMU model.
  void addImu(Chunk* c) {
    if (s_.replaysRecordedImu()) {
      for (; recorded_k_ < s_.recorded_imu.size(); ++recorded_k_) {
        const AslImuSample& r = s_.recorded_imu[recorded_k_];
        const int64_t u = (r.stamp_ns + 500) / 1000;
        if (u >= c->end) break;
        c->imus.push_back({u, r.gyro, r.accel});
      }
    } else {
      for (int64_t u; (u = stampOf(start_, imu_k_, rig_.imu.rate_hz)) < c->end; ++imu_k_) {
        ImuReading r = idealImuReading(s_.trajectory->at(s_.trajectoryTime(u)), rig_.imu.gravity, u);
        if (s_.imu_errors.any()) applyImuErrors(s_.imu_errors, (u - start_) * 1e-6, &r);
        imu_noise_.apply(&r);
        c->imus.push_back(r);
      }
    }
    for (size_t i = 0; i < c->imus.size(); ++i) c->pending.push_back({c->imus[i].utime, kImuRank, i});
  }

  void addGroundTruth(Chunk* c) {
    for (int64_t u; (u = stampOf(start_, gt_k_, options_.ground_truth_rate_hz)) < c->end; ++gt_k_) {
      c->poses.push_back({u, s_.trajectory->at(s_.trajectoryTime(u)).T_W_I});
      c->pending.push_back({u, kGroundTruthRank, c->poses.size() - 1});
    }
  }

  void addWheel(Chunk* c) {
    if (!rig_.wheel) return;
    for (int64_t u; (u = stampOf(start_, wheel_k_, rig_.wheel->rate_hz)) < c->end; ++wheel_k_) {
      // stamped u, measured at IMU time u + the wheel's time offset error
      const double t = s_.trajectoryTime(u) + errors_.wheel_time_offset_s;
      WheelReading r = idealWheelReading(s_.trajectory->at(t), *mounted_.wheel, u);
      if (wheel_slip_) wheel_slip_->apply((u - start_) * 1e-6, &r);  // the wheels' own rotation, then scale and noise
      wheel_noise_->apply(&r);
      c->wheels.push_back(r);
      c->pending.push_back({u, kWheelRank, c->wheels.size() - 1});
    }
    if (wheel_slip_ && !c->wheels.empty()) {
      // episodes begun up to the chunk's last sample
      const double last = (c->wheels.back().utime - start_) * 1e-6;
      const auto& episodes = wheel_slip_->episodes();
      stats_.wheel_slip_episodes = std::count_if(episodes.begin(), episodes.end(),
                                                 [last](const WheelSlipEpisode& e) { return e.start_s <= last; });
    }
  }

  /// Reserves the chunk's sweeps; a job per sweep computes it.
  void planSweeps(Chunk* c) {
    if (!scanner_) return;
    for (int64_t u; (u = stampOf(start_, sweep_k_, rig_.lidar->rate_hz)) < c->end && u + sweep_us_ <= end_;
         ++sweep_k_) {
      c->pending.push_back({u, kLidarRank, c->sweeps.size()});
      c->sweeps.emplace_back();
      const size_t slot = c->sweeps.size() - 1;
      const int64_t k = sweep_k_;
      c->jobs.push_back([this, c, slot, k, u] {
        // stamped u, swept from IMU time u + the LiDAR's time offset error
        const double t0 = s_.trajectoryTime(u) + errors_.lidar_time_offset_s;
        c->sweeps[slot] = scanner_->scan(*s_.scene, *s_.trajectory, t0, u, (u - start_) * 1e-6,
                                         Random(options_.seed, kLidarStream, static_cast<uint64_t>(k)));
      });
    }
  }

  /// Reserves the chunk's images; with auto exposure one job renders them in order (the
  /// controller meters each image for the next), else a job per image.
  void planImages(Chunk* c) {
    if (!renderer_) return;
    std::vector<std::function<void()>> frames;
    for (int64_t u; (u = frameStamp(frame_k_)) < c->end; ++frame_k_) {
      c->pending.push_back({u, kCameraRank, c->images.size()});
      c->images.emplace_back();
      const size_t slot = c->images.size() - 1;
      if (rig_.camera->depth) {
        c->depths.emplace_back();
        c->pending.push_back({u, kDepthRank, slot});
      }
      const int64_t k = frame_k_;
      frames.push_back([this, c, slot, k, u] {
        // stamped on the camera's clock as the rig believes it (rig camera time_offset_s) and logged at
        // IMU time u; rendered at u + the camera's time offset error
        const double t = s_.trajectoryTime(u) + errors_.camera_time_offset_s;
        const Random rng(options_.seed, kCameraStream, static_cast<uint64_t>(k));
        CameraImage& image = c->images[slot];
        const ExposureSetting setting =
            auto_exposure_ ? auto_exposure_->setting() : ExposureSetting{renderer_->exposureAt(t), 1.0};
        std::vector<float> z_depth;
        image = renderer_->render(*s_.scene, *s_.trajectory, t, u - camera_offset_us_, rng, setting,
                                  rig_.camera->depth ? &z_depth : nullptr);
        if (auto_exposure_) auto_exposure_->update(AutoExposure::meanLevel(image.data));
        image.log_utime = u;
        if (rig_.camera->depth) {
          // its noise from a stream of its own: every other channel is as it is without depth
          DepthImage& depth = c->depths[slot];
          depth.utime = image.utime;
          depth.log_utime = u;
          depth.width = image.width;
          depth.height = image.height;
          depth.millimetres = measureDepth(z_depth, image.width, image.height, options_.depth,
                                           Random(options_.seed, kDepthStream, static_cast<uint64_t>(k)));
        }
      });
    }
    if (auto_exposure_)
      c->jobs.push_back([frames] {
        for (const auto& f : frames) f();
      });
    else
      c->jobs.insert(c->jobs.end(), frames.begin(), frames.end());
  }

  /// Hands the chunk's messages to the sink in time order (ties by rank).
  void write(Chunk* c, SensorDataSink& sink) {
    std::stable_sort(c->pending.begin(), c->pending.end(), [](const Pending& a, const Pending& b) {
      return a.utime < b.utime || (a.utime == b.utime && a.rank < b.rank);
    });
    for (const Pending& p : c->pending) {
      switch (p.rank) {
        case kImuRank:
          sink.write(c->imus[p.index]);
          ++stats_.messages[rig_.channels.imu];
          break;
        case kWheelRank:
          sink.write(c->wheels[p.index]);
          ++stats_.messages[rig_.channels.wheel];
          break;
        case kGroundTruthRank:
          sink.write(c->poses[p.index]);
          ++stats_.messages[rig_.channels.ground_truth];
          break;
        case kLidarRank:
          sink.write(c->sweeps[p.index]);
          ++stats_.messages[rig_.channels.lidar];
          stats_.lidar_points += static_cast<int64_t>(c->sweeps[p.index].size());
          break;
        case kCameraRank:
          sink.write(c->images[p.index]);
          ++stats_.messages[rig_.channels.camera];
          break;
        case kDepthRank:
          sink.write(c->depths[p.index]);
          ++stats_.messages[rig_.channels.depth];
          break;
      }
    }
  }

 private:
  /// Free-running: halfway between the clock's ticks; triggered: at the sweeps' starts or ends.
  int64_t frameStamp(int64_t k) const {
    switch (options_.camera_trigger) {
      case CameraTrigger::kSweepStart: return stampOf(start_, k, rig_.lidar->rate_hz);
      case CameraTrigger::kSweepEnd: return stampOf(start_, k, rig_.lidar->rate_hz) + sweep_us_;
      case CameraTrigger::kFree: break;
    }
    return stampOf(start_, k, rig_.camera->rate_hz, 0.5);
  }

  const SimulationSetup& s_;
  const SensorRig& rig_;     // the belief: stamps, channels, noise
  const SensorRig mounted_;  // the truth: what the sensors see
  const CalibrationErrors& errors_;
  const SimOptions& options_;
  const int64_t start_, end_;
  SimulationStats stats_;
  ImuNoise imu_noise_;
  std::optional<WheelNoise> wheel_noise_;
  std::optional<WheelSlip> wheel_slip_;
  std::unique_ptr<LidarScanner> scanner_;
  int64_t sweep_us_ = 0;
  std::unique_ptr<CameraRenderer> renderer_;
  int64_t camera_offset_us_ = 0;
  std::optional<AutoExposure> auto_exposure_;  // carried from chunk to chunk
  int64_t imu_k_ = 0, gt_k_ = 0, wheel_k_ = 0, sweep_k_ = 0, frame_k_ = 0;
  size_t recorded_k_ = 0;
};

}  // namespace

Simulator::Simulator(const SimulationSetup& setup) : setup_(setup) {}

SimulationStats Simulator::run(SensorDataSink& sink, const Progress& progress) {
  const auto wall0 = std::chrono::steady_clock::now();
  const double duration_s = setup_.options.duration_s;
  SimulationRun run(setup_);
  for (int64_t c0 = run.start(); c0 <= run.end(); c0 += kChunkUs) {
    Chunk chunk;
    chunk.end = std::min(c0 + kChunkUs, run.end() + 1);  // [c0, end)
    run.addImu(&chunk);
    run.addGroundTruth(&chunk);
    run.addWheel(&chunk);
    run.planSweeps(&chunk);  // heavy messages: slots reserved here, computed on the workers
    run.planImages(&chunk);
    runJobs(chunk.jobs, setup_.options.threads);
    run.write(&chunk, sink);
    SimulationStats& stats = run.stats();
    stats.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    if (progress) progress(std::min(duration_s, (chunk.end - run.start()) * 1e-6), duration_s, stats);
  }
  SimulationStats stats = run.stats();
  stats.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return stats;
}

}  // namespace livo::sim
