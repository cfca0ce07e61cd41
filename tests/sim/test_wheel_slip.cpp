// Wheel slip (sim.wheel.slip): episodes arrive at the configured rate, last within the configured
// durations and change the affected wheels' readings by the configured factors (spinning +min..max,
// or locked at 0); they come from a random stream of their own, so the readings outside them are
// bit for bit those without slip, and slip off (absent or rate 0) is exactly the old model. The
// schedule is a function of the seed only.
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "livo/sim/simulation_setup.hpp"
#include "livo/sim/simulator.hpp"
#include "livo/sim/wheel_model.hpp"
#include "sim_test_support.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

WheelSlipOptions slipEvery(double rate_per_min) {
  WheelSlipOptions o;
  o.rate_per_min = rate_per_min;
  return o;
}

/// Episodes starting before t_end, queried at 50 Hz from the start.
std::vector<WheelSlipEpisode> episodesUntil(WheelSlip& slip, double t_end) {
  for (double t = 0.0; t < t_end; t += 0.02) slip.episodeAt(t);
  std::vector<WheelSlipEpisode> out;
  for (const WheelSlipEpisode& e : slip.episodes())
    if (e.start_s < t_end) out.push_back(e);
  return out;
}

}  // namespace

TEST(WheelSlip, EpisodesArriveAtTheConfiguredRateWithTheConfiguredDurationsAndFactors) {
  const WheelSlipOptions o = slipEvery(3.0);  // a gap of 20 s on average
  WheelSlip slip(o, Random(11, 5));
  const double hours = 2.0, t_end = hours * 3600.0;
  const std::vector<WheelSlipEpisode> episodes = episodesUntil(slip, t_end);
  // a renewal process: mean gap 60 / rate, mean duration (min + max) / 2
  const double expected = t_end / (60.0 / o.rate_per_min + 0.5 * (o.min_duration_s + o.max_duration_s));
  EXPECT_NEAR(static_cast<double>(episodes.size()), expected, 3.0 * std::sqrt(expected));
  int both = 0, locked = 0;
  double gap_sum = 0.0;
  for (size_t i = 0; i < episodes.size(); ++i) {
    const WheelSlipEpisode& e = episodes[i];
    SCOPED_TRACE(i);
    EXPECT_GE(e.end_s - e.start_s, o.min_duration_s);
    EXPECT_LE(e.end_s - e.start_s, o.max_duration_s);
    if (i > 0) {
      EXPECT_GT(e.start_s, episodes[i - 1].end_s);  // never overlapping
      gap_sum += e.start_s - episodes[i - 1].end_s;
    }
    ASSERT_TRUE(e.left || e.right);
    both += e.left && e.right;
    locked += e.lock;
    for (const auto& [affected, factor] : {std::pair{e.left, e.left_factor}, std::pair{e.right, e.right_factor}}) {
      if (!affected) {
        EXPECT_EQ(factor, 1.0);
      } else if (e.lock) {
        EXPECT_EQ(factor, 0.0);
      } else {
        EXPECT_GE(factor, 1.0 + o.min_spin);
        EXPECT_LE(factor, 1.0 + o.max_spin);
      }
    }
  }
  const double n = static_cast<double>(episodes.size());
  EXPECT_NEAR(gap_sum / (n - 1.0), 60.0 / o.rate_per_min, 0.2 * 60.0 / o.rate_per_min);
  EXPECT_NEAR(both / n, o.both_probability, 0.1);
  EXPECT_NEAR(locked / n, o.lock_probability, 0.1);
  // the reading at a time inside an episode is scaled, outside it is untouched
  const WheelSlipEpisode& e = episodes[3];
  WheelReading r;
  r.left_speed = 2.0, r.right_speed = 3.0;
  EXPECT_TRUE(slip.apply(0.5 * (e.start_s + e.end_s), &r));
  EXPECT_EQ(r.left_speed, 2.0 * e.left_factor);
  EXPECT_EQ(r.right_speed, 3.0 * e.right_factor);
  WheelReading q;
  q.left_speed = 2.0, q.right_speed = 3.0;
  EXPECT_FALSE(slip.apply(e.end_s + 1e-9, &q));
  EXPECT_EQ(q.left_speed, 2.0);
  EXPECT_EQ(q.right_speed, 3.0);
}

