// The shared Ouster captures (OS0/OS1/OS2-128, firmware 2.3, RNG15_RFL8_NIR8 and
// RNG19_RFL8_SIG16_NIR16 profiles): packet counts, IMU values against the raw packet bytes,
// per-point times from column stamps, geometry against the capture's pose file, and IPv4
// fragments reassembled.
#include <cmath>
#include <cstring>
#include <fstream>
#include <unordered_map>

#include <gtest/gtest.h>

#include "livo/import/file_utils.hpp"
#include "livo/import/import_job.hpp"
#include "livo/import/ouster_metadata.hpp"
#include "livo/import/pcap_reader.hpp"
#include "livo/imu_t.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/trajectory_io.hpp"
#include "log_reading.hpp"

namespace livo::import {
namespace {

const std::string kOuster = std::string(LIVO_SHARED_DATA) + "/ouster";
const std::string kOs1 = kOuster + "/OS-1-128_v2.3.0_1024x10_lb_n3.pcap";

ImportJob ousterJob(const std::string& pcap, const std::string& out) {
  ImportJob job;
  job.format = "ouster";
  job.input = pcap;
  job.out = out;
  job.quiet = true;
  return job;
}

struct Captured {
  std::vector<UdpDatagram> lidar, imu;
};
Captured capture(const std::string& pcap) {
  Captured c;
  PcapReader reader(pcap);
  reader.readAll([&](const UdpDatagram& u) { (u.dst_port == 7502 ? c.lidar : c.imu).push_back(u); });
  return c;
}

/// Pixels with a return in a capture, counted straight from the packets' range fields.
int64_t returnsIn(const std::vector<UdpDatagram>& packets, int pixel_bytes, int header, int col_header) {
  int64_t n = 0;
  const int col_bytes = col_header + 128 * pixel_bytes;
  for (const UdpDatagram& u : packets)
    for (int c = 0; c < 16; ++c) {
      const uint8_t* col = u.payload.data() + header + c * col_bytes;
      uint16_t status;
      std::memcpy(&status, col + 10, 2);
      if (!(status & 1)) continue;
      for (int i = 0; i < 128; ++i) {
        uint32_t raw = 0;
        std::memcpy(&raw, col + col_header + i * pixel_bytes, pixel_bytes == 4 ? 2 : 4);
        n += (raw & (pixel_bytes == 4 ? 0x7fffu : 0x7ffffu)) != 0;
      }
    }
  return n;
}

TEST(OusterImport, SharedCapturesMatchTheirPackets) {
  struct Case {
    std::string name;
    int sweeps, imu;
    int pixel_bytes;
  };
  for (const Case& k : {Case{"OS-1-128_v2.3.0_1024x10_lb_n3", 3, 30, 4}, Case{"OS-0-128-U1_v2.3.0_1024x10", 1, 10, 4},
                        Case{"OS-2-128-U1_v2.3.0_1024x10", 1, 10, 12}}) {
    SCOPED_TRACE(k.name);
    const std::string dir = test::freshTempDir("ouster_" + k.name);
    const std::string pcap = kOuster + "/" + k.name + ".pcap";
    const ImportOutcome r = runImport(ousterJob(pcap, dir + "/o.lcmlog"), nullptr);
    ASSERT_TRUE(r.ok());
    const Captured cap = capture(pcap);
    EXPECT_EQ(static_cast<int>(cap.lidar.size()), k.sweeps * 64) << "1024 columns / 16 per packet";
    EXPECT_EQ(static_cast<int>(cap.imu.size()), k.imu);
    EXPECT_EQ(r.channel_counts.at("LIDAR"), k.sweeps);
    EXPECT_EQ(r.channel_counts.at("IMU"), k.imu);
    EXPECT_EQ(r.report.skipped().count("partial sweep (kept): fewer columns than the column window"), 0u);

    const auto events = test::readLog(dir + "/o.lcmlog");
    EXPECT_TRUE(test::inTimeOrder(events));
    const auto clouds = test::messagesOn<point_cloud_t>(events, "LIDAR");
    int64_t points = 0;
    for (const point_cloud_t& c : clouds) points += c.num_points;
    EXPECT_EQ(points, returnsIn(cap.lidar, k.pixel_bytes, 32, 12)) << "one point per pixel with a return";

    // Sweep start = first column stamp; offsets from the column stamps, 1024 columns in 0.1 s.
    uint64_t first_ts;
    std::memcpy(&first_ts, cap.lidar[0].payload.data() + 32, 8);
    EXPECT_EQ(clouds[0].utime, static_cast<int64_t>(first_ts / 1000));
    EXPECT_EQ(clouds[0].num_rings, 128);
    float max_offset = 0.0f;
    for (const point_cloud_t& c : clouds)
      for (int j = 0; j < c.num_points; ++j) {
        ASSERT_GE(c.time_offset[j], 0.0f);
        max_offset = std::max(max_offset, c.time_offset[j]);
      }
    EXPECT_GT(max_offset, 0.095f);
    EXPECT_LT(max_offset, 0.1f);

    // IMU against the first IMU packet's bytes: accel in g, gyro in deg/s, stamped by the gyro.
    const auto imu = test::messagesOn<imu_t>(events, "IMU");
    const uint8_t* p = cap.imu[0].payload.data();
    uint64_t gyro_ts;
    float a[3], w[3];
    std::memcpy(&gyro_ts, p + 16, 8);
    std::memcpy(a, p + 24, 12);
    std::memcpy(w, p + 36, 12);
    EXPECT_EQ(imu[0].utime, static_cast<int64_t>((gyro_ts + 500) / 1000));
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(imu[0].linear_acceleration[i], a[i] * 9.80665);
      EXPECT_EQ(imu[0].angular_velocity[i], w[i] * M_PI / 180.0);
    }
    // Units: the mean |a| over the capture is gravity plus the platform's motion (measured 10.66,
    // 10.09 and 9.97 m/s^2); a unit mistake (g or deg/s left unconverted) would be off tenfold.
    double sum = 0.0;
    for (const imu_t& m : imu)
      sum += std::sqrt(m.linear_acceleration[0] * m.linear_acceleration[0] +
                       m.linear_acceleration[1] * m.linear_acceleration[1] +
                       m.linear_acceleration[2] * m.linear_acceleration[2]);
    EXPECT_NEAR(sum / imu.size(), 9.81, 1.0);
  }
}

/// Median distance from each sampled point of `a`, moved by T, to its nearest point of `b`.
double medianNearest(const point_cloud_t& a, const point_cloud_t& b, const Pose3& T) {
  const double cell = 0.5;
  auto key = [&](const Vec3& p) {
    return (int64_t(std::floor(p.x() / cell)) * 73856093) ^ (int64_t(std::floor(p.y() / cell)) * 19349663) ^
           (int64_t(std::floor(p.z() / cell)) * 83492791);
  };
  std::unordered_map<int64_t, std::vector<Vec3>> grid;
  for (int j = 0; j < b.num_points; ++j) {
    const Vec3 p(b.x[j], b.y[j], b.z[j]);
    grid[key(p)].push_back(p);
  }
  std::vector<double> d;
  for (int j = 0; j < a.num_points; j += 97) {
    const Vec3 p = T * Vec3(a.x[j], a.y[j], a.z[j]);
    double best = 1e9;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          auto it = grid.find(key(p + cell * Vec3(dx, dy, dz)));
          if (it == grid.end()) continue;
          for (const Vec3& q : it->second) best = std::min(best, (p - q).norm());
        }
    d.push_back(best);
  }
  std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
  return d[d.size() / 2];
}

