// Per-candidate and pose-graph benchmarks of livo-loop (issue 8 bars) on real keyframe clouds: the
// shared KITTI 07 keyframes (../shared/data/lidar/kitti_07_dump, graph.txt poses), registering
// keyframe 1 onto keyframe 0 with the LoopCloser's default options. Stages:
//   Features/Coarse         ISS keypoints + FPFH descriptors of one keyframe (once per registered keyframe)
//   Features/Keypoints      its first stage (voxels, normals, ISS) and whether any keypoint will have a
//                           descriptor: what a keyframe that might be registered costs before it is
//   Features/Describe       the second stage: the keypoints' FPFH descriptors
//   Features/Describable    of Features/Keypoints, the exact test whether any keypoint will have one
//   Coarse/Cached           matching + max clique + Quatro (features cached per keyframe)   <= 5 ms
//   Coarse/WithFpfh         the above plus computing the source keyframe's features         <= 60 ms
//   Fine/Gicp               Nano-GICP from the coarse result (clouds, covariances, trees cached) <= 15 ms
//   PoseGraph/Incremental   the node's solve after a loop at 2,000 keyframes                <= 30 ms
//   PoseGraph/Batch         for reference: all loops of 2,000 keyframes at once, cold
// Run (one core): taskset -c 0 build-dir/bin/livo_loop_bench --benchmark_repetitions=5
// --benchmark_report_aggregates_only=true
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "livo/loop/loop_closer.hpp"
#include "livo/loop/loop_registration.hpp"
#include "livo/loop/voxel_grid.hpp"
#include "real_scans.hpp"

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
  kf.fine = GicpCloud::build(centroidPerVoxel(kf.levelled, defaults.fine_voxel_size), defaults.covariance_neighbors);
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

// Times `make` and reports the size of what it makes as counter `name`.
template <class Make>
void timeAndCount(benchmark::State& state, const char* name, const Make& make) {
  size_t n = 0;
  for (auto _ : state) {
    const auto made = make();
    n = made.size();
    benchmark::DoNotOptimize(made);
  }
  state.counters[name] = static_cast<double>(n);
}

void BM_Features(benchmark::State& state) {
  const auto& kf = keyframes();
  const LoopCloserOptions defaults;
  timeAndCount(state, "keypoints", [&] { return computeCoarseFeatures(kf[1].levelled, defaults.coarse); });
  state.counters["raw_points"] = static_cast<double>(kf[1].levelled.size());
}
BENCHMARK(BM_Features)->Name("Features/Coarse")->Unit(benchmark::kMillisecond);

void BM_FeaturesKeypoints(benchmark::State& state) {
  const auto& kf = keyframes();
  const LoopCloserOptions defaults;
  size_t n = 0;
  bool describable = false;
  for (auto _ : state) {
    const CoarseKeypoints k = detectCoarseKeypoints(kf[1].levelled, defaults.coarse);
    describable = anyKeypointDescribable(k, defaults.coarse);
    n = k.keys.size();
    benchmark::DoNotOptimize(describable);
  }
  state.counters["keypoints"] = static_cast<double>(n);
  state.counters["describable"] = describable;
}
BENCHMARK(BM_FeaturesKeypoints)->Name("Features/Keypoints")->Unit(benchmark::kMillisecond);

void BM_FeaturesDescribe(benchmark::State& state) {
  const auto& kf = keyframes();
  const LoopCloserOptions defaults;
  const CoarseKeypoints k = detectCoarseKeypoints(kf[1].levelled, defaults.coarse);
  timeAndCount(state, "keypoints", [&] { return describeCoarseKeypoints(k, defaults.coarse); });
}
BENCHMARK(BM_FeaturesDescribe)->Name("Features/Describe")->Unit(benchmark::kMillisecond);

void BM_FeaturesDescribable(benchmark::State& state) {
  const auto& kf = keyframes();
  const LoopCloserOptions defaults;
  const CoarseKeypoints k = detectCoarseKeypoints(kf[1].levelled, defaults.coarse);
  for (auto _ : state) benchmark::DoNotOptimize(anyKeypointDescribable(k, defaults.coarse));
}
BENCHMARK(BM_FeaturesDescribable)->Name("Features/Describable")->Unit(benchmark::kMicrosecond);

void BM_CoarseCached(benchmark::State& state) {
  const auto& kf = keyframes();
  const LoopRegistrationOptions opt;
  int inliers = 0;
  for (auto _ : state) {
    const Correspondences m = matchDescriptors(kf[1].coarse.descriptors, kf[0].coarse.descriptors, opt.matching);
    const QuatroResult r = quatroRegister(kf[1].coarse.points, kf[0].coarse.points, m, opt.quatro);
    inliers = r.num_inliers;
    benchmark::DoNotOptimize(r);
  }
  state.counters["keypoints"] = static_cast<double>(kf[1].coarse.size());
  state.counters["inliers"] = inliers;
}
BENCHMARK(BM_CoarseCached)->Name("Coarse/Cached")->Unit(benchmark::kMillisecond);

// The two parts of Coarse/Cached, for profiling.
void BM_Matching(benchmark::State& state) {
  const auto& kf = keyframes();
  const LoopRegistrationOptions opt;
  timeAndCount(state, "matches",
               [&] { return matchDescriptors(kf[1].coarse.descriptors, kf[0].coarse.descriptors, opt.matching); });
}
BENCHMARK(BM_Matching)->Name("Coarse/Matching")->Unit(benchmark::kMillisecond);

