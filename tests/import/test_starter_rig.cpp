// livo-import --rig-out and --rig: the starter rig written from what a bag told (camera_info.bag of
// make_test_bags.py: VLP-16 clouds, a 200 Hz IMU, rgb8 images with a CameraInfo), read back with
// the rig reader every process uses; and a rig checked against the log.
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "livo/config.hpp"
#include "livo/import/import_job.hpp"
#include "livo/import/lidar_models.hpp"
#include "livo/import/starter_rig_config.hpp"
#include "livo/sensor_rig.hpp"
#include "log_reading.hpp"

namespace livo::import {
namespace {

using nlohmann::json;
const std::string kBag = std::string(LIVO_IMPORT_TEST_BAGS) + "/camera_info.bag";

json expected() {
  std::ifstream in(kBag + ".expected.json");
  EXPECT_TRUE(in.good()) << kBag << ".expected.json (written by the import_make_test_bags fixture)";
  return in ? json::parse(in) : json();
}

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

ImportJob cameraInfoJob(const std::string& dir) {
  ImportJob job;
  job.format = "rosbag";
  job.input = kBag;
  job.out = dir + "/out.lcmlog";
  job.rig_out = dir + "/rig.yaml";
  job.quiet = true;
  return job;
}

/// The line of `text` holding `key:` (with its comment).
std::string lineOf(const std::string& text, const std::string& key) {
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (line.find(" " + key + ":") != std::string::npos) return line;
  return "";
}

TEST(StarterRig, CameraInfoGivesTheIntrinsicsAndTheLogTheRest) {
  const json e = expected();
  const json& ci = e["camera_info"];
  const std::string dir = test::freshTempDir("starter_rig");
  const ImportOutcome r = runImport(cameraInfoJob(dir), nullptr);
  ASSERT_TRUE(r.ok());
  // The camera's namespace decides between the two CameraInfo topics.
  EXPECT_EQ(r.report.metadataValue("topic_camera-info"), "\"/camera/camera_info\"");
  ASSERT_TRUE(r.report.calibration().camera.has_value());
  EXPECT_EQ(r.report.calibration().camera->source, "camera_info /camera/camera_info");

  const std::string text = readText(dir + "/rig.yaml");
  const SensorRig rig = readSensorRig(Config::load(dir + "/rig.yaml").section("rig"));
  ASSERT_TRUE(rig.camera && rig.lidar);
  EXPECT_EQ(rig.camera->width, ci["width"].get<int>());
  EXPECT_EQ(rig.camera->height, ci["height"].get<int>());
  EXPECT_EQ(rig.camera->fx, ci["fx"].get<double>());
  EXPECT_EQ(rig.camera->fy, ci["fy"].get<double>());
  EXPECT_EQ(rig.camera->cx, ci["cx"].get<double>());
  EXPECT_EQ(rig.camera->cy, ci["cy"].get<double>());
  EXPECT_EQ(rig.camera->distortion_model, DistortionModel::kRadtan);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(rig.camera->distortion[i], ci["D"][i].get<double>()) << i;
  EXPECT_NE(lineOf(text, "distortion").find("REPLACE:"), std::string::npos) << "the dropped k3 is said";
  EXPECT_TRUE(rig.camera->color);
  EXPECT_EQ(rig.camera->rate_hz, e["camera_hz"].get<double>());
  EXPECT_EQ(rig.imu.rate_hz, e["imu_hz"].get<double>());
  EXPECT_EQ(rig.lidar->rate_hz, e["lidar_hz"].get<double>());
  EXPECT_EQ(rig.lidar->model, "VLP-16");
  EXPECT_EQ(rig.channels.imu, "IMU");
  EXPECT_EQ(rig.channels.camera, "CAMERA");
  // What the bag could not tell is marked, with its placeholder.
  for (const char* key : {"gyro_noise_density", "accel_random_walk", "gravity", "T_I_L", "min_range", "time_offset_s"})
    EXPECT_NE(lineOf(text, key).find("REPLACE:"), std::string::npos) << key << ": " << lineOf(text, key);
  EXPECT_NE(text.find("REPLACE: p_I = T_I_C p_C"), std::string::npos);
  for (const char* key : {"fx", "cx", "rate_hz", "model", "color", "width"})
    EXPECT_EQ(lineOf(text, key).find("REPLACE:"), std::string::npos) << key << ": " << lineOf(text, key);
  // The pipeline sections of a rig with a LiDAR and a camera.
  for (const char* section : {"\nlio:", "\nvio: {}", "\nloop:", "\ncolour: {}", "\noctomap: {}"})
    EXPECT_NE(text.find(section), std::string::npos) << section;
  // The sidecar repeats what was measured.
  EXPECT_EQ(r.report.metadataValue("camera_resolution"), "[8, 6]");
  EXPECT_EQ(r.report.metadataValue("lidar_rings"), "16");
}

TEST(StarterRig, IsTheSameForTheSameBag) {
  const std::string a = test::freshTempDir("starter_rig_a"), b = test::freshTempDir("starter_rig_b");
  ImportJob ja = cameraInfoJob(a), jb = cameraInfoJob(b);
  jb.out = ja.out;  // the log's path is in the header comment
  ASSERT_TRUE(runImport(ja, nullptr).ok());
  ASSERT_TRUE(runImport(jb, nullptr).ok());
  EXPECT_EQ(readText(a + "/rig.yaml"), readText(b + "/rig.yaml"));
}

TEST(StarterRig, APresetGivesItsDatasetsExtrinsicsAndCalibratedRig) {
  const std::string dir = test::freshTempDir("starter_rig_ntu");
  ImportJob job;
  job.format = "rosbag";
  job.input = std::string(LIVO_IMPORT_TEST_BAGS) + "/ntu_viral.bag";
  job.out = dir + "/out.lcmlog";
  job.rig_out = dir + "/rig.yaml";
  job.preset = "ntu_viral";
  job.quiet = true;
  applyPreset(job);
  ASSERT_TRUE(runImport(job, nullptr).ok());
  const std::string text = readText(job.rig_out);
  const SensorRig rig = readSensorRig(Config::load(job.rig_out).section("rig"));
  ASSERT_TRUE(rig.lidar && rig.camera);
  EXPECT_EQ(rig.lidar->model, "OS1-16");  // 16 rings, Ouster's t field
  EXPECT_TRUE(rig.lidar->T_I_L.translation().isApprox(Vec3(-0.05, 0.0, 0.055)));
  EXPECT_NEAR(rig.camera->T_I_C.translation().y(), -0.12431302, 1e-12);
  EXPECT_FALSE(rig.camera->color);  // mono8
  EXPECT_NE(text.find("config/rigs/ntu_viral.yaml is this dataset's calibrated rig"), std::string::npos);
  EXPECT_EQ(lineOf(text, "T_I_L").find("REPLACE:"), std::string::npos) << lineOf(text, "T_I_L");
  EXPECT_NE(lineOf(text, "T_I_L").find("preset ntu_viral"), std::string::npos) << lineOf(text, "T_I_L");
}

SensorRig templateRig() {
  return readSensorRig(
      Config::load(std::string(LIVO_SOURCE_DIR) + "/config/rigs/template_velodyne_vlp16.yaml").section("rig"));
}

TEST(RigCheck, ImageSizeIsAnErrorNamingBothSizes) {
  const std::string dir = test::freshTempDir("rig_check_size");
  ImportJob job = cameraInfoJob(dir);
  job.rig = templateRig();  // 640x480, fx 500
  job.rig_file = "template.yaml";
  const ImportOutcome r = runImport(job, nullptr);
  ASSERT_TRUE(r.ok());
  EXPECT_FALSE(r.rigFits());
  ASSERT_FALSE(r.rig_findings.empty());
  const RigFinding& first = r.rig_findings.front();
  EXPECT_TRUE(first.error);
  EXPECT_NE(first.message.find("640x480"), std::string::npos) << first.message;
  EXPECT_NE(first.message.find("8x6"), std::string::npos) << first.message;
  EXPECT_NE(first.message.find("template.yaml"), std::string::npos) << first.message;
  bool intrinsics = false;
  for (const RigFinding& f : r.rig_findings)
    if (!f.error && f.message.find("intrinsics") != std::string::npos) {
      intrinsics = true;
      EXPECT_NE(f.message.find("fx 500"), std::string::npos) << f.message;
      EXPECT_NE(f.message.find("fx 5.5"), std::string::npos) << f.message;
    }
  EXPECT_TRUE(intrinsics) << "a warning for the intrinsics against camera_info";
}

TEST(RigCheck, TheStarterRigFitsItsOwnLog) {
  const std::string dir = test::freshTempDir("rig_check_own");
  ASSERT_TRUE(runImport(cameraInfoJob(dir), nullptr).ok());
  ImportJob job = cameraInfoJob(dir);
  job.out = dir + "/again.lcmlog";
  job.rig_out.clear();
  job.rig_file = dir + "/rig.yaml";
  job.rig = readSensorRig(Config::load(job.rig_file).section("rig"));
  const ImportOutcome r = runImport(job, nullptr);
  EXPECT_TRUE(r.rigFits());
  for (const RigFinding& f : r.rig_findings) ADD_FAILURE() << (f.error ? "error: " : "warning: ") << f.message;
}

TEST(RigCheck, RatesAndRingsAreWarnings) {
  const std::string dir = test::freshTempDir("rig_check_rates");
  ImportJob job = cameraInfoJob(dir);
  job.rig_out.clear();
  SensorRig rig = templateRig();
  rig.camera->width = 8;
  rig.camera->height = 6;
  rig.imu.rate_hz = 400;
  rig.lidar->model = "VLP-32C";
  job.rig = rig;
  job.rig_file = "mine.yaml";
  const ImportOutcome r = runImport(job, nullptr);
  EXPECT_TRUE(r.rigFits());
  std::string all;
  for (const RigFinding& f : r.rig_findings) all += f.message + "\n";
  EXPECT_NE(all.find("IMU rate: the rig (mine.yaml: rig.imu.rate_hz) says 400 Hz, the log's stamps 200 Hz"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("VLP-32C (32 rings), the log's sweeps have 16"), std::string::npos) << all;
}

TEST(CameraInfo, DistortionModelsAndUncalibratedCameras) {
  RosCameraInfo m;
  m.width = 100;
  m.height = 50;
  m.K = {40.0, 0.0, 50.0, 0.0, 41.0, 25.0, 0.0, 0.0, 1.0};
  m.distortion_model = "equidistant";
  m.D = {0.1, 0.2, 0.3, 0.4};
  std::optional<CameraIntrinsics> k = intrinsicsFromCameraInfo(m, "/fish/camera_info");
  ASSERT_TRUE(k);
  EXPECT_EQ(k->distortion_model, DistortionModel::kEquidistant);
  EXPECT_EQ(k->distortion[3], 0.4);
  EXPECT_EQ(k->fy, 41.0);
  EXPECT_TRUE(k->note.empty()) << k->note;
  m.distortion_model = "rational_polynomial";
  m.D = {0.1, 0.2, 0.0, 0.0, 0.01, 0.02, 0.0, 0.0};
  k = intrinsicsFromCameraInfo(m, "/x");
  ASSERT_TRUE(k);
  EXPECT_EQ(k->distortion_model, DistortionModel::kRadtan);
  EXPECT_NE(k->note.find("rational_polynomial"), std::string::npos) << k->note;
  m.K = {};
  EXPECT_FALSE(intrinsicsFromCameraInfo(m, "/x")) << "K[0] == 0: uncalibrated";
}

TEST(LidarModels, GuessedFromRingsAndTimeLayout) {
  const std::string velodyne = "x y z intensity ring time(float32 s, relative)";
  const std::string ouster = "x y z intensity ring t(uint32 ns, relative)";
  const std::string hesai = "x y z intensity ring timestamp(float64 s, absolute)";
  EXPECT_EQ(guessLidarModel(16, false, velodyne, "").facts->model, "VLP-16");
  EXPECT_EQ(guessLidarModel(16, false, ouster, "").facts->model, "OS1-16");
  EXPECT_EQ(guessLidarModel(32, false, velodyne, "").facts->model, "VLP-32C");
  EXPECT_EQ(guessLidarModel(32, false, hesai, "").facts->model, "hesai-xt32");
  EXPECT_EQ(guessLidarModel(64, false, velodyne, "").facts->model, "HDL-64E");
  EXPECT_EQ(guessLidarModel(64, false, ouster, "").facts->model, "OS1-64");
  EXPECT_EQ(guessLidarModel(128, false, ouster, "").facts->model, "OS1-128");
  EXPECT_EQ(guessLidarModel(128, false, ouster, "OS0-128").facts->model, "OS0-128");
  EXPECT_EQ(guessLidarModel(6, true, "x y z intensity line offset_time(uint32 ns, relative)", "").facts->model,
            "livox-avia");
  EXPECT_EQ(guessLidarModel(4, true, "", "").facts->model, "livox-mid360");
  const LidarModelGuess odd = guessLidarModel(40, false, velodyne, "");
  EXPECT_FALSE(odd.exact);
  EXPECT_EQ(odd.facts->model, "VLP-32C");
  for (const std::string& m : kLidarModels) EXPECT_NE(findLidarModel(m), nullptr) << m << " has no facts";
}

TEST(RigSurvey, RateIsTheMedianInterval) {
  std::vector<int64_t> stamps;
  for (int i = 0; i < 100; ++i) stamps.push_back(1000000 + i * 5000);
  stamps.push_back(stamps.back());           // a duplicate
  stamps.push_back(stamps.back() + 500000);  // a gap
  std::swap(stamps[3], stamps[60]);          // out of order
  const MeasuredRate r = measureRate(stamps);
  EXPECT_EQ(r.messages, 102);
  EXPECT_DOUBLE_EQ(r.hz, 200.0);
}

}  // namespace
}  // namespace livo::import
