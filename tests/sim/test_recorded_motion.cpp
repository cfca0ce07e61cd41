// Recorded motion: the least-squares B-spline that smooths jittery poses (against a known motion
// sampled with motion-capture-like noise), its handling of dropouts and repeated stamps, the
// placement and body frame of a recording, the start offset, and the shipped fr2/desk configs.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "livo/sim/paths.hpp"
#include "livo/sim/procedural_trajectory.hpp"
#include "livo/sim/random.hpp"
#include "livo/sim/recorded_trajectory.hpp"
#include "livo/sim/sample_curves.hpp"
#include "livo/sim/simulation_setup.hpp"
#include "livo/trajectory_io.hpp"
#include "sim_test_support.hpp"

using namespace livo;
using namespace livo::sim;

namespace {

const std::string kFr2Desk = std::string(LIVO_SHARED_DATA) + "/trajectories/fr2_desk_groundtruth.txt";

std::string configPath(const std::string& name) {
  return std::string(LIVO_SOURCE_DIR) + "/config/sim/" + name + ".yaml";
}

/// A handheld walk (1 m/s, corners, step bobbing and wrist shake at half the built-in amplitude).
ProceduralTrajectory handheldWalk() {
  ProceduralTrajectoryOptions o;
  o.shake = handheldShake(0.5);
  o.start_still_s = 0.0;
  o.ramp_s = 0.0;
  const std::vector<Vec3> w = {{-2, -2, 1.5}, {2, -2, 1.5}, {2.5, 1, 1.6}, {-2, 2.5, 1.4}};
  return ProceduralTrajectory(std::make_unique<BSplineLoopPath>(w, 1.0, 0.8), o);
}

/// `truth` sampled at 100 Hz for 20 s, each pose disturbed by 1 mm (per axis) and 0.1 deg (per
/// axis) of white noise, as a motion-capture system records it.
livo::Trajectory jitteryRecording(const BodyTrajectory& truth) {
  Random rng(7, 1);
  livo::Trajectory rec;
  for (int k = 0; k <= 2000; ++k) {
    const double t = 0.01 * k;
    Pose3 T = truth.at(t).T_W_I;
    T.translation() += 1e-3 * rng.normal3();
    T.linear() = T.linear() * so3::Exp(Vec3(0.1 * M_PI / 180.0 * rng.normal3()));
    rec.push_back({t, T});
  }
  return rec;
}

struct MotionErrors {
  double acceleration_rms = 0.0, angular_velocity_rms = 0.0, position_rms = 0.0;
};

/// RMS differences at 200 Hz over [1, 19] s (the fit's ends excluded).
MotionErrors compare(const BodyTrajectory& estimate, const BodyTrajectory& truth) {
  MotionErrors e;
  int n = 0;
  for (double t = 1.0; t < 19.0; t += 0.005, ++n) {
    const BodyState a = estimate.at(t), b = truth.at(t);
    e.acceleration_rms += (a.acceleration - b.acceleration).squaredNorm();
    e.angular_velocity_rms += (a.angular_velocity - b.angular_velocity).squaredNorm();
    e.position_rms += (a.T_W_I.translation() - b.T_W_I.translation()).squaredNorm();
  }
  e.acceleration_rms = std::sqrt(e.acceleration_rms / n);
  e.angular_velocity_rms = std::sqrt(e.angular_velocity_rms / n);
  e.position_rms = std::sqrt(e.position_rms / n);
  return e;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p / 100.0 * static_cast<double>(v.size())))];
}

}  // namespace

// Interpolating 100 Hz poses with 1 mm of jitter differentiates the jitter twice (tens of m/s^2 of
// false acceleration); the 0.1 s least-squares B-spline recovers the true acceleration to within a
// fraction of the walk's own (1.4 m/s^2 RMS).
TEST(SmoothingCubicBSpline, RecoversTheMotionOfAJitteryRecording) {
  const ProceduralTrajectory truth = handheldWalk();
  const livo::Trajectory rec = jitteryRecording(truth);
  RecordedMotionOptions smoothing;
  smoothing.smoothing_s = 0.1;
  const MotionErrors smoothed = compare(RecordedTrajectory(rec, smoothing), truth);
  const MotionErrors interpolated = compare(RecordedTrajectory(rec), truth);
  EXPECT_LT(smoothed.acceleration_rms, 0.5);          // measured 0.41 m/s^2
  EXPECT_LT(smoothed.angular_velocity_rms, 0.03);     // 0.018 rad/s
  EXPECT_LT(smoothed.position_rms, 1e-3);             // 0.6 mm: below the jitter (1.7 mm RMS)
  EXPECT_GT(interpolated.acceleration_rms, 20.0);     // 78 m/s^2
  EXPECT_GT(interpolated.angular_velocity_rms, 0.2);  // 0.46 rad/s
}

