// The control overlays of config/sim/controls/ (livo-sim --overlay): the same scene, seed and rig with
// one group of the simulator's sensor errors switched off and every other error left as it was.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "livo/sim/simulation_setup.hpp"
#include "temp_path.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

std::string sourcePath(const std::string& relative) { return std::string(LIVO_SOURCE_DIR) + "/" + relative; }

SimulationSetup bridge(const std::string& control) {
  SimOverrides o;
  o.seed = 2;
  o.no_images = true;
  if (!control.empty()) o.overlays = {sourcePath("config/sim/controls/" + control + ".yaml")};
  return loadSimulation(sourcePath("config/sim/bridge_deck_graded.yaml"), o);
}

void expectSameRig(const SensorRig& a, const SensorRig& b) {
  ASSERT_TRUE(a.lidar && b.lidar && a.camera && b.camera && a.wheel && b.wheel);
  EXPECT_TRUE(a.lidar->T_I_L.matrix() == b.lidar->T_I_L.matrix());
  EXPECT_TRUE(a.camera->T_I_C.matrix() == b.camera->T_I_C.matrix());
  EXPECT_EQ(a.imu.gyro_noise_density, b.imu.gyro_noise_density);
  EXPECT_EQ(a.imu.gyro_scale_std, b.imu.gyro_scale_std);
  EXPECT_TRUE(a.wheel->T_I_B.matrix() == b.wheel->T_I_B.matrix());
  EXPECT_EQ(a.wheel->track_width, b.wheel->track_width);
}

}  // namespace

TEST(SimControls, ExactImuSwitchesOffTheImuErrorsOnly) {
  const SimulationSetup base = bridge(""), control = bridge("exact_imu");
  ASSERT_TRUE(base.options.imu_errors.any());  // the scene has them: else the control shows nothing
  EXPECT_FALSE(control.options.imu_errors.any());
  // what the estimators model stays: the initial biases, the wheels' and the other sensors' errors
  EXPECT_TRUE(control.options.initial_gyro_bias == base.options.initial_gyro_bias);
  EXPECT_EQ(control.options.wheel_left_scale, base.options.wheel_left_scale);
  EXPECT_TRUE(control.options.wheel_slip.enabled());
  EXPECT_FALSE(control.options.calibration_errors.wheel.isZero());
  EXPECT_FALSE(control.options.calibration_errors.lidar.isZero());
  expectSameRig(control.rig, base.rig);
  EXPECT_NE(control.config_file.find(" + "), std::string::npos) << control.config_file;
}

TEST(SimControls, ExactWheelsSwitchesOffTheWheelErrorsOnly) {
  const SimulationSetup base = bridge(""), control = bridge("exact_wheels");
  ASSERT_NE(base.options.wheel_left_scale, 1.0);
  ASSERT_TRUE(base.options.wheel_slip.enabled());
  ASSERT_FALSE(base.options.calibration_errors.wheel.isZero());
  EXPECT_EQ(control.options.wheel_left_scale, 1.0);
  EXPECT_EQ(control.options.wheel_right_scale, 1.0);
  EXPECT_FALSE(control.options.wheel_slip.enabled());
  EXPECT_TRUE(control.options.calibration_errors.wheel.isZero());
  EXPECT_EQ(control.options.calibration_errors.wheel_time_offset_s, 0.0);
  EXPECT_TRUE(control.options.imu_errors.any());
  EXPECT_FALSE(control.options.calibration_errors.lidar.isZero());
  EXPECT_EQ(control.options.calibration_errors.lidar_time_offset_s,
            base.options.calibration_errors.lidar_time_offset_s);
  expectSameRig(control.rig, base.rig);
}

TEST(SimControls, AMissingOverlayOrAMisspeltKeyIsRefusedNamingIt) {
  SimOverrides o;
  o.overlays = {sourcePath("config/sim/controls/absent.yaml")};
  EXPECT_THROW(loadSimulation(sourcePath("config/sim/bridge_deck_graded.yaml"), o), ConfigError);
  const std::string typo = livo_test::tempPath("typo_control.yaml");
  std::ofstream(typo) << "sim:\n  imu:\n    gyro_scale_pm: [0, 0, 0]\n";
  o.overlays = {typo};
  try {
    loadSimulation(sourcePath("config/sim/bridge_deck_graded.yaml"), o);
    FAIL() << "a misspelt key was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("gyro_scale_pm"), std::string::npos) << e.what();
  }
}