TEST(WheelSlip, TheScheduleDependsOnTheStreamOnlyNotOnTheQueries) {
  const WheelSlipOptions o = slipEvery(10.0);
  WheelSlip forward(o, Random(5, 5)), backward(o, Random(5, 5)), other(o, Random(6, 5));
  const std::vector<WheelSlipEpisode> a = episodesUntil(forward, 300.0);
  // backwards from the end, at other times
  std::vector<bool> slipping_b;
  for (double t = 299.99; t >= 0.0; t -= 0.013) slipping_b.push_back(backward.episodeAt(t).has_value());
  const std::vector<WheelSlipEpisode> b = episodesUntil(backward, 300.0);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GE(a.size(), 30u);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].start_s, b[i].start_s);
    EXPECT_EQ(a[i].end_s, b[i].end_s);
    EXPECT_EQ(a[i].left_factor, b[i].left_factor);
    EXPECT_EQ(a[i].right_factor, b[i].right_factor);
  }
  size_t k = 0;
  for (double t = 299.99; t >= 0.0; t -= 0.013, ++k) EXPECT_EQ(slipping_b[k], forward.episodeAt(t).has_value()) << t;
  const std::vector<WheelSlipEpisode> c = episodesUntil(other, 300.0);
  EXPECT_NE(a.front().start_s, c.front().start_s);  // another seed, another schedule
}

namespace {

/// A car on a 200 x 100 m block at 5 m/s with a noise-free IMU and a 50 Hz wheel encoder (2 cm/s
/// noise, scale errors), no LiDAR and no camera; `slip` is put under sim.wheel as it is.
std::string carConfig(const std::string& slip) {
  return R"(
rig:
  imu: {rate_hz: 200, gyro_noise_density: 0, gyro_random_walk: 0, accel_noise_density: 0, accel_random_walk: 0, gravity: 9.81}
  wheel: {rate_hz: 50, track_width: 1.6, speed_noise_std: 0.02, T_I_B: {translation: [-1.2, 0, -1.5], rpy_deg: [0, 0, 0]}}
sim:
  duration_s: 600
)" + test::boxRoomScene() +
         R"(  trajectory: {type: car, waypoints: [0, 0, 1.8, 200, 0, 1.8, 200, 100, 1.8, 0, 100, 1.8], speed: 5, control_spacing: 8}
  wheel:
    left_scale: 1.01
    right_scale: 0.995
)" + slip;
}

std::vector<WheelReading> wheelReadings(const std::string& slip, uint64_t seed = 1) {
  SimOverrides o;
  o.seed = seed;
  const SimulationSetup setup = loadSimulation(Config::fromString(carConfig(slip), "slip.yaml"), "", o);
  struct Wheels : SensorDataSink {
    std::vector<WheelReading> wheel;
    void write(const ImuReading&) override {}
    void write(const PoseReading&) override {}
    void write(const WheelReading& m) override { wheel.push_back(m); }
    void write(const LidarSweep&) override {}
    void write(const CameraImage&) override {}
  } sink;
  Simulator(setup).run(sink);
  return sink.wheel;
}

bool same(const WheelReading& a, const WheelReading& b) {
  return a.utime == b.utime && a.left_speed == b.left_speed && a.right_speed == b.right_speed;
}

}  // namespace

