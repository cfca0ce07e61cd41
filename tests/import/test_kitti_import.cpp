// KITTI: the shared raw HDL-64E sweeps (a folder without timestamps), a raw-drive folder built
// from them with timestamp, OXTS and image files, and an odometry sequence built from the shared
// KITTI 00 scans and ground truth.
#include <cmath>
#include <cstring>
#include <fstream>
#include <iomanip>

#include <gtest/gtest.h>

#include "livo/image_t.hpp"
#include "livo/import/file_utils.hpp"
#include "livo/import/import_job.hpp"
#include "livo/import/kitti_velodyne.hpp"
#include "livo/imu_t.hpp"
#include "livo/messages.hpp"
#include "livo/point_cloud_t.hpp"
#include "livo/pose_t.hpp"
#include "log_reading.hpp"

namespace livo::import {
namespace {

const std::string kData = LIVO_SHARED_DATA;

void writeText(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
  ASSERT_TRUE(out.good()) << path;
}

void run(const std::string& cmd) { ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd; }

std::vector<float> binFloats(const std::string& path) {
  const std::vector<uint8_t> b = readFileBytes(path);
  std::vector<float> f(b.size() / 4);
  std::memcpy(f.data(), b.data(), f.size() * 4);
  return f;
}

ImportJob kittiJob(const std::string& in, const std::string& out) {
  ImportJob job;
  job.format = "kitti";
  job.input = in;
  job.out = out;
  job.quiet = true;
  return job;
}

TEST(KittiImport, SharedSweepsWithoutTimestamps) {
  const std::string dir = test::freshTempDir("kitti_bare");
  const std::string velo = kData + "/kitti_raw_22/velodyne";
  const ImportOutcome r = runImport(kittiJob(kData + "/kitti_raw_22", dir + "/k.lcmlog"), nullptr);
  ASSERT_TRUE(r.ok());
  const std::vector<std::string> files = listFiles(velo, ".bin");
  ASSERT_EQ(files.size(), 22u);
  EXPECT_EQ(r.channel_counts.at("LIDAR"), 22);
  const auto clouds = test::messagesOn<point_cloud_t>(test::readLog(dir + "/k.lcmlog"), "LIDAR");
  ASSERT_EQ(clouds.size(), 22u);
  for (size_t k = 0; k < clouds.size(); ++k) {
    const std::vector<float> f = binFloats(velo + "/" + files[k]);
    ASSERT_EQ(clouds[k].num_points, static_cast<int>(f.size() / 4)) << files[k];
    EXPECT_EQ(clouds[k].utime, static_cast<int64_t>(k) * 100000) << "10 Hz from 0 s";
    EXPECT_EQ(clouds[k].num_rings, 64);
    for (int j : {0, clouds[k].num_points / 2, clouds[k].num_points - 1}) {
      EXPECT_EQ(clouds[k].x[j], f[4 * j]);
      EXPECT_EQ(clouds[k].y[j], f[4 * j + 1]);
      EXPECT_EQ(clouds[k].z[j], f[4 * j + 2]);
      EXPECT_EQ(clouds[k].intensity[j], f[4 * j + 3]);
    }
    for (int j = 0; j < clouds[k].num_points; ++j) {
      ASSERT_GE(clouds[k].time_offset[j], 0.0f);
      ASSERT_LT(clouds[k].time_offset[j], 0.1f);
      ASSERT_GE(clouds[k].ring[j], 0);
      ASSERT_LE(clouds[k].ring[j], 63);
    }
  }
  EXPECT_NE(r.report.notes().at(0).find("no times.txt"), std::string::npos);
  // Timing convention: facing backwards at the start, forwards half way, clockwise.
  EXPECT_DOUBLE_EQ(kittiTimeOffset(-1.0, 0.0, 0.1), 0.0);
  EXPECT_DOUBLE_EQ(kittiTimeOffset(0.0, 1.0, 0.1), 0.025);
  EXPECT_DOUBLE_EQ(kittiTimeOffset(1.0, 0.0, 0.1), 0.05);
  EXPECT_DOUBLE_EQ(kittiTimeOffset(0.0, -1.0, 0.1), 0.075);
  EXPECT_EQ(hdl64RingFromElevation(2.0 * M_PI / 180.0), 63);
  EXPECT_EQ(hdl64RingFromElevation(-8.33 * M_PI / 180.0), 32);
  EXPECT_EQ(hdl64RingFromElevation(-8.83 * M_PI / 180.0), 31);
  EXPECT_EQ(hdl64RingFromElevation(-24.33 * M_PI / 180.0), 0);
}

std::string oxtsLine(double lat, double lon, double yaw, double ax) {
  std::ostringstream os;
  os << std::setprecision(17) << lat << " " << lon << " 110.5 0.01 -0.02 " << yaw << " 1 2 3 4 5 " << ax
     << " -0.1 9.8 0 0 0 0.011 0.022 0.033 0 0 0 0.5 0.1 4 10 5 5 6\n";
  return os.str();
}

TEST(KittiImport, RawDriveFolderWithOxtsAndImages) {
  const std::string dir = test::freshTempDir("kitti_raw");
  const std::string drive = dir + "/2011_09_26_drive_0048_sync";
  run("mkdir -p " + drive + "/velodyne_points/data " + drive + "/oxts/data " + drive + "/image_02/data");
  for (int i = 0; i < 3; ++i) {
    const std::string name = "000000000" + std::to_string(i) + ".bin";
    run("ln -s " + kData + "/kitti_raw_22/velodyne/" + name + " " + drive + "/velodyne_points/data/" + name);
  }
  writeText(drive + "/velodyne_points/timestamps.txt",
            "2011-09-26 13:02:25.964389445\n2011-09-26 13:02:26.067707000\n2011-09-26 13:02:26.171006500\n");
  writeText(drive + "/velodyne_points/timestamps_start.txt",
            "2011-09-26 13:02:25.912712000\n2011-09-26 13:02:26.016031000\n2011-09-26 13:02:26.119351000\n");
  writeText(drive + "/velodyne_points/timestamps_end.txt",
            "2011-09-26 13:02:26.016031000\n2011-09-26 13:02:26.119351000\n2011-09-26 13:02:26.222669000\n");
  const double lat0 = 49.011212804408, lon0 = 8.4228850417969;
  writeText(drive + "/oxts/data/0000000000.txt", oxtsLine(lat0, lon0, 1.2, 0.5));
  writeText(drive + "/oxts/data/0000000001.txt", oxtsLine(lat0 + 1e-5, lon0 + 2e-5, 1.25, 0.6));
  writeText(drive + "/oxts/timestamps.txt", "2011-09-26 13:02:25.951199000\n2011-09-26 13:02:25.961200512\n");
  run("cp " + kData + "/euroc_v1_01/mav0/cam0/data/1403715273262142976.png " + drive + "/image_02/data/0000000000.png");
  writeText(drive + "/image_02/timestamps.txt", "2011-09-26 13:02:25.964389445\n");

  const ImportOutcome r = runImport(kittiJob(drive, dir + "/raw.lcmlog"), nullptr);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.channel_counts.at("LIDAR"), 3);
  EXPECT_EQ(r.channel_counts.at("IMU"), 2);
  EXPECT_EQ(r.channel_counts.at("GROUND_TRUTH"), 2);
  EXPECT_EQ(r.channel_counts.at("CAMERA"), 1);
  const auto events = test::readLog(dir + "/raw.lcmlog");
  EXPECT_TRUE(test::inTimeOrder(events));

