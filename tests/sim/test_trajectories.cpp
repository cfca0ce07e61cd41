// Trajectories: exact derivatives (against finite differences), the recorded-motion spline (through
// its samples), and the key property of the IMU stream: integrating the noise-free IMU samples of
// the simulator reproduces the ground-truth trajectory.
#include <gtest/gtest.h>

#include "livo/sim/car_trajectory.hpp"
#include "livo/sim/paths.hpp"
#include "livo/sim/procedural_trajectory.hpp"
#include "livo/sim/recorded_trajectory.hpp"
#include "livo/sim/simulation_setup.hpp"
#include "livo/sim/simulator.hpp"
#include "livo/trajectory_io.hpp"
#include "sim_test_support.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

std::unique_ptr<BodyTrajectory> handheld() {
  ProceduralTrajectoryOptions o;
  o.shake = handheldShake(1.0);
  std::vector<Vec3> w = {{-2, -2, 1.5}, {2, -2, 1.5}, {2.5, 1, 1.6}, {-2, 2.5, 1.4}};
  return std::make_unique<ProceduralTrajectory>(std::make_unique<BSplineLoopPath>(w, 1.2, 0.8), o);
}
std::unique_ptr<BodyTrajectory> flight() {
  ProceduralTrajectoryOptions o;
  o.attitude = AttitudeMode::kThrustAligned;
  o.shake = flightShake(1.0);
  o.yaw_rate = 0.5;
  o.yaw_wave = {0.4, 0.2, 0.0};
  return std::make_unique<ProceduralTrajectory>(
      std::make_unique<LissajousPath>(Vec3(0, 0, 1.5), Vec3(1.5, 1.2, 0.4), Vec3(0.31, 0.42, 0.53), Vec3(0, 0.5, 1.0)),
      o);
}

/// A car with a roof IMU 1.2 m ahead of and 1.5 m above the rear axle, mounted a little tilted.
std::unique_ptr<BodyTrajectory> car() {
  CarTrajectoryOptions o;
  o.shake = carShake(1.0);
  o.T_I_B.linear() = so3::Exp(Vec3(0.01, -0.02, 0.03));
  o.T_I_B.translation() = Vec3(-1.2, 0.05, -1.5);
  std::vector<Vec3> w = {{0, 0, 1.8}, {60, 0, 1.8}, {60, 40, 1.8}, {0, 40, 1.8}};
  return std::make_unique<CarTrajectory>(std::make_unique<BSplineLoopPath>(w, 8.0, 6.0), o);
}

void expectDerivativesConsistent(const BodyTrajectory& traj) {
  const double h = 1e-5;
  for (double t = 0.5; t < 20.0; t += 0.37) {
    const BodyState a = traj.at(t - h), b = traj.at(t), c = traj.at(t + h);
    const Vec3 v_fd = (c.T_W_I.translation() - a.T_W_I.translation()) / (2 * h);
    const Vec3 a_fd = (c.velocity - a.velocity) / (2 * h);
    const Vec3 w_fd = (so3::Log(Mat3(b.T_W_I.linear().transpose() * c.T_W_I.linear())) -
                       so3::Log(Mat3(b.T_W_I.linear().transpose() * a.T_W_I.linear()))) /
                      (2 * h);
    ASSERT_LT((v_fd - b.velocity).norm(), 1e-6 * (1 + b.velocity.norm())) << "t = " << t;
    ASSERT_LT((a_fd - b.acceleration).norm(), 1e-5 * (1 + b.acceleration.norm())) << "t = " << t;
    ASSERT_LT((w_fd - b.angular_velocity).norm(), 1e-6 * (1 + b.angular_velocity.norm())) << "t = " << t;
  }
}

/// RK4 on (q, v, p) with IMU values between samples from cubic (4-point Lagrange) interpolation.
struct ImuIntegrator {
  const std::vector<ImuReading>& imu;
  double gravity;
  using State = Eigen::Matrix<double, 10, 1>;  // q (w x y z), v, p

