#include "simulator.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <thread>

#include "calibration_errors.hpp"
#include "camera_renderer.hpp"
#include "imu_model.hpp"
#include "lidar_scanner.hpp"
#include "random.hpp"
#include "wheel_model.hpp"

namespace livo {
namespace sim {

namespace {

// Random stream ids, one per sensor.
enum Stream : uint64_t { kImuStream = 1, kWheelStream = 2, kLidarStream = 3, kCameraStream = 4 };
// Order of messages that share a stamp.
enum Rank : int { kImuRank = 0, kWheelRank = 1, kGroundTruthRank = 2, kLidarRank = 3, kCameraRank = 4 };

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

}  // namespace

Simulator::Simulator(const SimulationSetup& setup) : setup_(setup) {}

SimulationStats Simulator::run(SensorDataSink& sink, const Progress& progress) {
  const auto wall0 = std::chrono::steady_clock::now();
  const SimulationSetup& s = setup_;
  const SensorRig& rig = s.rig;               // the belief: stamps, channels, noise
  const SensorRig mounted = trueRig(rig, s.calibration_errors);  // the truth: what the sensors see
  const CalibrationErrors& errors = s.calibration_errors;
  const SimOptions& o = s.options;
  const BodyTrajectory& trajectory = *s.trajectory;
  const Scene& scene = *s.scene;
  const int64_t start = s.start_utime, end = s.endUtime();

  SimulationStats stats;
  stats.sim_seconds = o.duration_s;
  for (const std::string& ch : {rig.channels.imu, rig.channels.ground_truth}) stats.messages[ch] = 0;

  ImuNoise imu_noise(rig.imu, o.initial_gyro_bias, o.initial_accel_bias, Random(o.seed, kImuStream));
  std::optional<WheelNoise> wheel_noise;
  if (rig.wheel) {
    stats.messages[rig.channels.wheel] = 0;
    wheel_noise.emplace(*rig.wheel, o.wheel_left_scale, o.wheel_right_scale, Random(o.seed, kWheelStream));
  }
  std::unique_ptr<LidarScanner> scanner;
  int64_t sweep_us = 0;
  if (rig.lidar) {
    stats.messages[rig.channels.lidar] = 0;
    scanner = std::make_unique<LidarScanner>(*mounted.lidar, o.lidar, o.lidar_effects);
    sweep_us = static_cast<int64_t>(std::llround(scanner->pattern().sweepDuration() * 1e6));
  }
  std::unique_ptr<CameraRenderer> renderer;
  int64_t camera_offset_us = 0;
  if (rig.camera) {
    stats.messages[rig.channels.camera] = 0;
    renderer = std::make_unique<CameraRenderer>(*mounted.camera, o.camera);
    camera_offset_us = static_cast<int64_t>(std::llround(rig.camera->time_offset_s * 1e6));
  }
  std::optional<AutoExposure> auto_exposure;  // carried from chunk to chunk
  if (renderer && o.camera.auto_exposure.enabled) auto_exposure.emplace(o.camera.auto_exposure, o.camera.exposure_time);

  int64_t imu_k = 0, gt_k = 0, wheel_k = 0, sweep_k = 0, frame_k = 0;
  size_t recorded_k = 0;
  if (s.replaysRecordedImu()) {
    while (recorded_k < s.recorded_imu.size() && s.recorded_imu[recorded_k].stamp_ns < start * 1000) ++recorded_k;
  }

  for (int64_t c0 = start; c0 <= end; c0 += kChunkUs) {
    const int64_t c1 = std::min(c0 + kChunkUs, end + 1);  // [c0, c1)
    std::vector<ImuReading> imus;
    std::vector<PoseReading> poses;
    std::vector<WheelReading> wheels;
    std::vector<LidarSweep> sweeps;
    std::vector<CameraImage> images;
    std::vector<Pending> pending;
    std::vector<std::function<void()>> jobs;

    // IMU: the recording's own samples, or exact readings of the motion through the IMU model
    if (s.replaysRecordedImu()) {
      for (; recorded_k < s.recorded_imu.size(); ++recorded_k) {
        const ImuSample& r = s.recorded_imu[recorded_k];
        const int64_t u = (r.stamp_ns + 500) / 1000;
        if (u >= c1) break;
        imus.push_back({u, r.gyro, r.accel});
      }
    } else {
      for (int64_t u; (u = stampOf(start, imu_k, rig.imu.rate_hz)) < c1; ++imu_k) {
        ImuReading r = idealImuReading(trajectory.at(s.trajectoryTime(u)), rig.imu.gravity, u);
        if (s.imu_errors.any()) applyImuErrors(s.imu_errors, (u - start) * 1e-6, &r);
        imu_noise.apply(&r);
        imus.push_back(r);
      }
    }
    for (size_t i = 0; i < imus.size(); ++i) pending.push_back({imus[i].utime, kImuRank, i});

    for (int64_t u; (u = stampOf(start, gt_k, o.ground_truth_rate_hz)) < c1; ++gt_k) {
      poses.push_back({u, trajectory.at(s.trajectoryTime(u)).T_W_I});
      pending.push_back({u, kGroundTruthRank, poses.size() - 1});
    }
    if (rig.wheel) {
      for (int64_t u; (u = stampOf(start, wheel_k, rig.wheel->rate_hz)) < c1; ++wheel_k) {
        // stamped u, measured at IMU time u + the wheel's time offset error
        const double t = s.trajectoryTime(u) + errors.wheel_time_offset_s;
        WheelReading r = idealWheelReading(trajectory.at(t), *mounted.wheel, u);
        wheel_noise->apply(&r);
        wheels.push_back(r);
        pending.push_back({u, kWheelRank, wheels.size() - 1});
      }
    }
    // heavy messages: reserve their slots, compute them on the workers
    if (scanner) {
      for (int64_t u; (u = stampOf(start, sweep_k, rig.lidar->rate_hz)) < c1 && u + sweep_us <= end; ++sweep_k) {
        pending.push_back({u, kLidarRank, sweeps.size()});
        sweeps.emplace_back();
        const size_t slot = sweeps.size() - 1;
        const int64_t k = sweep_k;
        jobs.push_back([&, slot, k, u] {
          // stamped u, swept from IMU time u + the LiDAR's time offset error
          const double t0 = s.trajectoryTime(u) + errors.lidar_time_offset_s;
          sweeps[slot] = scanner->scan(scene, trajectory, t0, u, (u - start) * 1e-6,
                                       Random(o.seed, kLidarStream, static_cast<uint64_t>(k)));
        });
      }
    }
    if (renderer) {
      std::vector<std::function<void()>> frames;
      // free-running: halfway between the clock's ticks; triggered: at the sweeps' starts or ends
      auto frameStamp = [&](int64_t k) {
        switch (o.camera_trigger) {
          case CameraTrigger::kSweepStart: return stampOf(start, k, rig.lidar->rate_hz);
          case CameraTrigger::kSweepEnd: return stampOf(start, k, rig.lidar->rate_hz) + sweep_us;
          case CameraTrigger::kFree: break;
        }
        return stampOf(start, k, rig.camera->rate_hz, 0.5);
      };
      for (int64_t u; (u = frameStamp(frame_k)) < c1; ++frame_k) {
        pending.push_back({u, kCameraRank, images.size()});
        images.emplace_back();
        const size_t slot = images.size() - 1;
        const int64_t k = frame_k;
        frames.push_back([&, slot, k, u] {
          // stamped on the camera's clock as the rig believes it (rig camera time_offset_s) and logged at
          // IMU time u; rendered at u + the camera's time offset error
          const double t = s.trajectoryTime(u) + errors.camera_time_offset_s;
          const Random rng(o.seed, kCameraStream, static_cast<uint64_t>(k));
          if (auto_exposure) {
            images[slot] = renderer->render(scene, trajectory, t, u - camera_offset_us, rng, auto_exposure->setting());
            auto_exposure->update(AutoExposure::meanLevel(images[slot].data));
          } else {
            images[slot] = renderer->render(scene, trajectory, t, u - camera_offset_us, rng);
          }
          images[slot].log_utime = u;
        });
      }
      // the controller meters each image for the next: one job renders the chunk's frames in order
      if (auto_exposure) jobs.push_back([frames] { for (const auto& f : frames) f(); });
      else jobs.insert(jobs.end(), frames.begin(), frames.end());
    }
    runJobs(jobs, o.threads);

    std::stable_sort(pending.begin(), pending.end(), [](const Pending& a, const Pending& b) {
      return a.utime < b.utime || (a.utime == b.utime && a.rank < b.rank);
    });
    for (const Pending& p : pending) {
      switch (p.rank) {
        case kImuRank: sink.write(imus[p.index]); ++stats.messages[rig.channels.imu]; break;
        case kWheelRank: sink.write(wheels[p.index]); ++stats.messages[rig.channels.wheel]; break;
        case kGroundTruthRank: sink.write(poses[p.index]); ++stats.messages[rig.channels.ground_truth]; break;
        case kLidarRank:
          sink.write(sweeps[p.index]);
          ++stats.messages[rig.channels.lidar];
          stats.lidar_points += static_cast<int64_t>(sweeps[p.index].size());
          break;
        case kCameraRank: sink.write(images[p.index]); ++stats.messages[rig.channels.camera]; break;
      }
    }
    stats.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    if (progress) progress(std::min(o.duration_s, (c1 - start) * 1e-6), o.duration_s, stats);
  }
  stats.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return stats;
}

}  // namespace sim
}  // namespace livo