  const int64_t t0 = 1317042145LL * 1000000;  // 2011-09-26 13:02:25 UTC
  const auto clouds = test::messagesOn<point_cloud_t>(events, "LIDAR");
  ASSERT_EQ(clouds.size(), 3u);
  EXPECT_EQ(clouds[0].utime, t0 + 912712) << "timestamps_start";
  EXPECT_FLOAT_EQ(clouds[0].sweep_duration, 0.103319f) << "end - start";
  const std::vector<float> f = binFloats(kData + "/kitti_raw_22/velodyne/0000000000.bin");
  EXPECT_EQ(clouds[0].num_points, static_cast<int>(f.size() / 4));
  EXPECT_EQ(clouds[0].x[0], f[0]);
  EXPECT_EQ(clouds[0].y[0], f[1]);
  EXPECT_FLOAT_EQ(clouds[0].time_offset[0],
                  static_cast<float>((M_PI - std::atan2(double(f[1]), double(f[0]))) / (2 * M_PI) * 0.103319));

  const auto imu = test::messagesOn<imu_t>(events, "IMU");
  ASSERT_EQ(imu.size(), 2u);
  EXPECT_EQ(imu[0].utime, t0 + 951199);
  EXPECT_EQ(imu[1].utime, t0 + 961201);  // 961200512 ns rounds up
  EXPECT_EQ(imu[0].linear_acceleration[0], 0.5);
  EXPECT_EQ(imu[0].linear_acceleration[1], -0.1);
  EXPECT_EQ(imu[0].linear_acceleration[2], 9.8);
  EXPECT_EQ(imu[1].linear_acceleration[0], 0.6);
  EXPECT_EQ(imu[0].angular_velocity[0], 0.011);
  EXPECT_EQ(imu[0].angular_velocity[2], 0.033);

