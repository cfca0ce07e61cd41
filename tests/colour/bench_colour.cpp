// bench_colour: CPU cost of the colouring core (ColouringPipeline) per VLP-16 sweep and per
// 640x480 image on the room run (true registered scans and poses, as in map-bars). Not a ctest
// test:  build/bin/bench_colour --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// Each iteration times one event of the kind benchmarked; the other events of the run are fed
// between, untimed, in time order; the pipeline restarts when the recording is used up.
// Bar: a sweep and its two images within 100 ms of one core (10 Hz sweeps, 20 Hz images).
#include <benchmark/benchmark.h>

#include <ctime>
#include <memory>
#include <string>

#include "../octomap/sim_recording.hpp"
#include "livo/colour/colouring_pipeline.hpp"

namespace {

// the iteration time is the process CPU time (all threads, e.g. OpenCV workers): the cost in
// core time, robust to a shared machine
double cpuSeconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

using livo::colour::ColouringPipeline;

void events(benchmark::State& state, int timed_kind, bool with_images) {
  const livo_bench::SimRecording& rec = livo_bench::roomRecording();
  const auto& setup = livo_bench::roomSetup();
  livo::colour::ColourOptions co;
  co.vignetting = setup.options.camera.vignetting;
  co.reference_exposure_s = setup.options.camera.exposure_time;
  std::unique_ptr<ColouringPipeline> pipe;
  size_t next = rec.events.size();
  std::string error;
  auto feed = [&](const std::pair<int, size_t>& e) {
    if (e.first == 0) {
      pipe->addPose(rec.poses[e.second].utime, rec.poses[e.second].T_W_I);
    } else if (e.first == 1) {
      const livo_bench::WorldSweep& s = rec.sweeps[e.second];
      livo::RegisteredScanView v;
      v.utime = s.utime, v.cloud_utime = s.cloud_utime, v.T_W_I = s.T_W_I;
      v.num_points = static_cast<int>(s.x.size());
      v.x = s.x.data(), v.y = s.y.data(), v.z = s.z.data(), v.time_offset = s.time_offset.data();
      pipe->addScan(v, &error);
    } else {
      const livo::sim::CameraImage& m = rec.images[e.second];
      livo::colour::ColourImage img;
      img.utime = m.utime;
      img.exposure_time = m.exposure_time;
      img.pixels = cv::Mat(m.height, m.width, m.color ? CV_8UC3 : CV_8UC1, const_cast<uint8_t*>(m.data.data())).clone();
      pipe->addImage(std::move(img), &error);
    }
  };
  for (auto _ : state) {
    // untimed: everything up to the next event of the benchmarked kind
    for (;;) {
      if (next == rec.events.size()) {
        pipe = std::make_unique<ColouringPipeline>(co, *setup.rig.camera);
        next = 0;
      }
      if (rec.events[next].first == timed_kind) break;
      if (with_images || rec.events[next].first != 2) feed(rec.events[next]);
      ++next;
    }
    const double t0 = cpuSeconds();
    feed(rec.events[next++]);
    state.SetIterationTime(cpuSeconds() - t0);
  }
}

// A sweep with the images it completes: an image is coloured once the sweeps covering its time
// window are in, i.e. inside addScan (about two images per sweep at 20 Hz / 10 Hz).
void BM_ColourScanWithImages(benchmark::State& state) { events(state, 1, true); }
// A sweep alone (no images in the run): the map update; the difference to the above is the
// images' colouring (per image: half of it).
void BM_ColourScanOnly(benchmark::State& state) { events(state, 1, false); }
// addImage itself: decoding is done by the node; the pipeline only queues the image.
void BM_ColourImageQueue(benchmark::State& state) { events(state, 2, true); }
BENCHMARK(BM_ColourScanWithImages)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(80);
BENCHMARK(BM_ColourScanOnly)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(80);
BENCHMARK(BM_ColourImageQueue)->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(160);

}  // namespace

BENCHMARK_MAIN();
