// Per-image time of the feature front end (Google Benchmark, not a ctest test): the simulated room
// walk (config/sim/room.yaml, 640x480 grey, 20 Hz, about 1 m/s) rendered once, 120 images from
// t = 5 s. Each iteration times one FeatureTracker::track (pyramid, KLT forward and backward,
// RANSAC, corner detection) in process CPU time (OpenCV's worker threads counted: the cost on one
// core), with the true rotation as the hint (range(0) = 1) or without (0); the counters give the
// median, p90 and max per image and the tracks carried over per image.
//
// BM_VisualSubsystemPerImage: the whole visual subsystem per image, front end and back end:
// VioFeatureEstimator::addImage as the node runs it (the gyro's rotation hint, FeatureTracker::track,
// the depth image's depths when there is one, FrameFeatures, SlidingWindowEstimator::addFrame), with the
// trajectory's exact IMU at 200 Hz (gyro = angular velocity, accel = R^T (a + g)) fed to the
// estimator up to each image first; no LiDAR, no wheels. Images are rendered at 20 Hz (640x480)
// from a sim config: t = 0.05..5 s warm up (the start at rest initialises the estimator, the walk
// or drive fills the window; not timed), then 120 images from t = 5.05 s are timed, each in
// process CPU time (OpenCV's and Ceres's threads counted: the cost on one core) and wall time.
// range(0): 0 = room (handheld walk), 1 = campus_loop (car at 6 m/s, colour camera),
// 2 = bridge_deck with its RGB-D depth image (the simulator's depth with its sensor effects).
// Counters: median / p90 / max CPU ms, median wall ms, features in the graph, with measured depth.
//
//   build/bin/livo_vio_feature_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "livo/config.hpp"
#include "livo/time.hpp"
#include "livo/vio_feature/feature_depth.hpp"
#include "livo/vio_feature/feature_tracker.hpp"
#include "livo/vio_feature/sliding_window_estimator.hpp"
#include "livo/vio_feature/vio_feature_config.hpp"
#include "livo/vio_feature/vio_feature_estimator.hpp"
#include "rendered_sequence.hpp"

using namespace livo;
using namespace livo::vio_feature;