  const auto gt = test::messagesOn<pose_t>(events, "GROUND_TRUTH");
  ASSERT_EQ(gt.size(), 2u);
  EXPECT_EQ(gt[0].position[0], 0.0);
  EXPECT_EQ(gt[0].position[1], 0.0);
  EXPECT_EQ(gt[0].position[2], 0.0);
  // East and north of the second fix, by the Mercator projection written another way:
  // ln(tan(pi/4 + lat/2)) = atanh(sin(lat)).
  const double R = 6378137.0, s = std::cos(lat0 * M_PI / 180.0);
  EXPECT_NEAR(gt[1].position[0], s * R * 2e-5 * M_PI / 180.0, 1e-6);
  EXPECT_NEAR(gt[1].position[1],
              s * R * (std::atanh(std::sin((lat0 + 1e-5) * M_PI / 180.0)) - std::atanh(std::sin(lat0 * M_PI / 180.0))),
              1e-6);
  const Mat3 R1 = quatFromWxyz(gt[1].orientation).toRotationMatrix();
  EXPECT_NEAR(std::atan2(R1(1, 0), R1(0, 0)), 1.25, 1e-12) << "yaw";
  EXPECT_NEAR(std::asin(-R1(2, 0)), -0.02, 1e-12) << "pitch";

