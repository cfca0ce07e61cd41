// Shared pieces of the simulator tests: fixed and constant-velocity trajectories, a sink that
// keeps what it is given, camera effects that leave a render as it is, and a minimal config.
#pragma once

#include <string>
#include <vector>

#include "livo/sim/camera_renderer.hpp"
#include "livo/sim/sensor_data.hpp"
#include "livo/sim/trajectory.hpp"

namespace livo {
namespace sim {
namespace test {

/// Moves with constant velocity and constant body rate from pose T0.
class ConstantMotion : public BodyTrajectory {
 public:
  explicit ConstantMotion(const Pose3& T0, const Vec3& velocity = Vec3::Zero(), const Vec3& omega = Vec3::Zero())
      : T0_(T0), v_(velocity), w_(omega) {}
  BodyState at(double t) const override {
    BodyState s;
    s.T_W_I.linear() = T0_.linear() * so3::Exp(w_ * t);
    s.T_W_I.translation() = T0_.translation() + v_ * t;
    s.velocity = v_;
    s.angular_velocity = w_;
    return s;
  }

 private:
  Pose3 T0_;
  Vec3 v_, w_;
};

class CollectingSink : public SensorDataSink {
 public:
  void write(const ImuReading& m) override { imu.push_back(m), order.push_back(m.utime); }
  void write(const PoseReading& m) override { poses.push_back(m), order.push_back(m.utime); }
  void write(const WheelReading& m) override { wheel.push_back(m), order.push_back(m.utime); }
  void write(const LidarSweep& m) override { sweeps.push_back(m), order.push_back(m.utime); }
  void write(const CameraImage& m) override { images.push_back(m), order.push_back(m.utime); }
  std::vector<ImuReading> imu;
  std::vector<PoseReading> poses;
  std::vector<WheelReading> wheel;
  std::vector<LidarSweep> sweeps;
  std::vector<CameraImage> images;
  std::vector<int64_t> order;  // stamps in the order written
};

/// No exposure variation, no noise, no vignetting: the render as the scene and its lighting make it.
inline CameraEffects plainEffects() {
  CameraEffects e;
  e.exposure_variation = 0.0;
  e.noise_std = 0.0;
  e.vignetting = 0.0;
  return e;
}

/// A rig with a noise-free 200 Hz IMU only, and a sim section placeholder `SIM` to fill in.
inline std::string noiseFreeImuRig() {
  return R"(
rig:
  imu: {rate_hz: 200, gyro_noise_density: 0, gyro_random_walk: 0, accel_noise_density: 0, accel_random_walk: 0, gravity: 9.81}
)";
}

/// A one-box scene (a 10 x 8 x 4 m room seen from inside), as YAML under sim.scene.
inline std::string boxRoomScene() {
  return R"(
  scene:
    textures:
      grey: {pattern: noise, scale: 0.5, color: [0.8, 0.8, 0.8]}
    objects:
      room: {type: box, center: [0, 0, 2], size: [10, 8, 4], texture: grey, reflectivity: 0.5}
)";
}

}  // namespace test
}  // namespace sim
}  // namespace livo
