// livo-loginfo's summary of a log written with LCM's own log writer.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include <lcm/lcm-cpp.hpp>

#include "livo/imu_t.hpp"
#include "livo/loginfo/log_summary.hpp"
#include "livo/point_cloud_t.hpp"
#include "temp_path.hpp"

namespace {
template <class T>
void write(lcm::LogFile& log, const std::string& channel, int64_t t, const T& m) {
  std::vector<uint8_t> buf(m.getEncodedSize());
  m.encode(buf.data(), 0, static_cast<int>(buf.size()));
  lcm::LogEvent ev;
  ev.timestamp = t;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(buf.size());
  ev.data = buf.data();
  log.writeEvent(&ev);
}

std::string makeLog() {
  const std::string path = livo_test::tempPath("loginfo_test.lcmlog");
  lcm::LogFile log(path, "w");
  EXPECT_TRUE(log.good());
  for (int i = 0; i <= 200; ++i) {  // 2 s of IMU at 100 Hz
    livo::imu_t m{};
    m.utime = 1000000 + i * 10000;
    write(log, "IMU", m.utime, m);
    if (i % 10 == 0) {  // LiDAR at 10 Hz
      livo::point_cloud_t c{};
      c.utime = m.utime;
      c.frame = "L";
      c.num_points = 100;
      c.x.assign(100, 1.f), c.y.assign(100, 2.f), c.z.assign(100, 3.f), c.intensity.assign(100, 0.f);
      c.time_offset.assign(100, 0.f), c.ring.assign(100, 0);
      write(log, "LIDAR", m.utime, c);
    }
  }
  lcm::LogEvent ev;
  uint8_t junk[16] = {0};
  ev.timestamp = 1500000;
  ev.channel = "OTHER";
  ev.datalen = 16;
  ev.data = junk;
  log.writeEvent(&ev);
  return path;
}
}  // namespace

TEST(LogInfo, CountsRatesAndTypes) {
  const livo::loginfo::LogSummary s = livo::loginfo::summarizeLog(makeLog());
  EXPECT_EQ(s.events, 201 + 21 + 1);
  EXPECT_NEAR(s.durationS(), 2.0, 1e-9);
  EXPECT_EQ(s.trailing_bytes, 0);
  ASSERT_EQ(s.channels.size(), 3u);
  const auto& imu = s.channels.at("IMU");
  EXPECT_EQ(imu.type, "livo.imu_t");
  EXPECT_EQ(imu.count, 201);
  EXPECT_NEAR(imu.rateHz(), 100.0, 1e-9);
  const auto& lidar = s.channels.at("LIDAR");
  EXPECT_EQ(lidar.type, "livo.point_cloud_t");
  EXPECT_EQ(lidar.count, 21);
  EXPECT_NEAR(lidar.rateHz(), 10.0, 1e-9);
  EXPECT_EQ(s.channels.at("OTHER").type.rfind("unknown", 0), 0u);
  std::ostringstream os;
  livo::loginfo::printLogSummary(s, os);
  EXPECT_NE(os.str().find("livo.point_cloud_t"), std::string::npos);
}

TEST(LogInfo, TruncatedLogKeepsWhatIsReadable) {
  const std::string path = makeLog();
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string cut = livo_test::tempPath("loginfo_cut.lcmlog");
  std::ofstream(cut, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  const livo::loginfo::LogSummary s = livo::loginfo::summarizeLog(cut);
  EXPECT_GT(s.events, 50);
  EXPECT_LT(s.events, 223);
  EXPECT_GT(s.trailing_bytes, 0);
  EXPECT_THROW(livo::loginfo::summarizeLog("/nonexistent.lcmlog"), std::runtime_error);
}
