// The rig's camera keys: depth (an RGB-D camera's registered depth, its channel) and the
// distortion model, read, printed and validated; the model read from an ASL sensor.yaml; the LiDAR
// model; the wheel's calibration uncertainty (its mounting rotation only).
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "livo/asl_dataset.hpp"
#include "livo/sensor_rig.hpp"
#include "livo/trajectory_io.hpp"

using namespace livo;

namespace {

std::string rigYaml(const std::string& camera_extra, const std::string& channels = "") {
  return "rig:\n" + channels +
         "  imu: {rate_hz: 200, gyro_noise_density: 0, gyro_random_walk: 0, accel_noise_density: 0, "
         "accel_random_walk: 0}\n"
         "  camera:\n"
         "    width: 640\n    height: 480\n    fx: 400\n    fy: 400\n    cx: 319.5\n    cy: 239.5\n"
         "    rate_hz: 30\n    T_I_C: {translation: [0, 0, 0], rpy_deg: [0, 0, 0]}\n" +
         camera_extra;
}

SensorRig readRig(const std::string& yaml) {
  return readSensorRig(Config::fromString(yaml, "rig.yaml").section("rig"));
}

std::string errorOf(const std::string& yaml) {
  try {
    readRig(yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SensorRig, CameraDefaultsToNoDepthAndRadtan) {
  const SensorRig r = readRig(rigYaml(""));
  ASSERT_TRUE(r.camera);
  EXPECT_FALSE(r.camera->depth);
  EXPECT_EQ(r.camera->distortion_model, DistortionModel::kRadtan);
  EXPECT_EQ(r.channels.depth, "DEPTH");
  std::ostringstream os;
  printSensorRig(r, os);
  EXPECT_EQ(os.str().find("depth"), std::string::npos) << os.str();
  EXPECT_NE(os.str().find("radtan distortion"), std::string::npos) << os.str();
}

TEST(SensorRig, DepthCameraOnItsChannel) {
  const SensorRig r = readRig(rigYaml("    depth: true\n", "  channels: {depth: ALIGNED_DEPTH}\n"));
  ASSERT_TRUE(r.camera);
  EXPECT_TRUE(r.camera->depth);
  EXPECT_EQ(r.channels.depth, "ALIGNED_DEPTH");
  std::ostringstream os;
  printSensorRig(r, os);
  EXPECT_NE(os.str().find("depth images registered to it on ALIGNED_DEPTH"), std::string::npos) << os.str();
  const std::string e = errorOf(rigYaml("    depth: true\n", "  channels: {depth: CAMERA}\n"));
  EXPECT_NE(e.find("channels.depth"), std::string::npos) << e;
  EXPECT_NE(e.find("a channel of their own"), std::string::npos) << e;
  EXPECT_NE(errorOf(rigYaml("    depth: maybe\n")), "");
}

TEST(SensorRig, DistortionModelIsReadAndChecked) {
  const SensorRig r =
      readRig(rigYaml("    distortion_model: equidistant\n    distortion: [0.01, -0.002, 0.0005, -0.0001]\n"));
  EXPECT_EQ(r.camera->distortion_model, DistortionModel::kEquidistant);
  EXPECT_DOUBLE_EQ(r.camera->distortion[2], 0.0005);
  std::ostringstream os;
  printSensorRig(r, os);
  EXPECT_NE(os.str().find("equidistant distortion [0.01, -0.002, 0.0005, -0.0001]"), std::string::npos) << os.str();
  EXPECT_EQ(readRig(rigYaml("    distortion_model: radtan\n")).camera->distortion_model, DistortionModel::kRadtan);
  const std::string e = errorOf(rigYaml("    distortion_model: fisheye\n"));
  EXPECT_NE(e.find("camera.distortion_model"), std::string::npos) << e;
  EXPECT_NE(e.find("not radtan or equidistant"), std::string::npos) << e;
  const std::string n = errorOf(rigYaml("    distortion_model: equidistant\n    distortion: [0.1, 0.2]\n"));
  EXPECT_NE(n.find("[k1, k2, k3, k4]"), std::string::npos) << n;
}

// ASL sensor.yaml: EuRoC's cam0 says radial-tangential, TUM-VI's say equidistant; the camera rig
// made from one carries the model.
TEST(SensorRig, AslSensorYamlCarriesTheDistortionModelIntoTheRig) {
  const std::string euroc = std::string(LIVO_SHARED_DATA) + "/euroc_v1_01/mav0/cam0/sensor.yaml";
  const CameraRig e = aslCameraRig(readAslSensorYaml(euroc), euroc);
  EXPECT_EQ(e.distortion_model, DistortionModel::kRadtan);
  EXPECT_EQ(e.width, 752);
  EXPECT_DOUBLE_EQ(e.fx, 458.654);
  EXPECT_DOUBLE_EQ(e.distortion[3], 1.76187114e-05);
  EXPECT_DOUBLE_EQ(e.rate_hz, 20.0);

  const std::string tumvi = ::testing::TempDir() + "livo_tumvi_cam0_sensor.yaml";
  {
    std::ofstream out(tumvi);
    out << "%YAML:1.0\nsensor_type: camera\n"
           "T_BS:\n  cols: 4\n  rows: 4\n  data: [1, 0, 0, 0.1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]\n"
           "rate_hz: 20\nresolution: [512, 512]\ncamera_model: pinhole\n"
           "intrinsics: [190.97847715128717, 190.9733070521226, 254.93170605935475, 256.8974428996504]\n"
           "distortion_model: equidistant\n"
           "distortion_coefficients: [0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202, "
           "0.00020293673591811182]\n";
  }
  const CameraRig t = aslCameraRig(readAslSensorYaml(tumvi), tumvi);
  EXPECT_EQ(t.distortion_model, DistortionModel::kEquidistant);
  EXPECT_DOUBLE_EQ(t.distortion[2], -0.0020532361418706202);
  EXPECT_DOUBLE_EQ(t.T_I_C.translation().x(), 0.1);
  {
    std::ofstream out(tumvi);
    out << "resolution: [512, 512]\nintrinsics: [190, 190, 255, 256]\ndistortion_model: fov\n"
           "distortion_coefficients: [0.9]\n";
  }
  try {
    readAslSensorYaml(tumvi);
    ADD_FAILURE() << "an unknown distortion model is refused";
  } catch (const TrajectoryError& err) {
    EXPECT_NE(std::string(err.what()).find("'fov'"), std::string::npos) << err.what();
  }
  std::remove(tumvi.c_str());
}

// The LiDAR model is one of kLidarModels: the simulator's and the real sensors of config/rigs/.
TEST(SensorRig, LidarModelIsOneOfTheKnown) {
  auto withLidar = [](const std::string& model) {
    return rigYaml("") + "  lidar: {model: " + model +
           ", rate_hz: 10, min_range: 1, max_range: 200, range_noise_std: 0.03, "
           "T_I_L: {translation: [0, 0, 0], rpy_deg: [0, 0, 0]}}\n";
  };
  for (const std::string& model : kLidarModels) EXPECT_EQ(errorOf(withLidar(model)), "") << model;
  EXPECT_EQ(readRig(withLidar("VLP-32C")).lidar->model, "VLP-32C");
  const std::string e = errorOf(withLidar("VLP-32"));
  EXPECT_NE(e.find("rig.lidar.model: unknown LiDAR model 'VLP-32'"), std::string::npos) << e;
}

// The wheel's calibration_std (read as the LiDAR's and the camera's): its rotation only, absent is
// exact (nothing estimated, the rig printed as before); a translation or time offset is refused.
TEST(SensorRig, WheelStatesItsMountingRotationUncertainty) {
  auto withWheel = [](const std::string& extra) {
    return rigYaml("") + "  wheel: {rate_hz: 50, track_width: 1.1, speed_noise_std: 0.03, " + extra +
           "T_I_B: {translation: [-0.8, 0, -1.15], rpy_deg: [0, 0, 0]}}\n";
  };
  const SensorRig exact = readRig(withWheel(""));
  ASSERT_TRUE(exact.wheel);
  EXPECT_EQ(exact.wheel->calibration_std.rotation_deg, 0.0);
  std::ostringstream exact_print;
  printSensorRig(exact, exact_print);
  EXPECT_EQ(exact_print.str().find("known to"), std::string::npos) << exact_print.str();

  const SensorRig stated = readRig(withWheel("calibration_std: {rotation_deg: 0.5}, "));
  EXPECT_DOUBLE_EQ(stated.wheel->calibration_std.rotation_deg, 0.5);
  std::ostringstream stated_print;
  printSensorRig(stated, stated_print);
  EXPECT_NE(stated_print.str().find("rotation known to 0.5 deg"), std::string::npos) << stated_print.str();

  const std::string t = errorOf(withWheel("calibration_std: {rotation_deg: 0.5, translation: 0.02}, "));
  EXPECT_NE(t.find("rig.wheel.calibration_std"), std::string::npos) << t;
  EXPECT_NE(t.find("only rotation_deg"), std::string::npos) << t;
  EXPECT_NE(errorOf(withWheel("calibration_std: {time_offset_s: 0.005}, ")), "");
  EXPECT_NE(errorOf(withWheel("calibration_std: {rotation_deg: 20}, ")), "");  // the shared range check
}