TEST(OusterImport, GeometryAgreesWithTheCapturesPoseFile) {
  const std::string dir = test::freshTempDir("ouster_geometry");
  ASSERT_TRUE(runImport(ousterJob(kOs1, dir + "/os1.lcmlog"), nullptr).ok());
  const auto clouds = test::messagesOn<point_cloud_t>(test::readLog(dir + "/os1.lcmlog"), "LIDAR");
  ASSERT_EQ(clouds.size(), 3u);
  std::vector<double> ranges;
  for (int j = 0; j < clouds[0].num_points; ++j)
    ranges.push_back(
        std::sqrt(clouds[0].x[j] * clouds[0].x[j] + clouds[0].y[j] * clouds[0].y[j] + clouds[0].z[j] * clouds[0].z[j]));
  std::sort(ranges.begin(), ranges.end());
  EXPECT_GT(ranges.front(), 0.1);
  EXPECT_LT(ranges[ranges.size() * 99 / 100], 120.0) << "OS1 rated range (rare multipath returns lie beyond)";
  EXPECT_GT(ranges[ranges.size() / 2], 1.0);
  // The SDK's poses of the three sweeps (0.25 m, then 0.5 m along x): sweep 2 moved by its pose
  // lands on sweep 0 much better than left where it is.
  const Trajectory poses = readKittiPoses(kOuster + "/OS-1-128_v2.3.0_1024x10_lb_n3_poses_kitti.txt");
  ASSERT_EQ(poses.size(), 3u);
  const double with_pose = medianNearest(clouds[2], clouds[0], poses[2].pose);
  const double without = medianNearest(clouds[2], clouds[0], Pose3::Identity());
  const double with_inverse = medianNearest(clouds[2], clouds[0], poses[2].pose.inverse());
  // Measured: 0.053 m with the pose, 0.091 m without, 0.124 m with the inverse; the median is
  // bounded below by the sampling density (1024 columns: 6 cm between neighbours at 10 m).
  EXPECT_LT(with_pose, 0.08);
  EXPECT_LT(with_pose, 0.7 * without);
  EXPECT_LT(with_pose, 0.5 * with_inverse) << "a mirrored geometry would prefer the inverse motion";
}