// Knot intervals without samples (a motion-capture dropout) are bridged in a straight line: a
// straight-line motion sampled with a 1.5 s hole is reproduced exactly, hole included.
TEST(SmoothingCubicBSpline, BridgesADropoutInAStraightLine) {
  const SampledCurve::Value start = (SampledCurve::Value() << 1, 2, 3, 1, 0, 0, 0).finished();
  const SampledCurve::Value velocity = (SampledCurve::Value() << 0.5, -0.2, 0.1, 0, 0.01, 0, 0).finished();
  std::vector<double> times;
  std::vector<SampledCurve::Value> values;
  for (int k = 0; k <= 600; ++k) {
    const double t = k / 100.0;
    if (t > 2.0 && t < 3.5) continue;
    times.push_back(t);
    values.push_back(start + t * velocity);
  }
  const SmoothingCubicBSpline fit(times, values, 0.05);
  EXPECT_EQ(fit.intervals(), 120);
  EXPECT_NEAR(fit.knotSpacing(), 0.05, 1e-12);
  SampledCurve::Value y, dy, ddy;
  for (double t = 0.0; t <= 6.0; t += 0.0137) {
    fit.eval(t, &y, &dy, &ddy);
    ASSERT_LT((y - (start + t * velocity)).norm(), 1e-9) << "t = " << t;
    ASSERT_LT((dy - velocity).norm(), 1e-8) << "t = " << t;
    ASSERT_LT(ddy.norm(), 1e-6) << "t = " << t;
  }
}

// The fr2/desk file repeats a stamp (pose 10859): interpolation refuses it, the fit takes it.
TEST(RecordedTrajectory, RepeatedStampsNeedSmoothing) {
  const std::string rig = test::noiseFreeImuRig() + "sim:\n" + test::boxRoomScene();
  const std::string trajectory = "  trajectory: {type: recorded, ground_truth: " + kFr2Desk;
  try {
    loadSimulation(Config::fromString(rig + trajectory + "}\n", "fr2.yaml"), "");
    ADD_FAILURE() << "interpolating through a repeated stamp was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(
        std::string(e.what()).find("stamps do not increase at pose 10859 (smoothing_s > 0 accepts repeated stamps)"),
        std::string::npos)
        << e.what();
  }
  const SimulationSetup s =
      loadSimulation(Config::fromString(rig + trajectory + ", smoothing_s: 0.1}\n", "fr2.yaml"), "");
  EXPECT_TRUE(s.recorded);
  EXPECT_FALSE(s.replaysRecordedImu());
  EXPECT_NEAR(s.options.duration_s, 99.3645, 1e-4);  // no duration_s: the whole recording
}

// T_W_I = placement * T_recorded * body_in_recorded at every recorded pose (interpolation passes
// through them), with the derivatives of the placed motion (finite differences).
TEST(RecordedTrajectory, PlacementAndBodyFrameAreAppliedAsDocumented) {
  livo::Trajectory rec;
  for (int k = 0; k < 200; ++k) {
    const double t = 100.0 + 0.02 * k;
    Pose3 T = Pose3::Identity();
    T.linear() = so3::Exp(Vec3(0.3 * std::sin(t), 0.2 * std::cos(0.7 * t), 0.5 * t));
    T.translation() = Vec3(std::cos(0.4 * t), std::sin(0.3 * t), 1.5 + 0.1 * std::sin(t));
    rec.push_back({t, T});
  }
  RecordedMotionOptions o;
  o.placement.linear() = so3::Exp(Vec3(0, 0, 0.7));
  o.placement.translation() = Vec3(-1.31, 1.14, 0.2);
  o.body_in_recorded.linear() =
      (Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ()) * Eigen::AngleAxisd(-M_PI / 2, Vec3::UnitY())).toRotationMatrix();
  o.body_in_recorded.translation() = Vec3(0.0, 0.02, -0.08);
  const RecordedTrajectory placed(rec, o);
  EXPECT_DOUBLE_EQ(placed.startStamp(), 100.0);
  for (size_t k = 0; k < rec.size(); k += 17) {
    const Pose3 expected = o.placement * rec[k].pose * o.body_in_recorded;
    const BodyState s = placed.at(rec[k].stamp - 100.0);
    EXPECT_LT((s.T_W_I.translation() - expected.translation()).norm(), 1e-9);
    EXPECT_LT(so3::Log(Mat3(s.T_W_I.linear().transpose() * expected.linear())).norm(), 1e-9);
    // rpy [0, -90, 90]: body x is the recorded z (a camera's optical axis), body z is -y (up)
    const Mat3 R_W_R = o.placement.linear() * rec[k].pose.linear();
    EXPECT_NEAR(s.T_W_I.linear().col(0).dot(R_W_R.col(2)), 1.0, 1e-9);
    EXPECT_NEAR(s.T_W_I.linear().col(2).dot(-R_W_R.col(1)), 1.0, 1e-9);
  }
  const double h = 1e-5, t = 1.234;
  const BodyState a = placed.at(t - h), b = placed.at(t), c = placed.at(t + h);
  EXPECT_LT(((c.T_W_I.translation() - a.T_W_I.translation()) / (2 * h) - b.velocity).norm(), 1e-6);
  EXPECT_LT(((c.velocity - a.velocity) / (2 * h) - b.acceleration).norm(), 1e-5);
  const Vec3 w_fd = (so3::Log(Mat3(b.T_W_I.linear().transpose() * c.T_W_I.linear())) -
                     so3::Log(Mat3(b.T_W_I.linear().transpose() * a.T_W_I.linear()))) /
                    (2 * h);
  EXPECT_LT((w_fd - b.angular_velocity).norm(), 1e-6);
}

