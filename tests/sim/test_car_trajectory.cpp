// The car trajectory is a car: the true rear axle rolls without slipping (its velocity in the car
// frame B is along B's x axis, up to the suspension shake), a point ahead of the axle moves
// sideways by yaw rate x lever arm in turns, and the wheel encoders read the axle's forward speed
// -/+ half the track width times the yaw rate.
#include <gtest/gtest.h>

#include <cmath>

#include "livo/sim/car_trajectory.hpp"
#include "livo/sim/simulation_setup.hpp"
#include "livo/sim/simulator.hpp"
#include "sim_test_support.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

const std::vector<Vec3> kBlock = {{0, 0, 1.8}, {60, 0, 1.8}, {60, 40, 1.8}, {0, 40, 1.8}};
constexpr double kSpeed = 8.0, kSpacing = 6.0;

/// A roof IMU 1.2 m ahead of and 1.5 m above the rear axle, mounted a little off (the truth).
Pose3 trueRearAxle() {
  Pose3 T = Pose3::Identity();
  T.linear() = so3::Exp(Vec3(0.01, -0.02, 0.03));
  T.translation() = Vec3(-1.2, 0.05, -1.5);
  return T;
}

CarTrajectory car(double shake, const Pose3& T_I_B) {
  CarTrajectoryOptions o;
  o.start_still_s = 0.5;
  o.shake = carShake(shake);
  o.T_I_B = T_I_B;
  return CarTrajectory(std::make_unique<BSplineLoopPath>(kBlock, kSpeed, kSpacing), o);
}

/// Velocity of the point p_B (in B) of the car frame at T_I_B, in B.
Vec3 velocityInB(const BodyState& s, const Pose3& T_I_B, const Vec3& p_B = Vec3::Zero()) {
  const Vec3 p_I = T_I_B * p_B;
  const Vec3 v_I = s.T_W_I.linear().transpose() * s.velocity + s.angular_velocity.cross(p_I);
  return T_I_B.linear().transpose() * v_I;
}

double yawRateOfB(const BodyState& s, const Pose3& T_I_B) {
  return (T_I_B.linear().transpose() * s.angular_velocity).z();
}

/// Sum over a shake's waves of amplitude and of amplitude x angular frequency (bounds of the
/// value and of its rate per unit path time).
void bounds(const std::vector<Sinusoid>& waves, double* value, double* rate) {
  *value = *rate = 0.0;
  for (const Sinusoid& w : waves) *value += w.amplitude, *rate += w.amplitude * 2.0 * M_PI * w.frequency_hz;
}

}  // namespace

TEST(CarTrajectory, RearAxleRollsWithoutSlipAlongThePath) {
  const Pose3 T_I_B = trueRearAxle();
  const CarTrajectory traj = car(0.0, T_I_B);
  const BSplineLoopPath path(kBlock, kSpeed, kSpacing);
  double max_yaw_rate = 0.0, min_forward = 1e9;
  for (double t = 3.0; t < 40.0; t += 0.05) {  // full speed (s = t - 1.5), two corners
    const BodyState s = traj.at(t);
    const Vec3 v = velocityInB(s, T_I_B);
    ASSERT_LT(std::abs(v.y()), 1e-9) << "t = " << t;
    ASSERT_LT(std::abs(v.z()), 1e-9) << "t = " << t;
    // the axle is on the path (lowered by the IMU's 1.5 m), heading along its tangent
    const Pose3 T_W_B = s.T_W_I * T_I_B;
    const PathSample p = path.at(t - 1.5);
    ASSERT_LT((T_W_B.translation() - p.p).head<2>().norm(), 1e-9) << "t = " << t;
    ASSERT_NEAR(T_W_B.translation().z(), 1.8 - T_I_B.inverse().translation().z(), 1e-9);
    ASSERT_LT((T_W_B.linear().col(0) - Vec3(p.d1.x(), p.d1.y(), 0).normalized()).norm(), 1e-9) << "t = " << t;
    max_yaw_rate = std::max(max_yaw_rate, std::abs(yawRateOfB(s, T_I_B)));
    min_forward = std::min(min_forward, v.x());
  }
  EXPECT_GT(max_yaw_rate, 0.3);  // it did turn
  EXPECT_GT(min_forward, 2.0);   // and drove forward throughout
}

TEST(CarTrajectory, PointAheadOfTheAxleMovesSidewaysByYawRateTimesLeverArm) {
  const Pose3 T_I_B = trueRearAxle();
  const CarTrajectory traj = car(0.0, T_I_B);
  const BSplineLoopPath path(kBlock, kSpeed, kSpacing);
  const Vec3 ahead(2.5, 0.0, 0.7);  // e.g. a bumper sensor
  double max_lateral = 0.0;
  for (double t = 3.0; t < 40.0; t += 0.05) {
    const BodyState s = traj.at(t);
    // yaw rate from the path alone: curvature x speed
    const PathSample p = path.at(t - 1.5);
    const double speed = p.d1.head<2>().norm();
    const double curvature = (p.d1.x() * p.d2.y() - p.d1.y() * p.d2.x()) / (speed * speed * speed);
    const Vec3 v = velocityInB(s, T_I_B, ahead);
    ASSERT_NEAR(v.x(), speed, 1e-9) << "t = " << t;
    ASSERT_NEAR(v.y(), curvature * speed * ahead.x(), 1e-9) << "t = " << t;
    ASSERT_NEAR(v.z(), 0.0, 1e-9) << "t = " << t;
    // the IMU itself, 1.2 m ahead of the axle, sees the same in its own frame
    const Vec3 v_imu_B = T_I_B.linear().transpose() * (s.T_W_I.linear().transpose() * s.velocity);
    ASSERT_NEAR(v_imu_B.y(), curvature * speed * T_I_B.inverse().translation().x(), 1e-9) << "t = " << t;
    max_lateral = std::max(max_lateral, std::abs(v.y()));
  }
  EXPECT_GT(max_lateral, 0.5);  // a lateral velocity a filter's lever-arm model must explain
}

