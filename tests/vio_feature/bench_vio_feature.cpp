// Per-image time of the feature front end (Google Benchmark, not a ctest test): the simulated room
// walk (config/sim/room.yaml, 640x480 grey, 20 Hz, about 1 m/s) rendered once, 120 images from
// t = 5 s. Each iteration times one FeatureTracker::track (pyramid, KLT forward and backward,
// RANSAC, corner detection) in process CPU time (OpenCV's worker threads counted: the cost on one
// core), with the true rotation as the hint (range(0) = 1) or without (0); the counters give the
// median, p90 and max per image and the tracks carried over per image.
//
//   build/bin/livo_vio_feature_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <ctime>
#include <vector>

#include "livo/vio_feature/feature_tracker.hpp"
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

}  // namespace

BENCHMARK_MAIN();