// start_offset_s moves the start into the recording; the default duration is what is left.
TEST(RecordedTrajectory, StartOffsetPicksAWindow) {
  const std::string yaml = test::noiseFreeImuRig() + "sim:\n" + test::boxRoomScene() +
                           "  trajectory: {type: recorded, ground_truth: " + kFr2Desk +
                           ", smoothing_s: 0.1, start_offset_s: ";
  const SimulationSetup s = loadSimulation(Config::fromString(yaml + "47}\n", "fr2.yaml"), "");
  const double first_stamp = 1311868163.8697;
  EXPECT_EQ(s.start_utime, static_cast<int64_t>(std::ceil((first_stamp + 47.0) * 1e6)));
  EXPECT_NEAR(s.trajectoryTime(s.start_utime), 47.0, 1e-6);
  EXPECT_NEAR(s.options.duration_s, 99.3645 - 47.0, 2e-6);
  try {
    loadSimulation(Config::fromString(yaml + "100}\n", "fr2.yaml"), "");
    ADD_FAILURE() << "a start after the end was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "fr2.yaml: sim.trajectory.start_offset_s: starts at or after the end of the recording"),
              std::string::npos)
        << e.what();
  }
}

// The shipped config: the rig's camera is the recorded camera (placed), the synthesised specific
// force is a handheld one, and the body stays in the room's free middle.
TEST(RecordedTrajectory, Fr2DeskConfigPutsTheRigCameraOnTheRecordedCamera) {
  const SimulationSetup s = loadSimulation(configPath("room_fr2_desk"));
  ASSERT_TRUE(s.recorded);
  ASSERT_FALSE(s.replaysRecordedImu());
  EXPECT_NEAR(s.options.duration_s, 52.0, 1e-9);
  const livo::Trajectory rec = readTrajectory(kFr2Desk);
  Pose3 placement = Pose3::Identity();
  placement.translation() = Vec3(-1.31, 1.14, 0.0);
  std::vector<double> position_error, angle_error, specific_force_less_gravity;
  Vec3 lo = Vec3::Constant(1e9), hi = -lo;
  for (const StampedPose& p : rec) {
    const double t = p.stamp - rec.front().stamp;
    if (t < 47.0) continue;
    const BodyState b = s.trajectory->at(t);
    const Pose3 T_W_C = b.T_W_I * s.rig.camera->T_I_C;  // the rig's camera
    const Pose3 recorded = placement * p.pose;          // the recorded camera, placed
    position_error.push_back((T_W_C.translation() - recorded.translation()).norm());
    angle_error.push_back(so3::Log(Mat3(T_W_C.linear().transpose() * recorded.linear())).norm());
    lo = lo.cwiseMin(b.T_W_I.translation()), hi = hi.cwiseMax(b.T_W_I.translation());
  }
  for (double t = 47.0; t < 99.3; t += 0.005)
    specific_force_less_gravity.push_back(
        (specificForce(s.trajectory->at(t), 9.81) - s.trajectory->at(t).T_W_I.linear().transpose() * Vec3(0, 0, 9.81))
            .norm());
  // within the smoothing's residual of the mocap poses (0.36 mm, 0.16 deg RMS measured)
  EXPECT_LT(percentile(position_error, 50), 1e-3);
  EXPECT_LT(percentile(position_error, 100), 5e-3);
  EXPECT_LT(percentile(angle_error, 50), 0.3 * M_PI / 180.0);
  // handheld: |f - g| 0.29 m/s^2 median, 0.79 at the 99th percentile, 1.4 at most
  EXPECT_LT(percentile(specific_force_less_gravity, 50), 0.5);
  EXPECT_LT(percentile(specific_force_less_gravity, 99), 1.5);
  EXPECT_LT(percentile(specific_force_less_gravity, 100), 2.5);
  // inside the free middle of scenes/room.yaml (|x| < 2.5, -2.6 < y < 3.6, above 0.8 m)
  EXPECT_GT(lo.x(), -2.5);
  EXPECT_LT(hi.x(), 2.5);
  EXPECT_GT(lo.y(), -2.6);
  EXPECT_LT(hi.y(), 3.6);
  EXPECT_GT(lo.z(), 1.0);
}
