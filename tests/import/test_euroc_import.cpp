// The shared EuRoC V1_01 sample (ASL folder + groundtruth.tum) against its own files.
#include <gtest/gtest.h>

#include "livo/image_t.hpp"
#include "livo/import/file_utils.hpp"
#include "livo/import/import_job.hpp"
#include "livo/imu_t.hpp"
#include "livo/pose_t.hpp"
#include "log_reading.hpp"

namespace livo::import {
namespace {

const std::string kEuroc = std::string(LIVO_SHARED_DATA) + "/euroc_v1_01";

TEST(EurocImport, SharedSampleMatchesItsFiles) {
  const std::string dir = test::freshTempDir("euroc");
  ImportJob job;
  job.format = "euroc";
  job.input = kEuroc;
  job.out = dir + "/v101.lcmlog";
  job.quiet = true;
  const ImportOutcome r = runImport(job, nullptr);
  ASSERT_TRUE(r.ok());
  // Counts: csv rows (29,120 IMU), PNG files present (95 per camera, cam1's csv lists 99),
  // TUM lines (2,895).
  EXPECT_EQ(r.channel_counts.at("IMU"), 29120);
  EXPECT_EQ(r.channel_counts.at("CAMERA"), static_cast<int64_t>(listFiles(kEuroc + "/mav0/cam0/data", ".png").size()));
  EXPECT_EQ(r.channel_counts.at("CAMERA"), 95);
  EXPECT_EQ(r.channel_counts.at("CAMERA_RIGHT"), 95);
  EXPECT_EQ(r.channel_counts.at("GROUND_TRUTH"), 2895);

  const auto events = test::readLog(job.out);
  EXPECT_TRUE(test::inTimeOrder(events));
  const auto imu = test::messagesOn<imu_t>(events, "IMU");
  ASSERT_EQ(imu.size(), 29120u);
  // First row: 1403715273262142976,-0.0020943951023931952,0.017453292519943295,0.07749261878854824,
  //            9.0874956666666655,0.13075533333333333,-3.6938381666666662
  EXPECT_EQ(imu[0].utime, 1403715273262143);
  EXPECT_EQ(imu[0].angular_velocity[0], -0.0020943951023931952);
  EXPECT_EQ(imu[0].angular_velocity[1], 0.017453292519943295);
  EXPECT_EQ(imu[0].angular_velocity[2], 0.07749261878854824);
  EXPECT_EQ(imu[0].linear_acceleration[0], 9.0874956666666655);
  EXPECT_EQ(imu[0].linear_acceleration[1], 0.13075533333333333);
  EXPECT_EQ(imu[0].linear_acceleration[2], -3.6938381666666662);
  EXPECT_EQ(imu[1].utime, 1403715273267143);  // ...267142912 ns rounds up

  const auto cam0 = test::messagesOn<image_t>(events, "CAMERA");
  ASSERT_EQ(cam0.size(), 95u);
  EXPECT_EQ(cam0[0].utime, 1403715273262143);
  EXPECT_EQ(cam0[0].encoding, +image_t::ENCODING_PNG);
  EXPECT_EQ(cam0[0].width, 752);
  EXPECT_EQ(cam0[0].height, 480);
  EXPECT_EQ(cam0[0].frame, "C");
  EXPECT_EQ(cam0[0].data, readFileBytes(kEuroc + "/mav0/cam0/data/1403715273262142976.png"));
  EXPECT_EQ(cam0.back().utime, 1403715277962143);
  EXPECT_EQ(test::messagesOn<image_t>(events, "CAMERA_RIGHT")[0].frame, "C1");

  const auto gt = test::messagesOn<pose_t>(events, "GROUND_TRUTH");
  ASSERT_EQ(gt.size(), 2895u);
  // 1403715273.26214 0.878895 2.183400 0.948427 -0.824237 -0.106942 -0.551702 0.069433
  EXPECT_EQ(gt[0].utime, 1403715273262140);
  EXPECT_EQ(gt[0].position[0], 0.878895);
  EXPECT_EQ(gt[0].position[1], 2.1834);
  EXPECT_EQ(gt[0].position[2], 0.948427);
  const double n = std::sqrt(0.824237 * 0.824237 + 0.106942 * 0.106942 + 0.551702 * 0.551702 + 0.069433 * 0.069433);
  const double file_wxyz[4] = {0.069433 / n, -0.824237 / n, -0.106942 / n, -0.551702 / n};
  double dot = 0.0;  // q and -q are the same rotation
  for (int i = 0; i < 4; ++i) dot += gt[0].orientation[i] * file_wxyz[i];
  EXPECT_NEAR(std::fabs(dot), 1.0, 1e-12);
  EXPECT_EQ(r.report.metadataValue("cam0_intrinsics_fu_fv_cu_cv").substr(0, 6), "[458.6");
}

TEST(EurocImport, DecodedPngsAreGray8) {
  const std::string dir = test::freshTempDir("euroc_decoded");
  // A copy of the folder with one camera image keeps the test fast.
  const std::string root = dir + "/set";
  ASSERT_EQ(std::system(("mkdir -p " + root + "/mav0/cam0/data && cp " + kEuroc +
                         "/mav0/cam0/data/1403715273262142976.png " + root + "/mav0/cam0/data/")
                            .c_str()),
            0);
  ImportJob job;
  job.format = "euroc";
  job.input = root;
  job.out = dir + "/one.lcmlog";
  job.quiet = true;
  job.euroc.decode_png = true;
  const ImportOutcome r = runImport(job, nullptr);
  ASSERT_TRUE(r.ok());
  const auto cam = test::messagesOn<image_t>(test::readLog(job.out), "CAMERA");
  ASSERT_EQ(cam.size(), 1u);
  EXPECT_EQ(cam[0].encoding, +image_t::ENCODING_GRAY8);
  EXPECT_EQ(cam[0].row_stride, 752);
  EXPECT_EQ(cam[0].size, 752 * 480);
}

TEST(EurocImport, NotAnAslFolderIsAClearError) {
  const std::string dir = test::freshTempDir("euroc_wrong");
  ImportJob job;
  job.format = "euroc";
  job.input = dir;
  job.out = dir + "/x.lcmlog";
  job.quiet = true;
  const ImportOutcome r = runImport(job, nullptr);
  ASSERT_EQ(r.report.errors().size(), 1u);
  EXPECT_NE(r.report.errors()[0].find("not an EuRoC/ASL folder"), std::string::npos);
}

}  // namespace
}  // namespace livo::import
