// Per-candidate and pose-graph benchmarks of livo-loop (issue 8 bars) on real keyframe clouds: the
// shared KITTI 07 keyframes (../shared/data/lidar/kitti_07_dump, graph.txt poses), registering
// keyframe 1 onto keyframe 0 with the LoopCloser's default options (coarse voxel 1 m, fine voxel
// 0.4 m). Stages:
//   Coarse/Cached      matching + max clique + Quatro (features cached per keyframe)    <= 5 ms
//   Coarse/WithFpfh    the above plus computing the source keyframe's FPFH features     <= 60 ms
//   Fine/Gicp          Nano-GICP from the coarse result (clouds and covariances cached)  <= 15 ms
//   PoseGraph/2000     Ceres optimisation of 2,000 keyframes with loop edges            <= 30 ms
// Run: build/tests/loop/livo_loop_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "loop_closer.hpp"
#include "loop_registration.hpp"
#include "real_scans.hpp"
#include "voxel_grid.hpp"

namespace livo::loop {
namespace {
using namespace livo::loop::testing;

const std::string kDump = std::string(LIVO_SHARED_DATA) + "/lidar/kitti_07_dump/";

struct Keyframe {
  Points levelled;
  CoarseFeatures coarse;
  GicpCloud fine;
};

Keyframe load(int i) {
  char name[64];
  std::snprintf(name, sizeof(name), "%06d/points.bin", i);
  Keyframe kf;
  kf.levelled = readXyzBin(kDump + name);  // KITTI velodyne frames are close to level
  const LoopCloserOptions defaults;
  kf.coarse = computeCoarseFeatures(kf.levelled, defaults.coarse);
  kf.fine = GicpCloud::build(voxelDownsample(kf.levelled, defaults.fine_voxel_size), defaults.covariance_neighbors);
  return kf;
}

const std::vector<Keyframe>& keyframes() {
  static const std::vector<Keyframe> kfs = [] {
    std::vector<Keyframe> v;
    for (int i = 0; i < 2; ++i) v.push_back(load(i));
    return v;
  }();
  return kfs;
}

void BM_CoarseCached(benchmark::State& state) {
  const auto& kf = keyframes();
  const LoopRegistrationOptions opt;
  int inliers = 0;
  for (auto _ : state) {
    const Correspondences m = matchFeatures(kf[1].coarse.features, kf[0].coarse.features, opt.matching);
    const QuatroResult r = quatroRegister(kf[1].coarse.points, kf[0].coarse.points, m, opt.quatro);
    inliers = r.num_inliers;
    benchmark::DoNotOptimize(r);
  }
  state.counters["features"] = static_cast<double>(kf[1].coarse.points.size());
  state.counters["inliers"] = inliers;
}
BENCHMARK(BM_CoarseCached)->Name("Coarse/Cached")->Unit(benchmark::kMillisecond);

// The two parts of Coarse/Cached, for profiling.
void BM_Matching(benchmark::State& state) {
  const auto& kf = keyframes();
  const LoopRegistrationOptions opt;
  size_t n = 0;
  for (auto _ : state) {
    const Correspondences m = matchFeatures(kf[1].coarse.features, kf[0].coarse.features, opt.matching);
    n = m.size();
    benchmark::DoNotOptimize(m);
  }
  state.counters["matches"] = static_cast<double>(n);
}
BENCHMARK(BM_Matching)->Name("Coarse/Matching")->Unit(benchmark::kMillisecond);

void BM_Quatro(benchmark::State& state) {
  const auto& kf = keyframes();
  const LoopRegistrationOptions opt;
  const Correspondences m = matchFeatures(kf[1].coarse.features, kf[0].coarse.features, opt.matching);
  int clique = 0;
  for (auto _ : state) {
    const QuatroResult r = quatroRegister(kf[1].coarse.points, kf[0].coarse.points, m, opt.quatro);
    clique = r.num_clique;
    benchmark::DoNotOptimize(r);
  }
  state.counters["clique"] = clique;
}
BENCHMARK(BM_Quatro)->Name("Coarse/Quatro")->Unit(benchmark::kMillisecond);

void BM_CoarseWithFpfh(benchmark::State& state) {
  const auto& kf = keyframes();
  const LoopCloserOptions defaults;
  const LoopRegistrationOptions opt;
  for (auto _ : state) {
    const CoarseFeatures source = computeCoarseFeatures(kf[1].levelled, defaults.coarse);
    const Correspondences m = matchFeatures(source.features, kf[0].coarse.features, opt.matching);
    const QuatroResult r = quatroRegister(source.points, kf[0].coarse.points, m, opt.quatro);
    benchmark::DoNotOptimize(r);
  }
  state.counters["raw_points"] = static_cast<double>(kf[1].levelled.size());
}
BENCHMARK(BM_CoarseWithFpfh)->Name("Coarse/WithFpfh")->Unit(benchmark::kMillisecond);

void BM_Fine(benchmark::State& state) {
  const auto& kf = keyframes();
  const LoopRegistrationOptions opt;
  const Correspondences m = matchFeatures(kf[1].coarse.features, kf[0].coarse.features, opt.matching);
  const QuatroResult coarse = quatroRegister(kf[1].coarse.points, kf[0].coarse.points, m, opt.quatro);
  int iterations = 0;
  for (auto _ : state) {
    const GicpResult r = gicpRegister(kf[1].fine, kf[0].fine, coarse.T_target_source, opt.gicp);
    iterations = r.iterations;
    benchmark::DoNotOptimize(r);
  }
  state.counters["source_points"] = static_cast<double>(kf[1].fine.size());
  state.counters["iterations"] = iterations;
}
BENCHMARK(BM_Fine)->Name("Fine/Gicp")->Unit(benchmark::kMillisecond);

// A 2,000-keyframe drive around a 1.6 km square with noisy odometry edges and a loop edge every
// 50 keyframes once the square is revisited; each iteration optimises the graph from the
// odometry initialisation (the node's first optimisation after a loop, the expensive case).
void BM_PoseGraph(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  std::mt19937 rng(7);
  std::normal_distribution<double> nr(0.0, 2e-3), nt(0.0, 2e-2);
  std::vector<Pose3> truth(n), odom(n);
  const int side = 250;  // keyframes per side of the square, 2 m apart
  for (int i = 0; i < n; ++i) {
    const int lap_pos = i % (4 * side);
    const int s = lap_pos / side, k = lap_pos % side;
    const double yaw = s * M_PI / 2;
    Vec3 corner[4] = {Vec3(0, 0, 0), Vec3(2.0 * side, 0, 0), Vec3(2.0 * side, 2.0 * side, 0), Vec3(0, 2.0 * side, 0)};
    truth[i] = Pose3::Identity();
    truth[i].linear() = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
    truth[i].translation() = corner[s] + truth[i].linear() * Vec3(2.0 * k, 0, 0);
  }
  odom[0] = truth[0];
  std::vector<Pose3> rel(n);
  for (int i = 1; i < n; ++i) {
    Pose3 d = truth[i - 1].inverse() * truth[i];
    d.linear() = d.linear() * so3::Exp(Vec3(nr(rng), nr(rng), nr(rng)));
    d.translation() += Vec3(nt(rng), nt(rng), nt(rng));
    rel[i] = d;
    odom[i] = odom[i - 1] * d;
  }
  Vec6 os, ls;
  os << Vec3::Constant(2e-3), Vec3::Constant(2e-2);
  ls << Vec3::Constant(5e-3), Vec3::Constant(5e-2);
  const Mat6 oi = os.cwiseInverse().cwiseAbs2().asDiagonal(), li = ls.cwiseInverse().cwiseAbs2().asDiagonal();
  int loops = 0;
  for (auto _ : state) {
    state.PauseTiming();
    PoseGraph g;
    for (int i = 0; i < n; ++i) {
      g.addNode(i, odom[i]);
      if (i > 0) g.addEdge({i - 1, i, rel[i], oi, false});
    }
    loops = 0;
    for (int i = 4 * side; i < n; i += 50) {
      g.addEdge({i - 4 * side, i, truth[i - 4 * side].inverse() * truth[i], li, true});
      ++loops;
    }
    state.ResumeTiming();
    const PoseGraphSummary s = g.optimize();
    benchmark::DoNotOptimize(s);
  }
  state.counters["loops"] = loops;
}
BENCHMARK(BM_PoseGraph)->Name("PoseGraph")->Arg(2000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace livo::loop

BENCHMARK_MAIN();
