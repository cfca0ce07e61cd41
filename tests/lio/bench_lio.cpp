// Per-sweep time of the LIO (Google Benchmark, not a ctest test): synthetic room runs with a
// 16-beam (VLP-16, ~29k points) and a 64-beam (HDL-64, ~130k points) LiDAR at 10 Hz with realistic
// IMU noise. Only LioEstimator::addScan is timed (manual time); the counters give the median and
// p90 per sweep. A second group compares the map structures: the hashed voxel map against
// nanoflann's static kd-tree (rebuilt per sweep) and its dynamic (incremental) kd-tree, for the
// 5-NN queries of one registration pass and the insertion of one sweep.
//
//   build/bin/livo_lio_bench --benchmark_filter=LioScan
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <memory>
// nanoflann's dynamic tree trips -Wmaybe-uninitialized in its own header
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <nanoflann.hpp>
#pragma GCC diagnostic pop
#include <random>

#include "livo/lio/lio_estimator.hpp"
#include "synthetic_world.hpp"

using namespace livo;
using namespace livo::lio;

namespace {

void reportPercentiles(benchmark::State& state, std::vector<double> ms) {
  if (ms.empty()) return;
  std::sort(ms.begin(), ms.end());
  state.counters["median_ms"] = ms[ms.size() / 2];
  state.counters["p90_ms"] = ms[std::min(ms.size() - 1, ms.size() * 9 / 10)];
  state.counters["max_ms"] = ms.back();
}

synth::SequenceSpec roomSpec(int beams, double duration) {
  synth::SequenceSpec spec;
  spec.duration = duration;
  spec.traj = synth::roomTrajectory(0.6);
  spec.lidar = beams == 64 ? synth::LidarModel::hdl64() : synth::LidarModel::vlp16();
  spec.lidar.range_noise_std = 0.01;
  spec.imu_error = synth::realisticImu();
  return spec;
}

void BM_LioScan(benchmark::State& state) {
  const int beams = static_cast<int>(state.range(0));
  const int timed = static_cast<int>(state.range(1));
  const bool map_upkeep = state.range(2) != 0;  // 0: the map of before issue 19 (no carving, no refresh)
  const synth::SyntheticSequence seq(roomSpec(beams, 1.0 + 0.1 * timed + 0.1));
  LioOptions opts;
  opts.imu_noise = seq.spec().imu_error.noise;
  if (!map_upkeep) {
    opts.seen_through.enabled = false;
    opts.map.refresh_range_ratio = 0.0;
  }
  LioEstimator lio(opts);
  size_t imu_index = 0;
  int k = 0;
  auto feedImu = [&](int64_t t_end) {
    const auto& imu = seq.imu();
    bool past = false;
    while (imu_index < imu.size() && !past) {
      lio.addImu(imu[imu_index]);
      past = imu[imu_index++].utime > t_end;
    }
  };
  // untimed: initialisation and the first registered sweeps
  for (; k < 10; ++k) {
    feedImu(seq.scanEndUtime(k));
    lio.addScan(seq.scan(k));
  }
  std::vector<double> ms;
  size_t points = 0;
  for (auto _ : state) {
    const LidarScan scan = seq.scan(k);
    feedImu(seq.scanEndUtime(k));
    const auto t0 = std::chrono::steady_clock::now();
    const ScanResult r = lio.addScan(scan);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    benchmark::DoNotOptimize(r.state.pos);
    state.SetIterationTime(s);
    ms.push_back(s * 1e3);
    points += scan.points.size();
    if (r.status != ScanResult::Status::kTracked) state.SkipWithError("a sweep was not tracked");
    ++k;
  }
  reportPercentiles(state, ms);
  state.counters["points_per_sweep"] =
      static_cast<double>(points) / static_cast<double>(std::max<size_t>(1, ms.size()));
  state.counters["map_points"] = static_cast<double>(lio.map().numPoints());
}
// {beams, timed sweeps, map upkeep (seen-through carving and range refresh) on}
BENCHMARK(BM_LioScan)
    ->Args({16, 60, 1})
    ->Args({16, 60, 0})
    ->Iterations(60)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LioScan)
    ->Args({64, 30, 1})
    ->Args({64, 30, 0})
    ->Iterations(30)
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// ---- map structures ----
struct MapData {
  std::vector<Vec3> map_points;  // what the LIO's map holds after 30 sweeps
  std::vector<Vec3> sweep;       // one downsampled sweep (insertions and queries)
};

const MapData& largeMapData() {
  static const MapData data = [] {
    MapData d;
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> jitter(-0.05, 0.05), u(-30.0, 30.0);
    for (double x = -100.0; x < 100.0; x += 0.4)
      for (double y = -100.0; y < 100.0; y += 0.4)
        d.map_points.emplace_back(x + jitter(rng), y + jitter(rng), 0.01 * jitter(rng));
    for (int i = 0; i < 2300; ++i) d.sweep.emplace_back(u(rng), u(rng), 0.02 * jitter(rng));
    return d;
  }();
  return data;
}