/// Writes a pcap (Ethernet, microsecond stamps) whose UDP datagrams are split into IPv4
/// fragments of at most `mtu` bytes.
void writeFragmentedPcap(const std::string& path, const std::vector<UdpDatagram>& datagrams, size_t mtu) {
  std::ofstream out(path, std::ios::binary);
  const uint32_t gh[6] = {0xa1b2c3d4, 0x00040002, 0, 0, 65535, 1};
  out.write(reinterpret_cast<const char*>(gh), 24);
  uint16_t id = 100;
  for (const UdpDatagram& u : datagrams) {
    std::vector<uint8_t> udp(8 + u.payload.size());
    const uint16_t len = static_cast<uint16_t>(udp.size());
    udp[0] = u.src_port >> 8, udp[1] = u.src_port & 0xff, udp[2] = u.dst_port >> 8, udp[3] = u.dst_port & 0xff;
    udp[4] = len >> 8, udp[5] = len & 0xff;
    std::memcpy(udp.data() + 8, u.payload.data(), u.payload.size());
    const size_t chunk = (mtu - 20) / 8 * 8;
    ++id;
    for (size_t off = 0; off < udp.size(); off += chunk) {
      const size_t n = std::min(chunk, udp.size() - off);
      const bool more = off + n < udp.size();
      std::vector<uint8_t> frame(14 + 20 + n, 0);
      frame[12] = 0x08;  // IPv4
      uint8_t* ip = frame.data() + 14;
      ip[0] = 0x45;
      ip[2] = static_cast<uint8_t>((20 + n) >> 8), ip[3] = static_cast<uint8_t>((20 + n) & 0xff);
      ip[4] = id >> 8, ip[5] = id & 0xff;
      const uint16_t ff = static_cast<uint16_t>((more ? 0x2000 : 0) | (off / 8));
      ip[6] = ff >> 8, ip[7] = ff & 0xff;
      ip[8] = 64, ip[9] = 17;
      std::memcpy(ip + 20, udp.data() + off, n);
      const uint32_t rh[4] = {1, 0, static_cast<uint32_t>(frame.size()), static_cast<uint32_t>(frame.size())};
      out.write(reinterpret_cast<const char*>(rh), 16);
      out.write(reinterpret_cast<const char*>(frame.data()), static_cast<std::streamsize>(frame.size()));
    }
  }
}