void BM_Quatro(benchmark::State& state) {
  const auto& kf = keyframes();
  const LoopRegistrationOptions opt;
  const Correspondences m = matchDescriptors(kf[1].coarse.descriptors, kf[0].coarse.descriptors, opt.matching);
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
    const Correspondences m = matchDescriptors(source.descriptors, kf[0].coarse.descriptors, opt.matching);
    const QuatroResult r = quatroRegister(source.points, kf[0].coarse.points, m, opt.quatro);
    benchmark::DoNotOptimize(r);
  }
  state.counters["raw_points"] = static_cast<double>(kf[1].levelled.size());
}
BENCHMARK(BM_CoarseWithFpfh)->Name("Coarse/WithFpfh")->Unit(benchmark::kMillisecond);

void BM_Fine(benchmark::State& state) {
  const auto& kf = keyframes();
  const LoopRegistrationOptions opt;
  const Correspondences m = matchDescriptors(kf[1].coarse.descriptors, kf[0].coarse.descriptors, opt.matching);
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

// A 2,000-keyframe drive around a 500 m square (2 m between keyframes) with noisy odometry edges
// (2 mrad, 2 cm per edge) and, once the square is revisited, a loop edge every 50 keyframes.
struct SquareDrive {
  std::vector<Pose3> truth, odom, rel;
  Mat6 odometry_information, loop_information;
  static constexpr int kSide = 250;  // keyframes per side
  explicit SquareDrive(int n) : truth(n), odom(n), rel(n) {
    std::mt19937 rng(7);
    std::normal_distribution<double> nr(0.0, 2e-3), nt(0.0, 2e-2);
    const Vec3 corner[4] = {Vec3(0, 0, 0), Vec3(2.0 * kSide, 0, 0), Vec3(2.0 * kSide, 2.0 * kSide, 0),
                            Vec3(0, 2.0 * kSide, 0)};
    for (int i = 0; i < n; ++i) {
      const int lap_pos = i % (4 * kSide);
      const int s = lap_pos / kSide, k = lap_pos % kSide;
      truth[i] = Pose3::Identity();
      truth[i].linear() = Eigen::AngleAxisd(s * M_PI / 2, Vec3::UnitZ()).toRotationMatrix();
      truth[i].translation() = corner[s] + truth[i].linear() * Vec3(2.0 * k, 0, 0);
    }
    odom[0] = truth[0];
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
    odometry_information = os.cwiseInverse().cwiseAbs2().asDiagonal();
    loop_information = ls.cwiseInverse().cwiseAbs2().asDiagonal();
  }
  static bool isLoop(int i) { return i >= 4 * kSide && i % 50 == 0; }
  /// Node i as LoopCloser adds it: the previous (optimised) pose composed with the odometry step.
  void addNode(PoseGraph& g, int i) const {
    g.addNode(i, i == 0 ? odom[0] : Pose3(g.pose(i - 1) * rel[i]));
    if (i > 0) g.addEdge({i - 1, i, rel[i], odometry_information, false});
  }
  void addLoop(PoseGraph& g, int i) const {
    g.addEdge({i - 4 * kSide, i, truth[i - 4 * kSide].inverse() * truth[i], loop_information, true});
  }
};

// Times the solve of the graph `build` makes (untimed; it returns the number of loops it added),
// reporting the loops and the solver's iterations.
template <class Build>
void timeSolve(benchmark::State& state, const Build& build) {
  int iterations = 0, loops = 0;
  for (auto _ : state) {
    state.PauseTiming();
    PoseGraph g;
    loops = build(g);
    state.ResumeTiming();
    const PoseGraphSummary s = g.optimize();
    iterations = s.iterations;
    benchmark::DoNotOptimize(s);
  }
  state.counters["loops"] = loops;
  state.counters["solver_iterations"] = iterations;
}

// The node's schedule (the paper's): the graph is optimised whenever a loop is added, each solve
// warm-started from the previous one. Timed: the solve after the loop at the 2,000th keyframe, on a
// graph last optimised at the previous loop, 49 keyframes earlier.
void BM_PoseGraphIncremental(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const SquareDrive drive(n);
  timeSolve(state, [&](PoseGraph& g) {
    int loops = 0;
    for (int i = 0; i < n; ++i) {
      drive.addNode(g, i);
      if (SquareDrive::isLoop(i) || i == n - 1) {
        drive.addLoop(g, i);
        ++loops;
        if (i < n - 1) g.optimize();
      }
    }
    return loops;
  });
}
BENCHMARK(BM_PoseGraphIncremental)
    ->Name("PoseGraph/Incremental")
    ->Arg(2000)
    ->Iterations(5)
    ->Unit(benchmark::kMillisecond);

// For reference, the cold case: all loops of the 2,000 keyframes at once, from the odometry.
void BM_PoseGraphBatch(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const SquareDrive drive(n);
  timeSolve(state, [&](PoseGraph& g) {
    int loops = 0;
    for (int i = 0; i < n; ++i) g.addNode(i, drive.odom[i]);
    for (int i = 1; i < n; ++i) g.addEdge({i - 1, i, drive.rel[i], drive.odometry_information, false});
    for (int i = 0; i < n; ++i)
      if (SquareDrive::isLoop(i)) {
        drive.addLoop(g, i);
        ++loops;
      }
    return loops;
  });
}
BENCHMARK(BM_PoseGraphBatch)->Name("PoseGraph/Batch")->Arg(2000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace livo::loop

BENCHMARK_MAIN();
