// Per-sweep time of livo-lio-graph's estimator (Google Benchmark, not a ctest test): the ray-cast
// room walk with a 16-beam (VLP-16) LiDAR at 10 Hz and a realistic IMU, with and without the planar
// factors. Only LioGraphEstimator::addScan is timed (manual time); the counters give the median and
// p90 per sweep, and cpu_median_ms the median of the thread's CPU time in addScan (steadier than the
// wall time on a shared machine). Issue 13's bar: median <= 25 ms on one core for a 16-beam LiDAR.
//
//   build/bin/livo_lio_graph_bench
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <ctime>

#include "livo/lio_graph/lio_graph_estimator.hpp"
#include "synthetic_world.hpp"

using namespace livo;
using namespace livo::lio_graph;
namespace synth = livo::lio::synth;

namespace {

double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void BM_LioGraphScan(benchmark::State& state) {
  const bool planar = state.range(0) != 0;
  const int timed = static_cast<int>(state.range(1));
  synth::SequenceSpec spec;
  spec.duration = 1.5 + 0.1 * timed;
  spec.traj = synth::roomTrajectory(0.6);
  spec.lidar.range_noise_std = 0.01;
  spec.imu_error = synth::realisticImu();
  const synth::SyntheticSequence seq(spec);
  LioGraphOptions opts;
  opts.planar_factors = planar;
  LioGraphEstimator est(opts);
  size_t imu_index = 0;
  auto feedImu = [&](int64_t t_end) {
    while (imu_index < seq.imu().size() && seq.imu()[imu_index].utime <= t_end + 10000)
      est.addImu(seq.imu()[imu_index++]);
  };
  int k = 0;
  // untimed: initialisation and a full window
  for (; k < 15; ++k) {
    feedImu(seq.scanEndUtime(k));
    est.addScan(seq.scan(k));
  }
  std::vector<double> ms, cpu_ms;
  for (auto _ : state) {
    const LidarScan scan = seq.scan(k);
    feedImu(seq.scanEndUtime(k));
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = threadCpuSeconds();
    const GraphScanResult r = est.addScan(scan);
    const double c = threadCpuSeconds() - c0;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    benchmark::DoNotOptimize(r.pose);
    state.SetIterationTime(s);
    ms.push_back(s * 1e3);
    cpu_ms.push_back(c * 1e3);
    if (r.status != GraphScanResult::Status::kTracked) state.SkipWithError("a sweep was not tracked");
    ++k;
  }
  std::sort(ms.begin(), ms.end());
  std::sort(cpu_ms.begin(), cpu_ms.end());
  if (!ms.empty()) {
    state.counters["cpu_median_ms"] = cpu_ms[cpu_ms.size() / 2];
    state.counters["median_ms"] = ms[ms.size() / 2];
    state.counters["p90_ms"] = ms[std::min(ms.size() - 1, ms.size() * 9 / 10)];
    state.counters["max_ms"] = ms.back();
  }
}
// {planar factors on, timed sweeps}
BENCHMARK(BM_LioGraphScan)
    ->Args({1, 60})
    ->Args({0, 60})
    ->Iterations(60)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