  Eigen::Matrix<double, 6, 1> sampleAt(size_t k, double a) const {  // between samples k and k+1
    auto val = [&](size_t i) {
      i = std::min(i, imu.size() - 1);
      Eigen::Matrix<double, 6, 1> x;
      x << imu[i].angular_velocity, imu[i].linear_acceleration;
      return x;
    };
    if (k == 0 || k + 2 >= imu.size()) return (1 - a) * val(k) + a * val(k + 1);
    // Lagrange on nodes -1, 0, 1, 2
    const double l0 = -a * (a - 1) * (a - 2) / 6, l1 = (a + 1) * (a - 1) * (a - 2) / 2, l2 = -(a + 1) * a * (a - 2) / 2,
                 l3 = (a + 1) * a * (a - 1) / 6;
    return l0 * val(k - 1) + l1 * val(k) + l2 * val(k + 1) + l3 * val(k + 2);
  }
  State derivative(const State& x, const Eigen::Matrix<double, 6, 1>& m) const {
    const Quat q(x[0], x[1], x[2], x[3]);
    const Quat w(0, m[0], m[1], m[2]);
    const Quat dq = q * w;
    State d;
    d << 0.5 * dq.w(), 0.5 * dq.x(), 0.5 * dq.y(), 0.5 * dq.z(),
        q.normalized().toRotationMatrix() * m.tail<3>() - Vec3(0, 0, gravity), x.segment<3>(4);
    return d;
  }
  State integrate(State x, size_t steps) const {
    for (size_t k = 0; k < steps; ++k) {
      const double dt = (imu[k + 1].utime - imu[k].utime) * 1e-6;
      const auto m0 = sampleAt(k, 0.0), mh = sampleAt(k, 0.5), m1 = sampleAt(k, 1.0);
      const State k1 = derivative(x, m0), k2 = derivative(x + 0.5 * dt * k1, mh),
                  k3 = derivative(x + 0.5 * dt * k2, mh), k4 = derivative(x + dt * k3, m1);
      x += dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
      x.head<4>().normalize();
    }
    return x;
  }
};

void expectImuIntegratesToGroundTruth(const std::string& trajectory_yaml, const std::string& rig_extra = "") {
  const std::string yaml = test::noiseFreeImuRig() + rig_extra +
                           "sim:\n  duration_s: 10.5\n  ground_truth_rate_hz: 50\n" + test::boxRoomScene() +
                           "  trajectory:\n" + trajectory_yaml;
  const SimulationSetup setup = loadSimulation(Config::fromString(yaml, "imu_test.yaml"), "");
  test::CollectingSink sink;
  Simulator(setup).run(sink);
  ASSERT_EQ(sink.imu.size(), 2101u);
  ASSERT_EQ(sink.imu.front().utime, setup.start_utime);
  const BodyState s0 = setup.trajectory->at(setup.trajectoryTime(setup.start_utime));
  ImuIntegrator integ{sink.imu, 9.81};
  ImuIntegrator::State x;
  const Quat q0(s0.T_W_I.linear());
  x << q0.w(), q0.x(), q0.y(), q0.z(), s0.velocity, s0.T_W_I.translation();
  const size_t steps = 2000;  // 10 s at 200 Hz
  const ImuIntegrator::State xe = integ.integrate(x, steps);
  // ground truth at 10 s from the log (50 Hz: pose 500)
  const PoseReading& gt = sink.poses.at(500);
  ASSERT_EQ(gt.utime, sink.imu[steps].utime);
  const double pos_err = (xe.tail<3>() - gt.T_W_I.translation()).norm();
  const double rot_err =
      so3::Log(Mat3(gt.T_W_I.linear().transpose() * Quat(xe[0], xe[1], xe[2], xe[3]).toRotationMatrix())).norm();
  const double travelled = (gt.T_W_I.translation() - s0.T_W_I.translation()).norm();
  EXPECT_LT(pos_err, 1e-3) << "after 10 s (moved " << travelled << " m)";
  EXPECT_LT(rot_err, 1e-5);
  EXPECT_GT(travelled, 0.5);  // it did move
}

}  // namespace

TEST(BodyTrajectory, HandheldDerivativesAreExact) { expectDerivativesConsistent(*handheld()); }
TEST(BodyTrajectory, FlightDerivativesAreExact) { expectDerivativesConsistent(*flight()); }
TEST(BodyTrajectory, CarDerivativesAreExact) { expectDerivativesConsistent(*car()); }

TEST(BodyTrajectory, StillStartThenMoving) {
  const auto t = handheld();
  const BodyState a = t->at(0.0), b = t->at(1.9);
  EXPECT_EQ(a.velocity.norm(), 0.0);
  EXPECT_EQ(a.angular_velocity.norm(), 0.0);
  EXPECT_LT((a.T_W_I.translation() - b.T_W_I.translation()).norm(), 1e-15);
  EXPECT_GT(t->at(6.0).velocity.norm(), 0.5);
}

TEST(BodyTrajectory, FlightBodyZAlongThrust) {
  const auto t = flight();
  for (double s = 3.0; s < 20.0; s += 1.1) {
    const BodyState b = t->at(s);
    const Vec3 thrust = (b.acceleration + Vec3(0, 0, 9.81)).normalized();
    EXPECT_NEAR(thrust.dot(b.T_W_I.linear().col(2)), 1.0, 1e-4);  // shake tilts by < 0.5 deg
  }
}

