// Per-image time of the VIO core (Google Benchmark, not a ctest test): the simulated room walk
// (config/sim/room.yaml) rendered at 640x512, REGISTERED_SCANs from the true poses at 10 Hz,
// and at every image (20 Hz) a prior 1 cm / 0.2 deg off the truth. Each iteration times one
// VioEstimator::processImage (pyramid, selection, coarse-to-fine update, map maintenance) in
// process CPU time; the counters give the median and p90 per image and the map it worked on
// (points in view, patches in the update, map size, share of valid updates). Images of the first
// second only build the map and are not timed.
//
//   build/bin/livo_vio_bench --benchmark_filter=VioImage
#include <benchmark/benchmark.h>

#include <algorithm>
#include <ctime>
#include <memory>
#include <vector>

#include "livo/vio/vio_estimator.hpp"
#include "sim_fixture.hpp"

using namespace livo;
using namespace livo::vio;

namespace {

double cpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

struct Frame {
  double t;
  GreyImage image;
  FilterState prior;  // with the rig's camera calibration
  Vec3 body_rate = Vec3::Zero();
  std::vector<Vec3> scan;  // the sweep that ended just before the image, if one did
  int64_t scan_utime = 0;
};

// 6 s of the walk from t = 5 s (moving at about 1 m/s), rendered once.
const std::vector<Frame>& frames() {
  static const std::vector<Frame> f = [] {
    const livo_test::SimScene s("config/sim/room.yaml", 512);
    std::vector<Frame> out;
    const double t0 = 5.0;
    for (int k = 0; k < 120; ++k) {
      Frame fr;
      fr.t = t0 + 0.05 * k;
      fr.image = s.image(fr.t, static_cast<uint64_t>(k));
      StateVector d = StateVector::Zero();
      d.head<3>() =
          Vec3(std::sin(1.3 * k), std::cos(0.7 * k), std::sin(0.4 * k + 1.0)).normalized() * (0.2 * M_PI / 180.0);
      d.segment<3>(3) = Vec3(std::cos(1.1 * k), std::sin(0.9 * k), std::cos(0.3 * k + 2.0)).normalized() * 0.01;
      fr.prior = s.trueState(fr.t).boxplus(d);
      fr.body_rate = s.bodyRate(fr.t);
      if (k % 2 == 0) {
        fr.scan = s.sweep(fr.t - 0.1, static_cast<uint64_t>(k));
        fr.scan_utime = s.utime(fr.t);
      }
      out.push_back(std::move(fr));
    }
    return out;
  }();
  return f;
}

void reportPercentiles(benchmark::State& state, std::vector<double> ms) {
  if (ms.empty()) return;
  std::sort(ms.begin(), ms.end());
  state.counters["median_ms"] = ms[ms.size() / 2];
  state.counters["p90_ms"] = ms[std::min(ms.size() - 1, ms.size() * 9 / 10)];
  state.counters["max_ms"] = ms.back();
}

// range(0): the grid cell (px) of tracked and new points: 32 (the default, ~120 patches of ~200
// points in view) or 16 (a denser map: ~4x the points)
void BM_VioImage(benchmark::State& state) {
  const std::vector<Frame>& fr = frames();
  VioOptions options;
  options.selection.grid_cell_px = options.maintenance.new_point_cell_px = static_cast<int>(state.range(0));
  const int warmup = 20;
  const StateCovariance P = livo_test::priorCovariance(0.005, 0.02);  // the calibration held fixed
  const CameraRig camera = livo_test::SimScene("config/sim/room.yaml", 512).camera();
  std::unique_ptr<VioEstimator> vio;
  size_t next = fr.size();
  std::vector<double> ms;
  double tracked = 0.0, in_view = 0.0, map_points = 0.0, valid = 0.0;
  auto feed = [&](const Frame& f) {
    if (!f.scan.empty()) vio->addScan(f.scan_utime, f.scan);
  };
  for (auto _ : state) {
    if (next == fr.size()) {
      vio = std::make_unique<VioEstimator>(options, camera);
      for (next = 0; next < static_cast<size_t>(warmup); ++next) {
        feed(fr[next]);
        vio->processImage(fr[next].image, fr[next].prior, P, fr[next].body_rate);
      }
    }
    const Frame& f = fr[next++];
    feed(f);
    const double t0 = cpuSeconds();
    const ImageResult r = vio->processImage(f.image, f.prior, P, f.body_rate);
    const double dt = cpuSeconds() - t0;
    state.SetIterationTime(dt);
    ms.push_back(dt * 1e3);
    tracked += r.patches;
    in_view += r.selection.in_view;
    map_points += static_cast<double>(r.map_points);
    valid += r.valid;
  }
  const double n = static_cast<double>(ms.size());
  reportPercentiles(state, ms);
  state.counters["patches"] = tracked / n;
  state.counters["in_view"] = in_view / n;
  state.counters["map_points"] = map_points / n;
  state.counters["valid"] = valid / n;
}
BENCHMARK(BM_VioImage)->Arg(32)->Arg(16)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(200);

}  // namespace

BENCHMARK_MAIN();