TEST(WheelSlip, SimulatedSpeedsDeviateFromTheSlipFreeOnesInBoundedEpisodesAtTheConfiguredRate) {
  const std::vector<WheelReading> plain = wheelReadings("");
  ASSERT_EQ(plain.size(), 600u * 50u + 1u);
  // off: absent, or a zero rate, is the model without slip bit for bit
  const std::vector<WheelReading> zero = wheelReadings("    slip: {rate_per_min: 0}\n");
  ASSERT_EQ(zero.size(), plain.size());
  for (size_t i = 0; i < plain.size(); ++i) ASSERT_TRUE(same(zero[i], plain[i])) << i;

  const std::string slip =
      "    slip: {rate_per_min: 6, duration_s: [0.2, 1.5], spin: [0.1, 0.4], lock_probability: 0.25, "
      "both_probability: 0.3}\n";
  const std::vector<WheelReading> slipping = wheelReadings(slip);
  ASSERT_EQ(slipping.size(), plain.size());
  // episodes: maximal runs of samples that differ from the slip-free ones
  struct Run {
    size_t first = 0, last = 0;
  };
  std::vector<Run> runs;
  size_t deviating = 0;
  for (size_t i = 0; i < plain.size(); ++i) {
    ASSERT_EQ(slipping[i].utime, plain[i].utime);
    if (same(slipping[i], plain[i])) continue;  // outside the episodes: the same noise, bit for bit
    ++deviating;
    if (!runs.empty() && runs.back().last + 1 == i)
      runs.back().last = i;
    else
      runs.push_back({i, i});
    // a wheel is off by (factor - 1) x its true speed: +10..40 % spinning, -100 % locked (noise 2 cm/s
    // at 5 m/s: 0.4 %; the car stands still for 2 s and ramps up for 2 s, so only from 4 s on)
    if (plain[i].utime - plain.front().utime < 4'000'000) continue;
    for (const auto& [s, p] : {std::pair{slipping[i].left_speed, plain[i].left_speed},
                               std::pair{slipping[i].right_speed, plain[i].right_speed}}) {
      const double relative = (s - p) / p;
      if (s == p) continue;  // this wheel is not affected
      const bool spinning = relative > 0.1 - 0.02 && relative < 0.4 + 0.02;
      const bool locked = std::abs(relative + 1.0) < 0.02;
      EXPECT_TRUE(spinning || locked) << "sample " << i << ": " << s << " against " << p;
    }
  }
  // about the configured rate: one episode per 10 s of grip plus 0.85 s of slip (the first 2 s
  // standing still hide what falls in them)
  const double expected = (600.0 - 2.0) / (60.0 / 6.0 + 0.85);
  EXPECT_NEAR(static_cast<double>(runs.size()), expected, 3.0 * std::sqrt(expected));
  for (const Run& r : runs) {
    const double seconds = (r.last - r.first + 1) / 50.0;  // samples in the run x 20 ms
    EXPECT_LE(seconds, 1.5 + 0.02) << "episode at sample " << r.first;
    if (r.last + 1 < plain.size()) {  // (the last one may be cut by the end of the run)
      EXPECT_GE(seconds, 0.2 - 0.02) << "episode at sample " << r.first;
    }
  }
  EXPECT_LT(deviating, plain.size() / 5);  // slipping about 8 % of the time
  // the same seed gives the same readings; another seed other episodes
  const std::vector<WheelReading> again = wheelReadings(slip);
  for (size_t i = 0; i < plain.size(); ++i) ASSERT_TRUE(same(again[i], slipping[i])) << i;
  const std::vector<WheelReading> other = wheelReadings(slip, 2);
  const std::vector<WheelReading> other_plain = wheelReadings("", 2);
  size_t differ = 0;
  for (size_t i = 0; i < plain.size(); ++i) differ += same(other[i], other_plain[i]) != same(slipping[i], plain[i]);
  EXPECT_GT(differ, 100u);
}

TEST(WheelSlip, BadOptionsAreRejectedWithTheKey) {
  auto error = [](const std::string& slip) {
    try {
      loadSimulation(Config::fromString(carConfig(slip), "slip.yaml"), "");
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error("    slip: {rate_per_min: 2}\n"), "");
  EXPECT_NE(error("    slip: {rate_per_min: -1}\n").find("sim.wheel.slip.rate_per_min: must be in [0, 600]"),
            std::string::npos);
  EXPECT_NE(error("    slip: {rate_per_min: 2, duration_s: [1.5, 0.2]}\n")
                .find("sim.wheel.slip.duration_s: must be [min, max]"),
            std::string::npos);
  EXPECT_NE(error("    slip: {rate_per_min: 2, spin: [0.1]}\n").find("sim.wheel.slip.spin: must be [min, max]"),
            std::string::npos);
  EXPECT_NE(error("    slip: {rate_per_min: 2, lock_probability: 1.5}\n")
                .find("sim.wheel.slip.lock_probability: must be in [0, 1]"),
            std::string::npos);
  EXPECT_NE(error("    slip: {rate: 2}\n").find("sim.wheel.slip.rate"), std::string::npos);  // unknown key
}
