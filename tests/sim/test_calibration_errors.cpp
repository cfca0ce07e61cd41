// Calibration errors and the IMU error model: the simulator renders with the TRUE rig (nominal rig
// times the configured errors, sensors read at stamp + time offset) while `rig:` stays the belief;
// IMU scale, misalignment, g-sensitivity and temperature bias against the analytic formula; seeded
// draws against their 1-sigmas; and configuration mistakes named by file and key.
#include <gtest/gtest.h>

#include <cmath>

#include "livo/sim/calibration_errors.hpp"
#include "livo/sim/camera_renderer.hpp"
#include "livo/sim/imu_model.hpp"
#include "livo/sim/lidar_scanner.hpp"
#include "livo/sim/simulation_setup.hpp"
#include "livo/sim/simulator.hpp"
#include "livo/sim/wheel_model.hpp"
#include "sim_test_support.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

constexpr double kOffset = 0.0123;  // s, a time offset error larger than a frame of motion blur

/// A moving rig in the 10 x 8 x 4 m box room: noise-free IMU, VLP-16 without noise or dropouts,
/// a small noise-free camera and a wheel encoder; `extra` is appended under sim:.
std::string movingRig(const std::string& extra = "") {
  return R"(
rig:
  imu: {rate_hz: 200, gyro_noise_density: 0, gyro_random_walk: 0, accel_noise_density: 0, accel_random_walk: 0, gravity: 9.81}
  lidar: {model: VLP-16, rate_hz: 10, min_range: 0.3, max_range: 50, range_noise_std: 0, dropout_probability: 0,
          T_I_L: {translation: [0.1, 0.0, 0.2], rpy_deg: [0, 0, 30]}}
  camera: {width: 64, height: 48, fx: 40, fy: 40, cx: 31.5, cy: 23.5, distortion: [0, 0, 0, 0], rate_hz: 20,
           color: false, T_I_C: {translation: [0.05, 0.0, 0.0], rpy_deg: [-90, 0, -90]}}
  wheel: {rate_hz: 50, track_width: 0.5, speed_noise_std: 0, T_I_B: {translation: [0, 0, -0.5], rpy_deg: [0, 0, 0]}}
sim:
  duration_s: 0.35
  camera: {noise_std: 0}
)" + test::boxRoomScene() +
         "  trajectory: {type: handheld, waypoints: [-2,-1,1.2, 2,-1,1.3, 2,2,1.2], speed: 1.5, start_still_s: 0, "
         "ramp_s: 0.1}\n" +
         extra;
}

SimulationSetup load(const std::string& yaml, uint64_t seed = 1) {
  SimOverrides o;
  o.seed = seed;
  return loadSimulation(Config::fromString(yaml, "calib.yaml"), "", o);
}

test::CollectingSink simulate(const SimulationSetup& setup) {
  test::CollectingSink sink;
  Simulator(setup).run(sink);
  return sink;
}

/// The extrinsic error used below, built independently of ExtrinsicError::transform.
const Vec3 kErrT(0.03, -0.02, 0.05), kErrRpyDeg(1.5, -2.0, 3.0);
const char* kErrYaml = "{translation: [0.03, -0.02, 0.05], rpy_deg: [1.5, -2.0, 3.0]}";
Pose3 errorTransform() {
  const Vec3 r = kErrRpyDeg * M_PI / 180.0;
  Pose3 T = Pose3::Identity();
  T.linear() = so3::Exp(Vec3(0, 0, r.z())) * so3::Exp(Vec3(0, r.y(), 0)) * so3::Exp(Vec3(r.x(), 0, 0));
  T.translation() = kErrT;
  return T;
}

