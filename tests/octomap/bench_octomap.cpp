// bench_octomap: CPU cost of one VLP-16 sweep into the OctoMap (OctomapBuilder::addScan, 0.1 m,
// the room run's true registered scans). Not a ctest test:
//   build/bin/bench_octomap --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Each iteration is one sweep; the map is rebuilt from empty when the recording is used up.
// Bar: well under 100 ms (10 Hz sweeps on one core). BM_OctomapRebuild times the rebuild from the
// keyframes after a loop correction.
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <ctime>
#include <map>
#include <set>
#include <string>

#include "livo/octomap/octomap_builder.hpp"
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
  livo::octomap::OctomapOptions o;
  o.resolution = 0.1;
  o.max_range = setup.rig.lidar->max_range;
  o.origin_segments = origin_segments;
  std::unique_ptr<livo::octomap::OctomapBuilder> builder;
  size_t next = rec.sweeps.size(), points = 0;
  std::string error;
  for (auto _ : state) {
    if (next == rec.sweeps.size()) {
      builder = std::make_unique<livo::octomap::OctomapBuilder>(o, setup.rig.lidar->T_I_L);
      next = 0;
    }
    const livo_bench::WorldSweep& s = rec.sweeps[next++];
    livo::RegisteredScanView v;
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

// The rebuild after a loop correction: keyframes as the LIO makes them (every 10th sweep, its body
// frame points on a 0.2 m grid), each iteration moves all of them by 0.2 m (back and forth) and
// times OctomapBuilder::applyCorrection, i.e. one rebuild from every keyframe.
void BM_OctomapRebuild(benchmark::State& state) {
  const livo_bench::SimRecording& rec = livo_bench::roomRecording();
  const auto& setup = livo_bench::roomSetup();
  livo::octomap::OctomapOptions o;
  o.resolution = 0.1;
  o.max_range = setup.rig.lidar->max_range;
  livo::octomap::OctomapBuilder builder(o, setup.rig.lidar->T_I_L);
  std::map<int64_t, livo::Pose3> poses;
  size_t keyframe_points = 0;
  std::string error;
  for (size_t k = 0; k < rec.sweeps.size(); ++k) {
    const livo_bench::WorldSweep& s = rec.sweeps[k];
    livo::RegisteredScanView v;
    v.utime = s.utime, v.cloud_utime = s.cloud_utime, v.T_W_I = s.T_W_I;
    v.num_points = static_cast<int>(s.x.size());
    v.x = s.x.data(), v.y = s.y.data(), v.z = s.z.data(), v.time_offset = s.time_offset.data();
    builder.addScan(v, &error);
    if (k % 10 != 5) continue;
    livo::octomap::Keyframe kf;
    kf.utime = s.utime;
    kf.T_W_I = s.T_W_I;
    const livo::Pose3 T_I_W = s.T_W_I.inverse();
    std::set<std::array<int64_t, 3>> cells;  // 0.2 m downsampling, first point per cell
    for (size_t j = 0; j < s.x.size(); ++j) {
      const Eigen::Vector3d p = T_I_W * Eigen::Vector3d(s.x[j], s.y[j], s.z[j]);
      const std::array<int64_t, 3> c{int64_t(std::floor(p.x() / 0.2)), int64_t(std::floor(p.y() / 0.2)),
                                     int64_t(std::floor(p.z() / 0.2))};
      if (cells.insert(c).second) kf.points.push_back(p.cast<float>());
    }
    keyframe_points += kf.points.size();
    poses[static_cast<int64_t>(k)] = s.T_W_I;
    builder.addKeyframe(static_cast<int64_t>(k), std::move(kf));
  }
  int n = 0;
  for (auto _ : state) {
    std::map<int64_t, livo::Pose3> corrected = poses;
    for (auto& [id, T] : corrected) T.translation().x() += (n % 2 == 0) ? 0.2 : 0.0;
    ++n;
    const double t0 = cpuSeconds();
    builder.applyCorrection(corrected);
    state.SetIterationTime(cpuSeconds() - t0);
  }
  state.counters["keyframes"] = double(poses.size());
  state.counters["points_per_keyframe"] = double(keyframe_points) / double(std::max<size_t>(1, poses.size()));
  state.counters["rebuilds"] = double(builder.rebuilds());
}
BENCHMARK(BM_OctomapRebuild)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(10);

}  // namespace

BENCHMARK_MAIN();