TEST(CarTrajectory, ShakeBreaksTheConstraintOnlyWithinItsBound) {
  const Pose3 T_I_B = trueRearAxle();
  const CarTrajectory traj = car(1.0, T_I_B);
  const MotionShake m = carShake(1.0);
  double roll, pitch, yaw, z, unused, z_rate;
  bounds(m.attitude[0], &roll, &unused);
  bounds(m.attitude[1], &pitch, &unused);
  bounds(m.attitude[2], &yaw, &unused);
  bounds(m.position[2], &z, &z_rate);
  ASSERT_EQ(yaw, 0.0);
  ASSERT_TRUE(m.position[0].empty() && m.position[1].empty());
  // v_B = Rx(roll)^T Ry(pitch)^T (speed x + dz/dt z), path time runs at most as fast as time
  double max_vertical = 0.0;
  for (double t = 3.0; t < 40.0; t += 0.05) {
    const BodyState s = traj.at(t);
    const Vec3 v = velocityInB(s, T_I_B);
    const double speed = (std::abs(v.x()) + z_rate) / std::cos(pitch);  // >= the horizontal speed
    EXPECT_LE(std::abs(v.y()), speed * std::sin(roll) * std::sin(pitch) + z_rate * std::sin(roll)) << "t = " << t;
    EXPECT_LE(std::abs(v.z()), speed * std::sin(pitch) + z_rate) << "t = " << t;
    max_vertical = std::max(max_vertical, std::abs(v.z()));
  }
  EXPECT_GT(max_vertical, 0.05);  // the shake is there
}

TEST(CarTrajectory, WithoutLeverArmTheBodyFollowsTheHeading) {
  // no wheel encoder: B = I, the body origin on the path and yaw along its tangent
  const CarTrajectory traj = car(0.0, Pose3::Identity());
  const BSplineLoopPath path(kBlock, kSpeed, kSpacing);
  for (double t = 3.0; t < 40.0; t += 0.5) {
    const BodyState s = traj.at(t);
    const PathSample p = path.at(t - 1.5);
    EXPECT_LT((s.T_W_I.translation() - p.p).norm(), 1e-9);
    EXPECT_LT((s.velocity - p.d1).norm(), 1e-9);
    EXPECT_LT((s.T_W_I.linear().col(0) - p.d1.normalized()).norm(), 1e-9);
  }
}

TEST(CarTrajectory, WheelSpeedsAreAxleSpeedPlusMinusHalfTrackTimesYawRate) {
  // a mounting error on the wheel base: the readings follow the TRUE axle
  const std::string yaml = test::noiseFreeImuRig() + R"(
  wheel: {rate_hz: 50, track_width: 1.6, speed_noise_std: 0, T_I_B: {translation: [-1.2, 0, -1.5], rpy_deg: [0, 0, 0]}}
sim:
  duration_s: 30
  ground_truth_rate_hz: 50
  calibration_errors:
    wheel: {translation: [0.03, -0.02, 0.01], rpy_deg: [0.5, -0.4, 1.5]}
)" + test::boxRoomScene() + R"(
  trajectory:
    type: car
    waypoints: [0, 0, 1.8,  60, 0, 1.8,  60, 40, 1.8,  0, 40, 1.8]
    speed: 8
    control_spacing: 6
    start_still_s: 0.5
    shake: 0
)";
  const SimulationSetup setup = loadSimulation(Config::fromString(yaml, "car_wheel_test.yaml"), "");
  const Pose3 T_I_B = trueRig(setup.rig, setup.calibration_errors).wheel->T_I_B;
  ASSERT_GT((T_I_B.translation() - setup.rig.wheel->T_I_B.translation()).norm(), 0.01);
  test::CollectingSink sink;
  Simulator(setup).run(sink);
  ASSERT_GT(sink.wheel.size(), 1400u);
  // the axle's forward speed and yaw rate from finite differences of its true pose
  const double h = 1e-4;
  double max_difference = 0.0;
  for (size_t k = 0; k < sink.wheel.size(); k += 7) {
    const double t = setup.trajectoryTime(sink.wheel[k].utime);
    if (t < 1.0) continue;
    const Pose3 a = setup.trajectory->at(t - h).T_W_I * T_I_B, b = setup.trajectory->at(t + h).T_W_I * T_I_B;
    const Pose3 c = setup.trajectory->at(t).T_W_I * T_I_B;
    const double forward = c.linear().col(0).dot(b.translation() - a.translation()) / (2 * h);
    const double yaw_rate = so3::Log(Mat3(a.linear().transpose() * b.linear())).z() / (2 * h);
    EXPECT_NEAR(sink.wheel[k].left_speed, forward - 0.8 * yaw_rate, 1e-6) << "t = " << t;
    EXPECT_NEAR(sink.wheel[k].right_speed, forward + 0.8 * yaw_rate, 1e-6) << "t = " << t;
    max_difference = std::max(max_difference, std::abs(sink.wheel[k].right_speed - sink.wheel[k].left_speed));
  }
  EXPECT_GT(max_difference, 0.5);  // it turned
}