void expectSameSweeps(const std::vector<LidarSweep>& a, const std::vector<LidarSweep>& b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].utime, b[k].utime);
    ASSERT_EQ(a[k].size(), b[k].size()) << "sweep " << k;
    for (size_t i = 0; i < a[k].size(); ++i) {
      ASSERT_NEAR(a[k].x[i], b[k].x[i], tol);
      ASSERT_NEAR(a[k].y[i], b[k].y[i], tol);
      ASSERT_NEAR(a[k].z[i], b[k].z[i], tol);
      ASSERT_EQ(a[k].time_offset[i], b[k].time_offset[i]);
    }
  }
}

/// Distance of a world point inside the box room to its surface.
double offRoomSurface(const Vec3& p) {
  const Vec3 lo(-5, -4, 0), hi(5, 4, 4);
  return std::min((p - lo).minCoeff(), (hi - p).minCoeff());
}

/// Mean distance to the room's surface of a sweep's points put into the world with T_I_L and the
/// body poses at stamp + time_offset + clock_offset.
double meanOffSurface(const LidarSweep& sweep, const SimulationSetup& s, const Pose3& T_I_L,
                      double clock_offset = 0.0) {
  double sum = 0.0;
  for (size_t i = 0; i < sweep.size(); ++i) {
    const double t = s.trajectoryTime(sweep.utime) + clock_offset + sweep.time_offset[i];
    const Vec3 p_L(sweep.x[i], sweep.y[i], sweep.z[i]);
    sum += std::abs(offRoomSurface(s.trajectory->at(t).T_W_I * T_I_L * p_L));
  }
  return sum / static_cast<double>(sweep.size());
}