  const auto cam = test::messagesOn<image_t>(events, "CAMERA");
  ASSERT_EQ(cam.size(), 1u);
  EXPECT_EQ(cam[0].utime, t0 + 964389);
  EXPECT_EQ(cam[0].encoding, +image_t::ENCODING_PNG);
}

TEST(KittiImport, OdometrySequenceWithPosesInTheLidarFrame) {
  const std::string dir = test::freshTempDir("kitti_odometry");
  const std::string seq = dir + "/dataset/sequences/00";
  run("mkdir -p " + seq + "/velodyne " + dir + "/dataset/poses");
  for (const char* name : {"000000.bin", "000001.bin"})
    run("ln -s " + kData + "/lidar/kitti_00/" + name + " " + seq + "/velodyne/" + name);
  run("cp " + kData + "/lidar/kitti_00/poses_gt_first2_from_evo_KITTI_00_gt.txt " + dir + "/dataset/poses/00.txt");
  writeText(seq + "/times.txt", "0.000000e+00\n1.036224e-01\n");
  // KITTI 00's velodyne-to-camera Tr.
  writeText(seq + "/calib.txt",
            "Tr: 4.276802385584e-04 -9.999672484946e-01 -8.084491683471e-03 -1.198459927713e-02 "
            "-7.210626507497e-03 8.081198471645e-03 -9.999413164504e-01 -5.403984729748e-02 "
            "9.999738645903e-01 4.859485810390e-04 -7.206933692422e-03 -2.921968648686e-01\n");
  const ImportOutcome r = runImport(kittiJob(seq, dir + "/odo.lcmlog"), nullptr);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.channel_counts.at("LIDAR"), 2);
  EXPECT_EQ(r.channel_counts.at("GROUND_TRUTH"), 2);
  EXPECT_EQ(r.report.metadataValue("kitti_point_fields"), "\"x y z\"") << "3 floats per point, detected";
  const auto events = test::readLog(dir + "/odo.lcmlog");
  const auto clouds = test::messagesOn<point_cloud_t>(events, "LIDAR");
  ASSERT_EQ(clouds.size(), 2u);
  const std::vector<float> f = binFloats(kData + "/lidar/kitti_00/000001.bin");
  EXPECT_EQ(clouds[1].num_points, static_cast<int>(f.size() / 3));
  EXPECT_EQ(clouds[1].z[7], f[3 * 7 + 2]);
  EXPECT_EQ(clouds[1].utime, 103622 - 50000) << "mid-sweep time minus half a sweep";

  const auto gt = test::messagesOn<pose_t>(events, "GROUND_TRUTH");
  ASSERT_EQ(gt.size(), 2u);
  EXPECT_EQ(gt[1].utime, 103622);
  EXPECT_EQ(gt[1].child_frame, "I");
  Eigen::Matrix4d Tr = Eigen::Matrix4d::Identity(), P1 = Eigen::Matrix4d::Identity();
  Tr << 4.276802385584e-04, -9.999672484946e-01, -8.084491683471e-03, -1.198459927713e-02, -7.210626507497e-03,
      8.081198471645e-03, -9.999413164504e-01, -5.403984729748e-02, 9.999738645903e-01, 4.859485810390e-04,
      -7.206933692422e-03, -2.921968648686e-01, 0, 0, 0, 1;
  P1 << 9.999978e-01, 5.272628e-04, -2.066935e-03, -4.690294e-02, -5.296506e-04, 9.999992e-01, -1.154865e-03,
      -2.839928e-02, 2.066324e-03, 1.155958e-03, 9.999971e-01, 8.586941e-01, 0, 0, 0, 1;
  const Eigen::Matrix4d expected = Tr.inverse() * P1 * Tr;
  // readKittiPoses projects the file's 7-digit rotation onto SO(3), which moves Tr^-1 P Tr by ~1e-7.
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(gt[1].position[i], expected(i, 3), 1e-6);
  EXPECT_NEAR(gt[1].position[0], 0.8587, 1e-3) << "the car drives along the LiDAR's x (forward)";
}

TEST(KittiImport, TruncatedScanIsSkippedNamingTheFile) {
  const std::string dir = test::freshTempDir("kitti_truncated");
  run("mkdir -p " + dir + "/velodyne");
  run("head -c 1000001 " + kData + "/kitti_raw_22/velodyne/0000000000.bin > " + dir + "/velodyne/0000000000.bin");
  run("cp " + kData + "/kitti_raw_22/velodyne/0000000001.bin " + dir + "/velodyne/");
  const ImportOutcome r = runImport(kittiJob(dir, dir + "/t.lcmlog"), nullptr);
  EXPECT_EQ(r.channel_counts.at("LIDAR"), 1);
  ASSERT_EQ(r.report.skipped().count("unreadable LiDAR scan"), 1u);
  EXPECT_NE(r.report.skipped().at("unreadable LiDAR scan").first_where.find("0000000000.bin: 1000001 bytes"),
            std::string::npos);
}

}  // namespace
}  // namespace livo::import
