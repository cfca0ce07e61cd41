// Every fault mode does exactly what it says, reproducibly for a seed.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <random>

#include "livo/playback/fault_injector.hpp"
#include "livo/imu_t.hpp"
#include "test_log.hpp"

using namespace livo;
using namespace livo::playback;
using playback_test::kT0;

namespace {

std::vector<LogEvent> run(const std::string& log, const std::vector<std::string>& faults, uint64_t seed,
                          FaultCounts* imu_counts = nullptr, FaultCounts* lidar_counts = nullptr) {
  std::vector<Fault> f;
  for (const auto& s : faults) f.push_back(parseFault(s));
  FaultInjector inj(f, seed);
  LogSource src(log, {});
  std::vector<LogEvent> out;
  while (auto e = src.next())
    for (auto& o : inj.push(std::move(*e), kT0)) out.push_back(std::move(o));
  for (auto& o : inj.flush()) out.push_back(std::move(o));
  if (imu_counts && inj.counts().count("IMU")) *imu_counts = inj.counts().at("IMU");
  if (lidar_counts && inj.counts().count("LIDAR")) *lidar_counts = inj.counts().at("LIDAR");
  return out;
}

std::vector<int64_t> imuStamps(const std::vector<LogEvent>& events) {
  std::vector<int64_t> t;
  for (const auto& e : events) {
    if (e.channel != "IMU") continue;
    imu_t m;
    EXPECT_EQ(m.decode(e.data.data(), 0, static_cast<int>(e.data.size())), static_cast<int>(e.data.size()));
    t.push_back(m.utime);
  }
  return t;
}

size_t countChannel(const std::vector<LogEvent>& events, const std::string& ch) {
  size_t n = 0;
  for (const auto& e : events) n += e.channel == ch;
  return n;
}

const std::string& testLog() {
  static const std::string path = playback_test::makeLog("faults", 20.0);  // 2000 IMU, 200 LIDAR
  return path;
}

}  // namespace

TEST(FaultInjector, NoFaultsIsIdentity) {
  const auto out = run(testLog(), {}, 1);
  LogSource src(testLog(), {});
  size_t i = 0;
  while (auto e = src.next()) {
    ASSERT_LT(i, out.size());
    EXPECT_EQ(out[i].data, e->data);
    EXPECT_EQ(out[i].channel, e->channel);
    ++i;
  }
  EXPECT_EQ(i, out.size());
}

TEST(FaultInjector, DropRemovesTheCountedFractionOnlyOnItsChannel) {
  FaultCounts c;
  const auto out = run(testLog(), {"drop:IMU:0.3"}, 7, &c);
  EXPECT_EQ(countChannel(out, "IMU") + c.dropped, 2000u);
  EXPECT_EQ(countChannel(out, "LIDAR"), 200u);
  // binomial(2000, 0.3): mean 600, sd 20.5; 5 sd
  EXPECT_NEAR(static_cast<double>(c.dropped), 600.0, 103.0);
  // what remains is in order and unchanged
  const auto t = imuStamps(out);
  EXPECT_TRUE(std::is_sorted(t.begin(), t.end()));
  // reproducible for a seed, different for another
  EXPECT_EQ(imuStamps(run(testLog(), {"drop:IMU:0.3"}, 7)), t);
  EXPECT_NE(imuStamps(run(testLog(), {"drop:IMU:0.3"}, 8)), t);
}

TEST(FaultInjector, DuplicateRepeatsMessagesInPlace) {
  FaultCounts c;
  const auto out = run(testLog(), {"duplicate:LIDAR:0.5"}, 3, nullptr, &c);
  EXPECT_EQ(countChannel(out, "LIDAR"), 200u + c.duplicated);
  EXPECT_GT(c.duplicated, 50);
  size_t adjacent = 0;
  for (size_t i = 1; i < out.size(); ++i) adjacent += out[i].channel == "LIDAR" && out[i].data == out[i - 1].data;
  EXPECT_EQ(adjacent, static_cast<size_t>(c.duplicated));
}