TEST(BodyTrajectory, BSplineLoopIsClosedAndNearItsPolygon) {
  std::vector<Vec3> square = {{0, 0, 0}, {20, 0, 0}, {20, 20, 0}, {0, 20, 0}};
  BSplineLoopPath path(square, 2.0, 1.0);
  EXPECT_NEAR(path.period(), 40.0, 1e-9);  // 80 control points, 0.5 s apart
  const PathSample a = path.at(3.0), b = path.at(3.0 + path.period());
  EXPECT_LT((a.p - b.p).norm(), 1e-9);
  EXPECT_LT((a.d3 - b.d3).norm(), 1e-9);
  // mid-edge the path runs on the edge at the nominal speed
  const PathSample mid = path.at(5.0);
  EXPECT_NEAR(mid.p.y(), 0.0, 1e-9);
  EXPECT_NEAR(mid.d1.norm(), 2.0, 1e-9);
}

TEST(RecordedTrajectory, PassesThroughTheRecordedPoses) {
  const livo::Trajectory gt = livo::readTrajectory(std::string(LIVO_SHARED_DATA) + "/euroc_v1_01/groundtruth.tum");
  RecordedTrajectory rec(gt);
  EXPECT_NEAR(rec.duration(), gt.back().stamp - gt.front().stamp, 1e-9);
  for (size_t i = 0; i < gt.size(); i += 97) {
    const BodyState s = rec.at(gt[i].stamp - gt.front().stamp);
    EXPECT_LT((s.T_W_I.translation() - gt[i].pose.translation()).norm(), 1e-9);
    EXPECT_LT(so3::Log(Mat3(s.T_W_I.linear().transpose() * gt[i].pose.linear())).norm(), 1e-9);
  }
  // smooth: between samples the pose stays within a few mm / mrad of the linear interpolation
  for (size_t i = 100; i + 1 < gt.size(); i += 211) {
    const double tm = 0.5 * (gt[i].stamp + gt[i + 1].stamp) - gt.front().stamp;
    const Pose3 lin = se3::interpolate(gt[i].pose, gt[i + 1].pose, 0.5);
    const BodyState s = rec.at(tm);
    EXPECT_LT((s.T_W_I.translation() - lin.translation()).norm(), 0.01);
    EXPECT_LT(so3::Log(Mat3(s.T_W_I.linear().transpose() * lin.linear())).norm(), 0.01);
  }
}

TEST(ImuIntegration, HandheldWalkReproducesGroundTruth) {
  expectImuIntegratesToGroundTruth(R"(
    type: handheld
    waypoints: [-2, -2, 1.5,  2, -2, 1.5,  2.5, 1, 1.6,  -2, 2.5, 1.4]
    speed: 1.2
    control_spacing: 0.8
    start_still_s: 1.0
    ramp_s: 1.5
)");
}

TEST(ImuIntegration, AggressiveFlightReproducesGroundTruth) {
  expectImuIntegratesToGroundTruth(R"(
    type: uav
    center: [0, 0, 1.5]
    amplitude: [2.0, 1.5, 0.5]
    frequency_hz: [0.3, 0.4, 0.5]
    yaw_rate_deg: 40
    yaw_amplitude_deg: 30
    start_still_s: 0.5
    ramp_s: 1.5
)");
}

/// A car driving a 60 x 40 m loop at 8 m/s, as YAML under sim.trajectory.
const char* const kCarLoop = R"(
    type: car
    waypoints: [0, 0, 1.8,  60, 0, 1.8,  60, 40, 1.8,  0, 40, 1.8]
    speed: 8
    control_spacing: 6
    start_still_s: 0.5
    ramp_s: 2.0
)";

TEST(ImuIntegration, CarLoopReproducesGroundTruth) { expectImuIntegratesToGroundTruth(kCarLoop); }

TEST(ImuIntegration, CarWithRearAxleBehindTheImuReproducesGroundTruth) {
  expectImuIntegratesToGroundTruth(kCarLoop,
                                   "  wheel: {rate_hz: 50, track_width: 1.6, speed_noise_std: 0, T_I_B: {translation: "
                                   "[-1.2, 0.1, -1.5], rpy_deg: [1, -2, 3]}}\n");
}

// A recording without IMU: the IMU is synthesised from the smoothed, placed motion (with the lever
// arm of a body 8 cm behind the recorded camera), exactly as for the procedural trajectories.
TEST(ImuIntegration, RecordedMotionWithoutImuReproducesGroundTruth) {
  expectImuIntegratesToGroundTruth("    type: recorded\n    ground_truth: " + std::string(LIVO_SHARED_DATA) +
                                   "/trajectories/fr2_desk_groundtruth.txt\n"
                                   "    smoothing_s: 0.1\n"
                                   "    start_offset_s: 50\n"
                                   "    placement: {translation: [-1.31, 1.14, 0.0], rpy_deg: [0, 0, 30]}\n"
                                   "    body_in_recorded: {translation: [0.0, 0.02, -0.08], rpy_deg: [0, -90, 90]}\n");
}
