// Poses from LCM logs: default and named channels, pose_t and odometry_t, and clear errors.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "lcm_log_writer.hpp"
#include "livo/evaluate/evaluation.hpp"
#include "livo/evaluate/pose_log.hpp"
#include "livo/imu_t.hpp"
#include "livo/messages.hpp"
#include "livo/odometry_t.hpp"
#include "livo/pose_t.hpp"
#include "synthetic_trajectory.hpp"
#include "temp_path.hpp"

using namespace livo;
using namespace livo::evaluate;

namespace {

pose_t poseMessage(int64_t utime, const Pose3& T) {
  pose_t m{};
  m.utime = utime;
  m.parent_frame = "W";
  m.child_frame = "I";
  poseTo(T, m.position, m.orientation);
  return m;
}

odometry_t odometryMessage(int64_t utime, const Pose3& T) {
  odometry_t m{};
  m.utime = utime;
  m.parent_frame = "W";
  m.child_frame = "I";
  poseTo(T, m.position, m.orientation);
  return m;
}

int64_t utimeOf(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e6)); }

/// GROUND_TRUTH (pose_t, 20 Hz), ODOMETRY (odometry_t, 10 Hz, the truth moved by a known
/// transform), ODOM_B (odometry_t) with two messages swapped, and IMU.
std::string makeLog(const Trajectory& gt, const Pose3& world_change) {
  const std::string path = livo_test::tempPath("evaluate_poses.lcmlog");
  lcm::LogFile log(path, "w");
  EXPECT_TRUE(log.good());
  for (size_t i = 0; i < gt.size(); ++i) {
    const int64_t t = utimeOf(gt[i].stamp);
    fixtures::writeMessage(log, "GROUND_TRUTH", t, poseMessage(t, gt[i].pose));
    imu_t imu{};
    imu.utime = t;
    fixtures::writeMessage(log, "IMU", t, imu);
    if (i % 2 == 0) fixtures::writeMessage(log, "ODOMETRY", t, odometryMessage(t, world_change * gt[i].pose));
  }
  for (size_t i : {0, 2, 1, 3, 4}) {
    const int64_t t = utimeOf(gt[i].stamp);
    fixtures::writeMessage(log, "ODOM_B", t, odometryMessage(t, gt[i].pose));
  }
  return path;
}