TEST(FaultInjector, DelayReleasesLateByTheGivenTime) {
  FaultCounts c;
  const auto out = run(testLog(), {"delay:IMU:0.1:0.05"}, 5, &c);
  EXPECT_EQ(countChannel(out, "IMU"), 2000u);
  EXPECT_GT(c.delayed, 100);
  // A delayed message (stamp below the newest already out) is released just before the first
  // in-order message stamped at or after its stamp + 50 ms, and not earlier.
  int late = 0;
  int64_t newest = 0;
  for (size_t i = 0; i < out.size(); ++i) {
    if (out[i].utime >= newest) {
      newest = out[i].utime;
      continue;
    }
    ++late;
    EXPECT_LT(newest, out[i].utime + 50000);
    size_t k = i + 1;
    while (k < out.size() && out[k].utime < newest) ++k;  // other delayed ones released with it
    if (k < out.size()) {
      EXPECT_GE(out[k].utime, out[i].utime + 50000);
    }
  }
  EXPECT_EQ(late, c.delayed);
  const auto t = imuStamps(out);
  EXPECT_FALSE(std::is_sorted(t.begin(), t.end()));
}

TEST(FaultInjector, ReorderSwapsWithTheNextMessageOfTheChannel) {
  FaultCounts c;
  const auto out = run(testLog(), {"reorder:IMU:0.2"}, 11, &c);
  const auto t = imuStamps(out);
  ASSERT_EQ(t.size(), 2000u);
  int inversions = 0;
  for (size_t i = 0; i + 1 < t.size(); ++i) {
    if (t[i] > t[i + 1]) {
      ++inversions;
      EXPECT_EQ(t[i] - t[i + 1], 10000);  // neighbours swapped, nothing else
    }
  }
  EXPECT_EQ(inversions, c.reordered);
  EXPECT_GT(c.reordered, 200);
}

TEST(FaultInjector, CorruptChangesBytesSoDecodingFailsOrDiffers) {
  FaultCounts c;
  const auto out = run(testLog(), {"corrupt:IMU:0.25"}, 2, &c);
  const auto clean = run(testLog(), {}, 2);
  ASSERT_EQ(out.size(), clean.size());
  int changed = 0;
  for (size_t i = 0; i < out.size(); ++i) changed += out[i].data != clean[i].data;
  EXPECT_EQ(changed, c.corrupted);
  EXPECT_NEAR(c.corrupted, 500, 100);
}

TEST(FaultInjector, NanPointsOnlyInClouds) {
  FaultCounts c;
  const auto out = run(testLog(), {"nan:LIDAR:0.5"}, 4, nullptr, &c);
  int clouds_with_nan = 0, nan_points = 0, points = 0;
  for (const auto& e : out) {
    if (e.channel != "LIDAR") continue;
    point_cloud_t pc;
    ASSERT_EQ(pc.decode(e.data.data(), 0, static_cast<int>(e.data.size())), static_cast<int>(e.data.size()));
    int n = 0;
    for (int i = 0; i < pc.num_points; ++i) n += !std::isfinite(pc.x[i]) || !std::isfinite(pc.y[i]) || !std::isfinite(pc.z[i]);
    clouds_with_nan += n > 0;
    nan_points += n;
    points += pc.num_points;
  }
  EXPECT_EQ(clouds_with_nan, c.nan_clouds);
  EXPECT_NEAR(c.nan_clouds, 100, 25);
  EXPECT_NEAR(static_cast<double>(nan_points) / (c.nan_clouds * 200), 0.1, 0.03);
}

TEST(FaultInjector, TimeJumpShiftsStampsFromTheGivenTime) {
  FaultCounts c;
  const auto out = run(testLog(), {"jump:IMU:5:2.5"}, 1, &c);
  const auto t = imuStamps(out);
  ASSERT_EQ(t.size(), 2000u);
  for (int i = 0; i < 2000; ++i) {
    const int64_t orig = kT0 + i * 10000;
    EXPECT_EQ(t[i], orig >= kT0 + 5000000 ? orig + 2500000 : orig);
  }
  EXPECT_EQ(c.time_shifted, 1500);
}