std::string configError(const std::string& yaml) {
  try {
    load(yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// A LiDAR mounted off its nominal pose by T_err gives the cloud of a rig whose nominal pose is the
// true one; put into the world with the nominal T_I_L it misses the walls, with the true one it
// lies on them.
TEST(CalibrationErrors, LidarExtrinsicErrorRendersFromTheTrueMounting) {
  const SimulationSetup wrong = load(movingRig(std::string("  calibration_errors: {lidar: ") + kErrYaml + "}\n"));
  SimulationSetup truth = load(movingRig());
  const Pose3 nominal = truth.rig.lidar->T_I_L;
  truth.rig.lidar->T_I_L = nominal * errorTransform();
  EXPECT_TRUE(wrong.rig.lidar->T_I_L.isApprox(nominal, 0.0));  // the belief is untouched
  const auto a = simulate(wrong), b = simulate(truth);
  ASSERT_EQ(a.sweeps.size(), 3u);
  expectSameSweeps(a.sweeps, b.sweeps, 1e-6);
  for (const LidarSweep& sweep : a.sweeps) {
    EXPECT_LT(meanOffSurface(sweep, wrong, truth.rig.lidar->T_I_L), 1e-6);  // float rounding of the points
    // the 6 cm / 3.9 deg error moves a point at 2..6 m by 10 cm or more
    EXPECT_GT(meanOffSurface(sweep, wrong, nominal), 0.05);
  }
}

TEST(CalibrationErrors, LidarTimeOffsetSweepsFromThePoseAtStampPlusOffset) {
  const SimulationSetup late = load(movingRig("  calibration_errors: {lidar_time_offset_s: 0.0123}\n"));
  const auto got = simulate(late);
  ASSERT_EQ(got.sweeps.size(), 3u);
  const LidarScanner scanner(*late.rig.lidar, late.options.lidar);
  for (const LidarSweep& sweep : got.sweeps) {
    const double t = late.trajectoryTime(sweep.utime);
    const double sensor_time = (sweep.utime - late.start_utime) * 1e-6;
    const LidarSweep shifted =
        scanner.scan(*late.scene, *late.trajectory, t + kOffset, sweep.utime, sensor_time, Random(9, 9));
    const LidarSweep on_time = scanner.scan(*late.scene, *late.trajectory, t, sweep.utime, sensor_time, Random(9, 9));
    expectSameSweeps({sweep}, {shifted}, 0.0);
    EXPECT_LT(meanOffSurface(sweep, late, late.rig.lidar->T_I_L, kOffset), 1e-6);  // on the walls at stamp + offset
    EXPECT_GT(meanOffSurface(sweep, late, late.rig.lidar->T_I_L), 0.01);           // 12 ms at up to 1.5 m/s: off them
    ASSERT_EQ(on_time.size(), sweep.size());
    EXPECT_NE(on_time.x, sweep.x);
  }
}

TEST(CalibrationErrors, CameraRendersFromTheTruePoseAndTime) {
  const std::string errors =
      std::string("  calibration_errors: {camera: ") + kErrYaml + ", camera_time_offset_s: 0.0123}\n";
  const SimulationSetup wrong = load(movingRig(errors));
  const SimulationSetup plain = load(movingRig());
  const auto a = simulate(wrong), b = simulate(plain);
  ASSERT_EQ(a.images.size(), 7u);
  ASSERT_EQ(a.images.size(), b.images.size());
  CameraRig mounted = *plain.rig.camera;
  mounted.T_I_C = mounted.T_I_C * errorTransform();
  const CameraRenderer renderer(mounted, plain.options.camera);
  for (size_t k = 0; k < a.images.size(); ++k) {
    EXPECT_EQ(a.images[k].utime, b.images[k].utime);  // stamps are the belief's
    EXPECT_EQ(a.images[k].log_utime, b.images[k].log_utime);
    const double t = plain.trajectoryTime(a.images[k].log_utime) + kOffset;
    const CameraImage expected = renderer.render(*plain.scene, *plain.trajectory, t, a.images[k].utime, Random(3, 3));
    EXPECT_EQ(a.images[k].data, expected.data) << "image " << k;
    EXPECT_NE(a.images[k].data, b.images[k].data);
  }
}

TEST(CalibrationErrors, WheelReadsTheTrueBaseAtStampPlusOffset) {
  const std::string errors =
      std::string("  calibration_errors: {wheel: ") + kErrYaml + ", wheel_time_offset_s: 0.0123}\n";
  const SimulationSetup wrong = load(movingRig(errors));
  const auto a = simulate(wrong);
  ASSERT_GE(a.wheel.size(), 17u);
  WheelRig mounted = *wrong.rig.wheel;
  mounted.T_I_B = mounted.T_I_B * errorTransform();
  for (const WheelReading& r : a.wheel) {
    const WheelReading e =
        idealWheelReading(wrong.trajectory->at(wrong.trajectoryTime(r.utime) + kOffset), mounted, r.utime);
    EXPECT_DOUBLE_EQ(r.left_speed, e.left_speed);
    EXPECT_DOUBLE_EQ(r.right_speed, e.right_speed);
  }
  const WheelReading nominal = idealWheelReading(wrong.trajectory->at(wrong.trajectoryTime(a.wheel.back().utime)),
                                                 *wrong.rig.wheel, a.wheel.back().utime);
  EXPECT_GT(std::abs(nominal.left_speed - a.wheel.back().left_speed), 1e-3);
}

// w_m = (I + S_g) M_g w + G f + k_g dT, f_m = (I + S_a) M_a f + k_a dT, written out per component.
TEST(ImuErrors, ReadingEqualsTheAnalyticModel) {
  ImuErrors e;
  e.gyro_scale_ppm = Vec3(1000, -2000, 3000);
  e.gyro_misalignment_mrad = Vec3(1, 2, 3);
  e.accel_scale_ppm = Vec3(-500, 700, 1500);
  e.accel_misalignment_mrad = Vec3(-4, 5, -6);
  e.gyro_g_sensitivity = Vec3(1e-4, -2e-4, 3e-4);
  BodyState s;
  s.T_W_I.linear() = so3::Exp(Vec3(0.2, -0.4, 1.1));
  s.acceleration = Vec3(1.0, -2.0, 0.5);
  s.angular_velocity = Vec3(0.3, -0.7, 1.9);
  ImuReading r = idealImuReading(s, 9.81, 0);
  const Vec3 w = r.angular_velocity, f = r.linear_acceleration;
  applyImuErrors(e, 0.0, &r);
  const Vec3 wm(1.001 * w.x() + 1e-4 * f.x(), 0.998 * (0.001 * w.x() + w.y()) - 2e-4 * f.y(),
                1.003 * (0.002 * w.x() + 0.003 * w.y() + w.z()) + 3e-4 * f.z());
  const Vec3 fm(0.9995 * f.x(), 1.0007 * (-0.004 * f.x() + f.y()), 1.0015 * (0.005 * f.x() - 0.006 * f.y() + f.z()));
  EXPECT_LT((r.angular_velocity - wm).norm(), 1e-14);
  EXPECT_LT((r.linear_acceleration - fm).norm(), 1e-13);
}

TEST(ImuErrors, TemperatureBiasFollowsTheRamp) {
  ImuErrors e;
  e.gyro_bias_per_c = Vec3(1e-4, -2e-4, 5e-5);
  e.accel_bias_per_c = Vec3(0.01, 0.0, -0.02);
  e.temperature = {20.0, 50.0, 300.0};
  for (const double t : {0.0, 75.0, 150.0, 299.0, 300.0, 1000.0}) {
    const double dT = 30.0 * std::min(t / 300.0, 1.0);
    EXPECT_DOUBLE_EQ(e.temperature.at(t), 20.0 + dT);
    ImuReading r;  // a still, level IMU would read (0, 0, 9.81); zero keeps only the bias
    applyImuErrors(e, t, &r);
    EXPECT_LT((r.angular_velocity - e.gyro_bias_per_c * dT).norm(), 1e-15) << t;
    EXPECT_LT((r.linear_acceleration - e.accel_bias_per_c * dT).norm(), 1e-15) << t;
  }
}

// The configured model reaches the published readings, before the (here zero) noise.
TEST(ImuErrors, SimulatorPublishesTheErroneousReadings) {
  const SimulationSetup s =
      load(movingRig(R"(  imu: {gyro_scale_ppm: [1000, -2000, 3000], gyro_misalignment_mrad: [1, 2, 3],
        accel_scale_ppm: [-500, 700, 1500], accel_misalignment_mrad: [-4, 5, -6], gyro_g_sensitivity: [1e-4, -2e-4, 3e-4],
        gyro_bias_per_c: [1e-4, 0, 0], accel_bias_per_c: [0, 0, 0.01], temperature: {start_c: 20, end_c: 40, ramp_s: 0.2}}
)"));
  const auto got = simulate(s);
  ASSERT_EQ(got.imu.size(), 71u);
  for (const ImuReading& r : got.imu) {
    const double t = (r.utime - s.start_utime) * 1e-6;
    const ImuReading ideal = idealImuReading(s.trajectory->at(s.trajectoryTime(r.utime)), 9.81, r.utime);
    const Vec3 w = ideal.angular_velocity, f = ideal.linear_acceleration;
    const double dT = 20.0 * std::min(t / 0.2, 1.0);
    const Vec3 wm(1.001 * w.x() + 1e-4 * f.x() + 1e-4 * dT, 0.998 * (0.001 * w.x() + w.y()) - 2e-4 * f.y(),
                  1.003 * (0.002 * w.x() + 0.003 * w.y() + w.z()) + 3e-4 * f.z());
    const Vec3 fm(0.9995 * f.x(), 1.0007 * (-0.004 * f.x() + f.y()),
                  1.0015 * (0.005 * f.x() - 0.006 * f.y() + f.z()) + 0.01 * dT);
    EXPECT_LT((r.angular_velocity - wm).norm(), 1e-12) << t;
    EXPECT_LT((r.linear_acceleration - fm).norm(), 1e-12) << t;
  }
}

// The IMU model applies to a recording only when its IMU is synthesised from the motion: with a
// replayed real IMU every sim.imu key is refused, without one they reach the readings.
TEST(ImuErrors, ApplyToARecordingOnlyWhenItsImuIsSynthesised) {
  const std::string euroc = std::string(LIVO_SHARED_DATA) + "/euroc_v1_01";
  const std::string replayed = test::noiseFreeImuRig() + "sim:\n" + test::boxRoomScene() +
                               "  trajectory: {type: recorded, ground_truth: " + euroc +
                               "/groundtruth.tum, imu: " + euroc + "/mav0/imu0/data.csv}\n";
  for (const std::string key : {"gyro_scale_ppm: [100, 0, 0]", "accel_misalignment_mrad: [1, 0, 0]",
                                "initial_gyro_bias: [0.01, 0, 0]", "temperature: {start_c: 20}"}) {
    SCOPED_TRACE(key);
    EXPECT_NE(configError(replayed + "  imu: {" + key + "}\n")
                  .find("a recorded trajectory publishes its real IMU samples unchanged"),
              std::string::npos);
  }

  const std::string synthesised =
      test::noiseFreeImuRig() + "sim:\n  duration_s: 0.3\n" + test::boxRoomScene() +
      "  trajectory: {type: recorded, ground_truth: " + std::string(LIVO_SHARED_DATA) +
      "/trajectories/fr2_desk_groundtruth.txt, smoothing_s: 0.1, start_offset_s: 60}\n"
      "  imu: {initial_gyro_bias: [0.01, -0.02, 0.03], initial_accel_bias: [0.1, 0.2, -0.3],\n"
      "        gyro_scale_ppm: [1000, -2000, 3000], accel_misalignment_mrad: [-4, 5, -6],\n"
      "        gyro_g_sensitivity: [1e-4, -2e-4, 3e-4]}\n";
  const SimulationSetup s = load(synthesised);
  ASSERT_FALSE(s.replaysRecordedImu());
  EXPECT_EQ(s.imu_errors.gyro_scale_ppm, Vec3(1000, -2000, 3000));
  const auto got = simulate(s);
  ASSERT_EQ(got.imu.size(), 61u);  // 0.3 s at 200 Hz
  for (const ImuReading& r : got.imu) {
    const ImuReading ideal = idealImuReading(s.trajectory->at(s.trajectoryTime(r.utime)), 9.81, r.utime);
    const Vec3 w = ideal.angular_velocity, f = ideal.linear_acceleration;
    const Vec3 wm(1.001 * w.x() + 1e-4 * f.x() + 0.01, 0.998 * w.y() - 2e-4 * f.y() - 0.02,
                  1.003 * w.z() + 3e-4 * f.z() + 0.03);
    const Vec3 fm(f.x() + 0.1, -0.004 * f.x() + f.y() + 0.2, 0.005 * f.x() - 0.006 * f.y() + f.z() - 0.3);
    EXPECT_LT((r.angular_velocity - wm).norm(), 1e-12);
    EXPECT_LT((r.linear_acceleration - fm).norm(), 1e-12);
    EXPECT_GT(f.norm(), 9.0);  // gravity in the specific force: a real reading, not zeros
  }
}

TEST(CalibrationErrors, DrawsDependOnTheSeedOnly) {
  const std::string yaml = movingRig(R"(  calibration_errors:
    draw: true
    lidar: {translation: [0.01, 0.01, 0.02], rpy_deg: [0.5, 0.5, 1.0]}
    camera_time_offset_s: 0.001
  imu: {gyro_scale_ppm: [30000, 30000, 30000]}
)");
  const SimulationSetup a = load(yaml, 1), b = load(yaml, 2), a2 = load(yaml, 1);
  EXPECT_NE(a.calibration_errors.lidar.translation, b.calibration_errors.lidar.translation);
  EXPECT_NE(a.calibration_errors.camera_time_offset_s, b.calibration_errors.camera_time_offset_s);
  EXPECT_NE(a.imu_errors.gyro_scale_ppm, b.imu_errors.gyro_scale_ppm);
  EXPECT_EQ(a.calibration_errors.lidar.translation, a2.calibration_errors.lidar.translation);
  EXPECT_EQ(a.calibration_errors.lidar.rpy_deg, a2.calibration_errors.lidar.rpy_deg);
  EXPECT_EQ(a.calibration_errors.camera_time_offset_s, a2.calibration_errors.camera_time_offset_s);
  EXPECT_EQ(a.imu_errors.gyro_scale_ppm, a2.imu_errors.gyro_scale_ppm);
  // unconfigured errors stay zero; the rig (the belief) is the nominal one whatever is drawn
  EXPECT_TRUE(a.calibration_errors.camera.isZero());
  EXPECT_EQ(a.calibration_errors.wheel_time_offset_s, 0.0);
  EXPECT_TRUE(a.rig.lidar->T_I_L.isApprox(b.rig.lidar->T_I_L, 0.0));
  EXPECT_EQ(a.rig.lidar->T_I_L.translation(), Vec3(0.1, 0.0, 0.2));
  // two seeds, two rigs: the clouds differ
  EXPECT_NE(simulate(a).sweeps.front().x, simulate(b).sweeps.front().x);
}

// Over N seeds each drawn component has mean 0 and std sigma: the sample mean's std is sigma/sqrt(N),
// the sample std's relative std 1/sqrt(2N) (1.1 % for N = 4000), a correlation's 1/sqrt(N); each is
// checked at 4 of those standard errors.
TEST(CalibrationErrors, DrawnErrorsHaveTheConfiguredSigmas) {
  CalibrationErrors sigma;
  sigma.lidar.translation = Vec3(0.01, 0.02, 0.005);
  sigma.lidar.rpy_deg = Vec3(0.5, 0.1, 1.0);
  sigma.camera_time_offset_s = 0.002;
  sigma.wheel_time_offset_s = 0.004;
  ImuErrors imu_sigma;
  imu_sigma.accel_scale_ppm = Vec3(3000, 3000, 3000);
  const int n = 4000;
  constexpr int kComponents = 11;
  const double sigmas[kComponents] = {0.01, 0.02, 0.005, 0.5, 0.1, 1.0, 0.002, 0.004, 3000, 3000, 3000};
  std::vector<std::array<double, kComponents>> draws(n);
  for (int k = 0; k < n; ++k) {
    const CalibrationErrors e = drawCalibrationErrors(sigma, static_cast<uint64_t>(k));
    const ImuErrors i = drawImuErrors(imu_sigma, static_cast<uint64_t>(k));
    draws[k] = {e.lidar.translation.x(), e.lidar.translation.y(), e.lidar.translation.z(), e.lidar.rpy_deg.x(),
                e.lidar.rpy_deg.y(),     e.lidar.rpy_deg.z(),     e.camera_time_offset_s,  e.wheel_time_offset_s,
                i.accel_scale_ppm.x(),   i.accel_scale_ppm.y(),   i.accel_scale_ppm.z()};
    EXPECT_EQ(e.lidar_time_offset_s, 0.0);
    EXPECT_TRUE(e.camera.isZero());
  }
  std::array<double, kComponents> mean{}, sd{};
  for (int c = 0; c < kComponents; ++c) {
    for (const auto& d : draws) mean[c] += d[c] / n;
    for (const auto& d : draws) sd[c] += (d[c] - mean[c]) * (d[c] - mean[c]) / (n - 1);
    sd[c] = std::sqrt(sd[c]);
    EXPECT_LT(std::abs(mean[c]), 4.0 * sigmas[c] / std::sqrt(n)) << "component " << c;
    EXPECT_NEAR(sd[c] / sigmas[c], 1.0, 4.0 / std::sqrt(2.0 * n)) << "component " << c;
  }
  for (int c = 0; c + 1 < kComponents; ++c) {
    double cov = 0.0;
    for (const auto& d : draws) cov += (d[c] - mean[c]) * (d[c + 1] - mean[c + 1]) / (n - 1);
    EXPECT_LT(std::abs(cov / (sd[c] * sd[c + 1])), 4.0 / std::sqrt(n)) << "components " << c << ", " << c + 1;
  }
}

TEST(CalibrationErrorsConfig, ErrorsNameTheFileAndKey) {
  EXPECT_EQ(configError(movingRig("  calibration_errors: {lidar: {translation: [0.01, 0, 0]}, draw: false}\n")), "");
  const auto expectError = [](const std::string& extra, const std::string& message) {
    const std::string got = configError(movingRig(extra));
    EXPECT_NE(got.find(message), std::string::npos) << "got: " << got << "\nwanted: " << message;
  };
  expectError("  calibration_errors: {lidar: {translaton: [0.01, 0, 0]}}\n",
              "calib.yaml: unknown key: sim.calibration_errors.lidar.translaton (did you mean "
              "sim.calibration_errors.lidar.translation?)");
  expectError("  calibration_errors: {drw: true}\n",
              "sim.calibration_errors.drw (did you mean sim.calibration_errors.draw?)");
  expectError("  calibration_errors: {camera: {translation: [0.01, 0]}}\n",
              "calib.yaml: sim.calibration_errors.camera.translation: expected a list of 3 numbers");
  expectError("  imu: {gyro_scale_ppm: 300}\n", "calib.yaml: sim.imu.gyro_scale_ppm: expected a list of 3 numbers");
  expectError("  calibration_errors: {wheel: {rpy_deg: [20, 0, 0]}}\n",
              "sim.calibration_errors.wheel.rpy_deg: components must be within +-10");
  expectError("  calibration_errors: {lidar_time_offset_s: 0.8}\n",
              "sim.calibration_errors.lidar_time_offset_s: must be within +-0.5");
  expectError("  calibration_errors: {draw: true, camera_time_offset_s: -0.001}\n",
              "sim.calibration_errors.camera_time_offset_s: a 1-sigma (calibration_errors.draw) must be >= 0");
  expectError("  calibration_errors: {draw: true}\n  imu: {accel_scale_ppm: [100, -100, 100]}\n",
              "sim.imu.accel_scale_ppm: a 1-sigma (calibration_errors.draw) must be >= 0");
  expectError("  imu: {temperature: {start_c: 20, ramp_s: 0}}\n", "sim.imu.temperature.ramp_s: must be > 0");
  expectError("  imu: {temperature: {start: 20}}\n",
              "sim.imu.temperature.start (did you mean sim.imu.temperature.start_c?)");

  const std::string imu_only = test::noiseFreeImuRig() + "sim:\n" + test::boxRoomScene() +
                               "  trajectory: {type: handheld, waypoints: [0,0,1, 2,0,1, 2,2,1]}\n";
  EXPECT_NE(configError(imu_only + "  calibration_errors: {camera: {translation: [0.01, 0, 0]}}\n")
                .find("sim.calibration_errors.camera: the rig has no camera"),
            std::string::npos);
  EXPECT_NE(configError(imu_only + "  calibration_errors: {wheel_time_offset_s: 0.01}\n")
                .find("sim.calibration_errors.wheel_time_offset_s: the rig has no wheel encoder"),
            std::string::npos);

  const std::string data = std::string(LIVO_SHARED_DATA) + "/euroc_v1_01";
  const std::string recorded = test::noiseFreeImuRig() + "sim:\n" + test::boxRoomScene() +
                               "  trajectory: {type: recorded, ground_truth: " + data +
                               "/groundtruth.tum, imu: " + data + "/mav0/imu0/data.csv}\n";
  EXPECT_EQ(configError(recorded + "  calibration_errors: {lidar_time_offset_s: 0.0}\n"),
            "calib.yaml: sim.calibration_errors.lidar_time_offset_s: the rig has no lidar");
  EXPECT_NE(
      configError(recorded + "  imu: {gyro_scale_ppm: [100, 0, 0]}\n")
          .find("calib.yaml: sim.imu.gyro_scale_ppm: a recorded trajectory publishes its real IMU samples unchanged"),
      std::string::npos);
}