const MapData& roomMapData() {
  static const MapData data = [] {
    MapData d;
    const synth::SyntheticSequence seq(roomSpec(16, 4.0));
    VoxelMap map;
    for (int k = 0; k < 30; ++k) {
      const LidarScan s = seq.scan(k + 6);
      const Pose3 T = seq.truth(seq.scanEndUtime(k + 6));
      std::vector<Vec3> world;
      for (const auto& p : s.points) world.push_back(T * p);
      std::vector<Vec3> reg;
      for (size_t i : firstPointPerVoxel(world, 0.5)) reg.push_back(world[i]);
      map.insert(reg);
      if (k == 29) d.sweep = reg;
    }
    d.map_points = map.points();
    return d;
  }();
  return data;
}

// range(0): 0 = the room map after 30 sweeps (~7k points), 1 = a 200 m x 200 m ground (250k)
const MapData& mapData(const benchmark::State& state) { return state.range(0) == 0 ? roomMapData() : largeMapData(); }

struct Cloud {
  const std::vector<Vec3>* pts;
  size_t count = ~size_t{0};  // points visible to the tree (the dynamic tree adds its initial ones)
  size_t kdtree_get_point_count() const { return std::min(count, pts->size()); }
  double kdtree_get_pt(size_t i, size_t dim) const { return (*pts)[i][static_cast<int>(dim)]; }
  template <class B>
  bool kdtree_get_bbox(B&) const {
    return false;
  }
};
using StaticTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 3>;
using DynamicTree = nanoflann::KDTreeSingleIndexDynamicAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 3>;

void BM_MapKnnVoxelMap(benchmark::State& state) {
  const MapData& d = mapData(state);
  VoxelMap map;
  map.insert(d.map_points);
  Vec3 nb[5];
  double d2[5];
  for (auto _ : state)
    for (const auto& q : d.sweep) benchmark::DoNotOptimize(map.knn(q, 5, 1.5, nb, d2));
  state.counters["queries"] = static_cast<double>(d.sweep.size());
  state.counters["map_points"] = static_cast<double>(d.map_points.size());
}
BENCHMARK(BM_MapKnnVoxelMap)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_MapKnnStaticKdTree(benchmark::State& state) {
  const MapData& d = mapData(state);
  Cloud c{&d.map_points};
  StaticTree tree(3, c, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  uint32_t idx[5];
  double d2[5];
  for (auto _ : state)
    for (const auto& q : d.sweep) benchmark::DoNotOptimize(tree.knnSearch(q.data(), 5, idx, d2));
  state.counters["queries"] = static_cast<double>(d.sweep.size());
}
BENCHMARK(BM_MapKnnStaticKdTree)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_MapKnnDynamicKdTree(benchmark::State& state) {
  const MapData& d = mapData(state);
  Cloud c{&d.map_points};
  DynamicTree tree(3, c, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  uint32_t idx[5];
  double d2[5];
  for (auto _ : state)
    for (const auto& q : d.sweep) {
      nanoflann::KNNResultSet<double, uint32_t> rs(5);
      rs.init(idx, d2);
      tree.findNeighbors(rs, q.data(), nanoflann::SearchParams());
      benchmark::DoNotOptimize(d2[0]);
    }
}
BENCHMARK(BM_MapKnnDynamicKdTree)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// Insertion of one sweep into a map of this size: voxel map (with its downsampling rule),
// static kd-tree (rebuild over map + sweep), dynamic kd-tree (add the sweep).
void BM_MapInsertVoxelMap(benchmark::State& state) {
  const MapData& d = mapData(state);
  for (auto _ : state) {
    state.PauseTiming();
    VoxelMap map;
    map.insert(d.map_points);
    std::vector<Vec3> shifted = d.sweep;
    for (auto& p : shifted) p += Vec3(0.13, 0.07, 0.0);
    state.ResumeTiming();
    benchmark::DoNotOptimize(map.insert(shifted));
  }
}
BENCHMARK(BM_MapInsertVoxelMap)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_MapInsertStaticKdTreeRebuild(benchmark::State& state) {
  const MapData& d = mapData(state);
  std::vector<Vec3> all = d.map_points;
  all.insert(all.end(), d.sweep.begin(), d.sweep.end());
  Cloud c{&all};
  for (auto _ : state) {
    StaticTree tree(3, c, nanoflann::KDTreeSingleIndexAdaptorParams(10));
    tree.buildIndex();
    benchmark::DoNotOptimize(&tree);
  }
}
BENCHMARK(BM_MapInsertStaticKdTreeRebuild)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_MapInsertDynamicKdTree(benchmark::State& state) {
  const MapData& d = mapData(state);
  std::vector<Vec3> all = d.map_points;
  all.insert(all.end(), d.sweep.begin(), d.sweep.end());
  Cloud c{&all, d.map_points.size()};
  for (auto _ : state) {
    state.PauseTiming();
    c.count = d.map_points.size();
    auto tree = std::make_unique<DynamicTree>(3, c, nanoflann::KDTreeSingleIndexAdaptorParams(10), all.size());
    c.count = all.size();
    state.ResumeTiming();
    tree->addPoints(static_cast<uint32_t>(d.map_points.size()), static_cast<uint32_t>(all.size() - 1));
    benchmark::DoNotOptimize(tree.get());
  }
}
BENCHMARK(BM_MapInsertDynamicKdTree)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
