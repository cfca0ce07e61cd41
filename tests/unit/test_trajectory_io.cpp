// Trajectory and ASL readers on the real files in ../shared/data.
#include <gtest/gtest.h>

#include <fstream>

#include "livo/asl_dataset.hpp"
#include "livo/trajectory_io.hpp"
#include "temp_path.hpp"

using namespace livo;

namespace {
const std::string kData = LIVO_SHARED_DATA;
}

TEST(TrajectoryIo, ReadsTumKittiAndDetectsFormats) {
  const std::string tum = kData + "/trajectories/V101_gt.txt";
  EXPECT_EQ(detectTrajectoryFormat(tum), TrajectoryFormat::kTum);
  const Trajectory gt = readTrajectory(tum);
  EXPECT_EQ(gt.size(), 2895u);
  EXPECT_NEAR(gt.front().stamp, 1403715273.26214, 1e-5);
  EXPECT_NEAR(gt.front().pose.translation().x(), 0.878895, 1e-9);
  // qx qy qz qw = -0.824237 -0.106942 -0.551702 0.069433
  const Quat q(gt.front().pose.linear());
  EXPECT_NEAR(std::abs(q.w()), 0.069433, 1e-5);

  const std::string kitti = kData + "/trajectories/KITTI_00_gt.txt";
  EXPECT_EQ(detectTrajectoryFormat(kitti), TrajectoryFormat::kKitti);
  const Trajectory k = readKittiPoses(kitti, kData + "/trajectories/KITTI_00_gt_times.txt");
  ASSERT_EQ(k.size(), 4541u);
  EXPECT_NEAR(k[1].stamp, 0.1037359, 1e-9);
  EXPECT_NEAR(k[2].pose.translation().z(), 1.716275, 1e-9);
}

TEST(TrajectoryIo, TumRoundTripAndErrors) {
  const Trajectory gt = readTum(kData + "/trajectories/freiburg1_xyz-groundtruth.txt");
  const std::string out = livo_test::tempPath("rt.tum");
  writeTum(out, gt);
  const Trajectory back = readTum(out);
  ASSERT_EQ(back.size(), gt.size());
  for (size_t i = 0; i < gt.size(); i += 97) {
    EXPECT_NEAR(back[i].stamp, gt[i].stamp, 1e-9);
    EXPECT_NEAR((back[i].pose.matrix() - gt[i].pose.matrix()).norm(), 0.0, 1e-8);
  }
  const std::string bad = livo_test::tempPath("bad.tum");
  std::ofstream(bad) << "1 0 0 0 0 0 0 1\n2 0 0 x 0 0 0 1\n";
  try {
    readTum(bad);
    FAIL();
  } catch (const TrajectoryError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.tum:2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(readTum("/nonexistent.tum"), TrajectoryError);
}

TEST(AslDataset, ReadsImuImagesAndSensorYaml) {
  const std::string mav = kData + "/euroc_v1_01/mav0";
  const auto imu = readAslImuCsv(mav + "/imu0/data.csv");
  EXPECT_EQ(imu.size(), 29120u);
  EXPECT_EQ(imu.front().stamp_ns, 1403715273262142976LL);
  EXPECT_NEAR(imu.front().accel.x(), 9.0874956666666655, 1e-12);
  const auto images = listAslImages(mav + "/cam0");
  EXPECT_EQ(images.size(), 95u);
  EXPECT_EQ(images.front().stamp_ns, 1403715273262142976LL);
  const auto cam = readAslSensorYaml(mav + "/cam0/sensor.yaml");
  EXPECT_EQ(cam.width, 752);
  EXPECT_EQ(cam.intrinsics.size(), 4u);
  EXPECT_EQ(cam.distortion.size(), 4u);
  EXPECT_GT(cam.T_body_sensor.translation().norm(), 0.0);
  const auto imuy = readAslSensorYaml(mav + "/imu0/sensor.yaml");
  EXPECT_NEAR(imuy.gyro_noise_density, 1.6968e-04, 1e-12);
  EXPECT_DOUBLE_EQ(imuy.rate_hz, 200.0);
}