template <class Fn>
std::string errorOf(Fn&& fn) {
  try {
    fn();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(PoseLog, ReadsDefaultAndNamedChannelsOfBothTypes) {
  const Trajectory gt = fixtures::wigglyTrajectory(200, 20.0, 1700000000.0);
  const std::string log = makeLog(gt, fixtures::somePose());
  EXPECT_TRUE(isLcmLog(log));
  EXPECT_FALSE(isLcmLog(std::string(LIVO_SHARED_DATA) + "/trajectories/V101_gt.txt"));

  const TrajectoryInput g = readTrajectoryInput(log, "GROUND_TRUTH");
  EXPECT_EQ(g.poses.size(), 200u);
  EXPECT_EQ(g.format, "lcmlog GROUND_TRUTH (livo.pose_t)");
  EXPECT_TRUE(g.has_stamps);
  EXPECT_NEAR(g.poses[3].stamp, gt[3].stamp, 1e-6);  // microsecond stamps
  EXPECT_LT((g.poses[3].pose.matrix() - gt[3].pose.matrix()).norm(), 1e-12);

  const TrajectoryInput o = readTrajectoryInput(log, "ODOMETRY");
  EXPECT_EQ(o.poses.size(), 100u);
  EXPECT_EQ(o.format, "lcmlog ODOMETRY (livo.odometry_t)");

  const TrajectoryInput b = readTrajectoryInput(log + ":ODOM_B", "ODOMETRY");
  ASSERT_EQ(b.poses.size(), 5u);
  for (size_t i = 1; i < b.poses.size(); ++i) EXPECT_LT(b.poses[i - 1].stamp, b.poses[i].stamp);  // sorted
  EXPECT_EQ(b.path, log);

  // The ground truth read back from a log under pose_t can be named by channel too.
  EXPECT_EQ(readTrajectoryInput(log + ":GROUND_TRUTH", "ODOMETRY").poses.size(), 200u);

  // Estimate and ground truth from the same log: the world change is undone by the alignment.
  const Evaluation ev = evaluateTrajectory(o, g, EvaluationOptions{});
  EXPECT_EQ(ev.pairs.size(), 100u);
  EXPECT_LT(ev.ate.max, 1e-9);
}

TEST(PoseLog, ErrorsNameTheFileTheEventAndTheChannels) {
  const Trajectory gt = fixtures::wigglyTrajectory(20, 20.0, 100.0);
  const std::string log = makeLog(gt, Pose3::Identity());

  std::string m = errorOf([&] { readTrajectoryInput(log + ":IMU", "ODOMETRY"); });
  EXPECT_NE(m.find(log + ": event 2 on IMU: is livo.imu_t, expected livo.pose_t or livo.odometry_t"), std::string::npos)
      << m;

  m = errorOf([&] { readTrajectoryInput(log + ":NOPE", "ODOMETRY"); });
  EXPECT_NE(m.find("no messages on channel NOPE"), std::string::npos) << m;
  EXPECT_NE(m.find("GROUND_TRUTH (20)"), std::string::npos) << m;
  EXPECT_NE(m.find("ODOMETRY (10)"), std::string::npos) << m;

  m = errorOf([&] { readTrajectoryInput("/nonexistent/x.lcmlog:ODOMETRY", "ODOMETRY"); });
  EXPECT_NE(m.find("/nonexistent/x.lcmlog:ODOMETRY: no such file"), std::string::npos) << m;

  // A channel named after a text trajectory file.
  const std::string tum = std::string(LIVO_SHARED_DATA) + "/trajectories/V101_gt.txt";
  m = errorOf([&] { readTrajectoryInput(tum + ":ODOMETRY", "ODOMETRY"); });
  EXPECT_NE(m.find("is not an LCM log"), std::string::npos) << m;

  // Garbage, a truncated message, a NaN pose and a zero quaternion on the channel.
  const std::string bad = livo_test::tempPath("evaluate_bad.lcmlog");
  auto writeBad = [&](const std::function<void(lcm::LogFile&)>& last) {
    lcm::LogFile f(bad, "w");
    fixtures::writeMessage(f, "ODOMETRY", 1, odometryMessage(1000000, Pose3::Identity()));
    fixtures::writeMessage(f, "IMU", 2, imu_t{});
    last(f);
  };
  writeBad([](lcm::LogFile& f) { fixtures::writeRaw(f, "ODOMETRY", 3, std::vector<uint8_t>(40, 0xAB)); });
  m = errorOf([&] { readPoseLog(bad, "ODOMETRY"); });
  EXPECT_NE(m.find("event 3 on ODOMETRY: is an unknown type"), std::string::npos) << m;

  writeBad([](lcm::LogFile& f) {
    const odometry_t o = odometryMessage(2000000, Pose3::Identity());
    std::vector<uint8_t> buf(static_cast<size_t>(o.getEncodedSize()));
    o.encode(buf.data(), 0, static_cast<int>(buf.size()));
    buf.resize(buf.size() / 2);
    fixtures::writeRaw(f, "ODOMETRY", 3, buf);
  });
  m = errorOf([&] { readPoseLog(bad, "ODOMETRY"); });
  EXPECT_NE(m.find("event 3 on ODOMETRY: does not decode as livo.odometry_t"), std::string::npos) << m;

  writeBad([](lcm::LogFile& f) {
    odometry_t o = odometryMessage(2000000, Pose3::Identity());
    o.position[1] = NAN;
    fixtures::writeMessage(f, "ODOMETRY", 3, o);
  });
  m = errorOf([&] { readPoseLog(bad, "ODOMETRY"); });
  EXPECT_NE(m.find("event 3 on ODOMETRY: pose is not finite"), std::string::npos) << m;

  writeBad([](lcm::LogFile& f) {
    odometry_t o = odometryMessage(2000000, Pose3::Identity());
    o.orientation[0] = 0.0;
    fixtures::writeMessage(f, "ODOMETRY", 3, o);
  });
  m = errorOf([&] { readPoseLog(bad, "ODOMETRY"); });
  EXPECT_NE(m.find("event 3 on ODOMETRY: orientation quaternion has norm 0"), std::string::npos) << m;

  writeBad([](lcm::LogFile& f) { fixtures::writeMessage(f, "ODOMETRY", 3, poseMessage(2000000, Pose3::Identity())); });
  m = errorOf([&] { readPoseLog(bad, "ODOMETRY"); });
  EXPECT_NE(m.find("event 3 on ODOMETRY: is livo.pose_t but earlier messages on the channel are livo.odometry_t"),
            std::string::npos)
      << m;
}