TEST(FaultInjector, CutRemovesAWindow) {
  FaultCounts c;
  const auto out = run(testLog(), {"cut:LIDAR:3:7"}, 1, nullptr, &c);
  for (const auto& e : out) {
    if (e.channel != "LIDAR") continue;
    const double t = (e.utime - kT0) * 1e-6;
    EXPECT_FALSE(t >= 3.0 && t < 7.0) << t;
  }
  EXPECT_EQ(c.cut, 40);
  EXPECT_EQ(countChannel(out, "LIDAR"), 160u);
  EXPECT_EQ(countChannel(out, "IMU"), 2000u);
}

TEST(FaultInjector, ParseErrors) {
  EXPECT_THROW(parseFault("drop:IMU"), std::invalid_argument);
  EXPECT_THROW(parseFault("drop:IMU:1.5"), std::invalid_argument);
  EXPECT_THROW(parseFault("explode:IMU:0.1"), std::invalid_argument);
  EXPECT_THROW(parseFault("delay:IMU:0.1"), std::invalid_argument);
  EXPECT_THROW(parseFault("cut:IMU:5:2"), std::invalid_argument);
  EXPECT_THROW(parseFault("nan:LIDAR:abc"), std::invalid_argument);
  const Fault f = parseFault("delay:CAMERA:0.25:0.1");
  EXPECT_EQ(f.kind, Fault::Kind::kDelay);
  EXPECT_EQ(f.channel, "CAMERA");
  EXPECT_DOUBLE_EQ(f.fraction, 0.25);
  EXPECT_DOUBLE_EQ(f.seconds, 0.1);
}

TEST(LogSource, FiltersByChannelAndWindow) {
  LogSourceOptions o;
  o.channels = "LID.*";
  o.start_s = 2.0;
  o.duration_s = 3.0;
  LogSource src(testLog(), o);
  int n = 0;
  while (auto e = src.next()) {
    EXPECT_EQ(e->channel, "LIDAR");
    const double t = (e->utime - kT0) * 1e-6;
    EXPECT_GE(t, 2.0);
    EXPECT_LE(t, 5.0);
    ++n;
  }
  EXPECT_EQ(n, 30);
  EXPECT_THROW(LogSource("/nonexistent.lcmlog", {}), std::runtime_error);
  LogSourceOptions bad;
  bad.channels = "(";
  EXPECT_THROW(LogSource(testLog(), bad), std::runtime_error);
}

namespace {
// Raw events as lcm::LogFile (LCM's own reader) reads them.
std::vector<LogEvent> readWithLcm(const std::string& path) {
  lcm::LogFile log(path, "r");
  std::vector<LogEvent> out;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    const auto* d = static_cast<const uint8_t*>(ev->data);
    out.push_back(LogEvent{ev->timestamp, ev->channel, std::vector<uint8_t>(d, d + ev->datalen)});
  }
  return out;
}

std::vector<LogEvent> readWithSource(const std::string& path, int64_t* trailing = nullptr) {
  LogSource src(path, {});
  std::vector<LogEvent> out;
  while (auto e = src.next()) out.push_back(std::move(*e));
  if (trailing) *trailing = src.trailingBytes();
  return out;
}

void expectSameEvents(const std::vector<LogEvent>& a, const std::vector<LogEvent>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].utime, b[i].utime) << "event " << i;
    EXPECT_EQ(a[i].channel, b[i].channel) << "event " << i;
    EXPECT_EQ(a[i].data, b[i].data) << "event " << i;
  }
}

std::vector<uint8_t> fileBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return std::vector<uint8_t>(std::istreambuf_iterator<char>(f), {});
}

void writeBytes(const std::string& path, const std::vector<uint8_t>& bytes) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}
}  // namespace