TEST(OusterImport, FragmentedPacketsAreReassembled) {
  const std::string dir = test::freshTempDir("ouster_fragments");
  const Captured cap = capture(kOs1);
  // The first sweep's 64 LiDAR packets and 10 IMU packets, each LiDAR packet in 6 fragments.
  std::vector<UdpDatagram> first(cap.lidar.begin(), cap.lidar.begin() + 64);
  first.insert(first.end(), cap.imu.begin(), cap.imu.begin() + 10);
  writeFragmentedPcap(dir + "/frag.pcap", first, 1500);
  ImportJob job = ousterJob(dir + "/frag.pcap", dir + "/frag.lcmlog");
  job.ouster.metadata_file = kOuster + "/OS-1-128_v2.3.0_1024x10.json";
  const ImportOutcome r = runImport(job, nullptr);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.report.metadataValue("pcap_ipv4_fragments"), std::to_string(64 * 6 + 10 * 0));
  EXPECT_EQ(r.channel_counts.at("LIDAR"), 1);
  EXPECT_EQ(r.channel_counts.at("IMU"), 10);
  const auto frag = test::messagesOn<point_cloud_t>(test::readLog(dir + "/frag.lcmlog"), "LIDAR");
  ASSERT_TRUE(runImport(ousterJob(kOs1, dir + "/whole.lcmlog"), nullptr).ok());
  const auto whole = test::messagesOn<point_cloud_t>(test::readLog(dir + "/whole.lcmlog"), "LIDAR");
  ASSERT_EQ(frag.size(), 1u);
  EXPECT_EQ(frag[0].num_points, whole[0].num_points);
  EXPECT_EQ(frag[0].x, whole[0].x);
  EXPECT_EQ(frag[0].time_offset, whole[0].time_offset);
}

TEST(OusterImport, TruncatedCaptureKeepsTheSweepsBeforeTheCut) {
  const std::string dir = test::freshTempDir("ouster_truncated");
  const std::vector<uint8_t> bytes = readFileBytes(kOs1);
  {
    std::ofstream out(dir + "/cut.pcap", std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size() * 3 / 4));
  }
  ImportJob job = ousterJob(dir + "/cut.pcap", dir + "/cut.lcmlog");
  job.ouster.metadata_file = kOuster + "/OS-1-128_v2.3.0_1024x10.json";
  const ImportOutcome r = runImport(job, nullptr);
  EXPECT_FALSE(r.ok());
  ASSERT_EQ(r.report.errors().size(), 1u);
  EXPECT_NE(r.report.errors()[0].find("cut.pcap: record "), std::string::npos) << r.report.errors()[0];
  EXPECT_NE(r.report.errors()[0].find("truncated"), std::string::npos);
  EXPECT_EQ(r.channel_counts.at("LIDAR"), 3) << "two whole sweeps and the partial third";
  EXPECT_EQ(r.report.skipped().at("partial sweep (kept): fewer columns than the column window").count, 1);
}

TEST(OusterImport, MetadataErrorsNameTheKey) {
  const std::string dir = test::freshTempDir("ouster_metadata");
  {
    std::ofstream out(dir + "/bad.json");
    out << R"({"lidar_mode": "1024x10", "data_format": {"columns_per_frame": 1024}})";
  }
  EXPECT_THROW(
      {
        try {
          readOusterMetadata(dir + "/bad.json");
        } catch (const std::runtime_error& e) {
          EXPECT_NE(std::string(e.what()).find("bad.json: key 'pixels_per_column' missing"), std::string::npos)
              << e.what();
          throw;
        }
      },
      std::runtime_error);
}

}  // namespace
}  // namespace livo::import
