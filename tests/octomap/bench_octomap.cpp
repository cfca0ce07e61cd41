// bench_octomap: CPU cost of one VLP-16 sweep into the OctoMap (OctomapBuilder::addScan, 0.1 m,
// the room run's true registered scans). Not a ctest test:
//   build/bin/bench_octomap --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Each iteration is one sweep; the map is rebuilt from empty when the recording is used up.
// Bar: well under 100 ms (10 Hz sweeps on one core).
#include <benchmark/benchmark.h>

#include <ctime>
#include <string>

#include "octomap_builder.hpp"
#include "sim_recording.hpp"

namespace {

// the iteration time is the process CPU time (all threads, e.g. OpenCV workers): the cost in
// core time, robust to a shared machine
double cpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

void sweeps(benchmark::State& state, int origin_segments) {
  const livo_bench::SimRecording& rec = livo_bench::roomRecording();
  const auto& setup = livo_bench::roomSetup();
  livo::octomap_export::OctomapOptions o;
  o.resolution = 0.1;
  o.max_range = setup.rig.lidar->max_range;
  o.origin_segments = origin_segments;
  std::unique_ptr<livo::octomap_export::OctomapBuilder> builder;
  size_t next = rec.sweeps.size(), points = 0;
  std::string error;
  for (auto _ : state) {
    if (next == rec.sweeps.size()) {
      builder = std::make_unique<livo::octomap_export::OctomapBuilder>(o, setup.rig.lidar->T_I_L);
      next = 0;
    }
    const livo_bench::WorldSweep& s = rec.sweeps[next++];
    livo::octomap_export::RegisteredScanView v;
    v.utime = s.utime, v.cloud_utime = s.cloud_utime, v.T_W_I = s.T_W_I;
    v.num_points = static_cast<int>(s.x.size());
    v.x = s.x.data(), v.y = s.y.data(), v.z = s.z.data(), v.time_offset = s.time_offset.data();
    const double t0 = cpuSeconds();
    if (!builder->addScan(v, &error)) state.SkipWithError(error.c_str());
    state.SetIterationTime(cpuSeconds() - t0);
    points += s.x.size();
  }
  state.counters["points_per_sweep"] = benchmark::Counter(double(points) / state.iterations());
}

void BM_OctomapSweep(benchmark::State& state) { sweeps(state, static_cast<int>(state.range(0))); }
BENCHMARK(BM_OctomapSweep)->Arg(8)->Arg(1)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(80);

}  // namespace

BENCHMARK_MAIN();