TEST(LogSource, ReadsTheEventsLcmReadsEvenAroundGarbageAndAtATruncatedTail) {
  // LogSource parses the mapped file itself; it must give what lcm::LogFile gives: the same
  // events, and the end of the log at an event cut short (its bytes reported as the trailing ones)
  // or at an impossible header. Garbage between events, where LCM's reader stops (dropping the
  // event before it too), is skipped up to the next sync word and counted.
  const std::string path = livo_test::tempPath("log_source_random.lcmlog");
  std::mt19937 rng(7);
  std::vector<size_t> event_ends;  // file offset after each event
  {
    lcm::LogFile log(path, "w");
    for (int i = 0; i < 200; ++i) {
      std::vector<uint8_t> data(i % 17 == 0 ? 0 : std::uniform_int_distribution<size_t>(1, i % 50 == 1 ? 300000 : 900)(rng));
      for (auto& b : data) b = static_cast<uint8_t>(rng());
      if (i == 3) data = {0xED, 0xA1, 0xDA, 0x01, 0xED};  // a sync word inside the data
      lcm::LogEvent ev;
      ev.timestamp = kT0 + 1000 * i;
      ev.channel = i % 3 == 0 ? "IMU" : (i % 3 == 1 ? "LIDAR" : "A_LONGER_CHANNEL_NAME");
      ev.datalen = static_cast<int32_t>(data.size());
      ev.data = data.data();
      log.writeEvent(&ev);
      event_ends.push_back(static_cast<size_t>(std::ftell(log.getFilePtr())));
    }
  }
  int64_t trailing = -1;
  expectSameEvents(readWithSource(path, &trailing), readWithLcm(path));
  EXPECT_EQ(readWithSource(path).size(), 200u);
  EXPECT_EQ(trailing, 0);

  // garbage before the first event and between two events
  std::vector<uint8_t> bytes = fileBytes(path);
  std::vector<uint8_t> garbled = {0x01, 0xED, 0xA1, 0x00, 0x42};
  garbled.insert(garbled.end(), bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(event_ends[10]));
  garbled.insert(garbled.end(), {0xDA, 0x01, 0xED, 0xA1, 0xDA});
  garbled.insert(garbled.end(), bytes.begin() + static_cast<std::ptrdiff_t>(event_ends[10]), bytes.end());
  const std::string garbled_path = livo_test::tempPath("log_source_garbled.lcmlog");
  writeBytes(garbled_path, garbled);
  {
    LogSource src(garbled_path, {});
    std::vector<LogEvent> events;
    while (auto e = src.next()) events.push_back(std::move(*e));
    expectSameEvents(events, readWithLcm(path));  // every event of the clean log
    EXPECT_EQ(src.skippedBytes(), 10);
    EXPECT_EQ(src.trailingBytes(), 0);
  }

  // cut inside the last event's data, and inside its header
  for (size_t cut : {event_ends[199] - 3, event_ends[198] + 10}) {
    const std::string cut_path = livo_test::tempPath("log_source_cut.lcmlog");
    writeBytes(cut_path, std::vector<uint8_t>(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(cut)));
    const std::vector<LogEvent> events = readWithSource(cut_path, &trailing);
    expectSameEvents(events, readWithLcm(cut_path));
    EXPECT_EQ(events.size(), 199u);
    EXPECT_EQ(trailing, static_cast<int64_t>(cut - event_ends[198]));
  }

  // an impossible channel length ends the log there, as in LCM
  std::vector<uint8_t> bad = bytes;
  bad[event_ends[49] + 4 + 16] = 0x7f;  // event 50's channel length: 2^30 and more
  const std::string bad_path = livo_test::tempPath("log_source_bad_header.lcmlog");
  writeBytes(bad_path, bad);
  const std::vector<LogEvent> events = readWithSource(bad_path, &trailing);
  expectSameEvents(events, readWithLcm(bad_path));
  EXPECT_EQ(events.size(), 50u);
  EXPECT_EQ(trailing, static_cast<int64_t>(bytes.size() - event_ends[49]));

  // an empty file: no events, nothing trailing
  const std::string empty_path = livo_test::tempPath("log_source_empty.lcmlog");
  writeBytes(empty_path, {});
  EXPECT_TRUE(readWithSource(empty_path, &trailing).empty());
  EXPECT_EQ(trailing, 0);
}