namespace {

double cpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Frames {
  livo_test::RenderedSequence sequence;
  std::vector<double> times;
  std::vector<cv::Mat> images;
};

const Frames& frames() {
  static const Frames f = [] {
    Frames out;
    for (int k = 0; k < 120; ++k) {
      out.times.push_back(5.0 + 0.05 * k);
      out.images.push_back(out.sequence.image(out.times.back(), static_cast<uint64_t>(k)));
    }
    return out;
  }();
  return f;
}

void BM_TrackImage(benchmark::State& state) {
  const Frames& fr = frames();
  const bool hint = state.range(0) != 0;
  std::vector<double> ms;
  double tracked = 0.0;
  FeatureTracker tracker(CameraProjection(fr.sequence.camera()), FeatureTrackerOptions{});
  size_t k = 0;
  for (auto _ : state) {
    if (k == fr.images.size()) {  // start the walk again, from no tracks
      tracker.reset();
      k = 0;
    }
    const Mat3 R = k > 0 ? fr.sequence.rotationCurPrev(fr.times[k], fr.times[k - 1]) : Mat3::Identity();
    const double t0 = cpuSeconds();
    const TrackedFrame f = tracker.track(fr.sequence.utime(fr.times[k]), fr.images[k], hint ? &R : nullptr);
    const double dt = cpuSeconds() - t0;
    state.SetIterationTime(dt);
    if (k > 0) ms.push_back(dt * 1e3), tracked += f.tracked;  // the first image has nothing to track
    ++k;
  }
  std::sort(ms.begin(), ms.end());
  state.counters["median_ms"] = ms[ms.size() / 2];
  state.counters["p90_ms"] = ms[std::min(ms.size() - 1, ms.size() * 9 / 10)];
  state.counters["max_ms"] = ms.back();
  state.counters["tracked"] = tracked / static_cast<double>(ms.size());
}
BENCHMARK(BM_TrackImage)->Arg(0)->Arg(1)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(239);

// ---- the whole visual subsystem ------------------------------------------------------------------

constexpr double kImageDt = 0.05;   // 20 Hz
constexpr double kWarmUpEnd = 5.0;  // s: images up to here initialise and fill the window
constexpr int kTimedImages = 120;

struct Subsystem {
  std::string config;
  std::unique_ptr<livo_test::RenderedSequence> sequence;
  vio_feature::VioFeatureNodeOptions options;
  std::vector<double> times;  // trajectory time of each image
  std::vector<cv::Mat> images;
  std::vector<cv::Mat> depths;              // empty without a depth image
  std::vector<std::vector<ImuSample>> imu;  // before each image: the samples up to its time
};

const Subsystem& subsystem(int which) {
  static std::array<std::unique_ptr<Subsystem>, 3> cache;
  if (cache[which]) return *cache[which];
  auto out = std::make_unique<Subsystem>();
  const char* configs[] = {"config/sim/room.yaml", "config/sim/campus_loop.yaml", "config/sim/bridge_deck.yaml"};
  out->config = configs[which];
  out->sequence = std::make_unique<livo_test::RenderedSequence>(out->config);
  out->options = vio_feature::readVioFeatureNodeOptions(Config::load(std::string(LIVO_SOURCE_DIR) + "/" + out->config));
  out->options.core.use_lidar_depth = false;   // no LIO here
  out->options.core.window.use_wheel = false;  // IMU and camera only
  const bool depth = which == 2;
  out->options.core.use_depth_image = depth;
  int imu_k = 0;
  const int n = static_cast<int>(std::lround(kWarmUpEnd / kImageDt)) + kTimedImages;
  for (int k = 1; k <= n; ++k) {
    const double t = kImageDt * k;
    out->times.push_back(t);
    cv::Mat grey, z;
    if (depth) {
      out->sequence->imageAndDepth(t, static_cast<uint64_t>(k), &grey, &z);
      out->depths.push_back(z);
    } else {
      grey = out->sequence->image(t, static_cast<uint64_t>(k));
    }
    out->images.push_back(grey);
    std::vector<ImuSample> imu;  // up to the first sample at or past the image (the node's watermark)
    while (imu.empty() || imu.back().utime < out->sequence->utime(t))
      imu.push_back(livo_test::exactImu(*out->sequence, 0.005 * imu_k++));
    out->imu.push_back(std::move(imu));
  }
  cache[which] = std::move(out);
  return *cache[which];
}

/// One image through the front end and the back end (VioFeatureNode::process without the node).
/// `utime`: the image's time on the IMU clock (its stamp is that less the rig's camera time offset);
/// `depth` may be null.
FrameResult processImage(vio_feature::VioFeatureEstimator* vs, const std::vector<ImuSample>& imu, int64_t utime,
                         const cv::Mat& grey, const cv::Mat* depth) {
  for (const ImuSample& s : imu) vs->addImu(s);
  vio_feature::ImageInput in;
  in.utime = utime - toUtime(vs->options().window.camera_time_offset_s);
  in.grey = grey;
  in.depth = depth;
  return vs->addImage(in).frame;
}

double wallSeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void BM_VisualSubsystemPerImage(benchmark::State& state) {
  const Subsystem& sub = subsystem(static_cast<int>(state.range(0)));
  const livo_test::RenderedSequence& seq = *sub.sequence;
  const bool depth = !sub.depths.empty();
  vio_feature::VioFeatureEstimator vs(sub.options.core);
  const size_t warm = sub.times.size() - kTimedImages;
  int tracked_in_warm_up = 0;
  for (size_t k = 0; k < warm; ++k) {
    const FrameResult r =
        processImage(&vs, sub.imu[k], seq.utime(sub.times[k]), sub.images[k], depth ? &sub.depths[k] : nullptr);
    tracked_in_warm_up += r.status == FrameResult::Status::kTracked;
  }
  if (tracked_in_warm_up < 20) {
    state.SkipWithError("the estimator did not initialise in the warm-up");
    return;
  }
  std::vector<double> cpu_ms, wall_ms;
  double in_graph = 0.0, with_depth = 0.0;
  int not_tracked = 0;
  size_t k = warm;
  for (auto _ : state) {
    const double c0 = cpuSeconds(), w0 = wallSeconds();
    const FrameResult r =
        processImage(&vs, sub.imu[k], seq.utime(sub.times[k]), sub.images[k], depth ? &sub.depths[k] : nullptr);
    const double dc = cpuSeconds() - c0, dw = wallSeconds() - w0;
    state.SetIterationTime(dc);
    cpu_ms.push_back(dc * 1e3);
    wall_ms.push_back(dw * 1e3);
    in_graph += r.features_in_graph;
    with_depth += r.features_with_depth;
    not_tracked += r.status != FrameResult::Status::kTracked;
    ++k;
  }
  const double n = static_cast<double>(cpu_ms.size());
  std::sort(cpu_ms.begin(), cpu_ms.end());
  std::sort(wall_ms.begin(), wall_ms.end());
  state.counters["median_ms"] = cpu_ms[cpu_ms.size() / 2];
  state.counters["p90_ms"] = cpu_ms[std::min(cpu_ms.size() - 1, cpu_ms.size() * 9 / 10)];
  state.counters["max_ms"] = cpu_ms.back();
  state.counters["wall_median_ms"] = wall_ms[wall_ms.size() / 2];
  state.counters["in_graph"] = in_graph / n;
  state.counters["with_depth"] = with_depth / n;
  state.counters["not_tracked"] = not_tracked;
  state.counters["restarts"] = vs.epoch();
  state.SetLabel(sub.config);
}
BENCHMARK(BM_VisualSubsystemPerImage)
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(kTimedImages);

}  // namespace

BENCHMARK_MAIN();
