// odometryMessage: every field of odometry_t from an OdometryOutput and the frame it is in.
#include <gtest/gtest.h>

#include "livo/odometry_message.hpp"

using namespace livo;

TEST(OdometryMessage, CarriesTheEstimateAndItsFrame) {
  OdometryOutput o;
  o.utime = 1234;
  o.parent_frame = "V";
  o.pose = Pose3::Identity();
  o.pose.translation() = Vec3(1.0, 2.0, 3.0);
  o.velocity = Vec3(0.5, 0.0, -0.5);
  o.angular_velocity = Vec3(0.0, 0.1, 0.0);
  o.pose_covariance = Mat6::Identity() * 1e-4;
  o.pose_covariance(0, 5) = 7.0;
  o.velocity_covariance = Mat3::Identity() * 1e-2;
  o.num_residuals = 42;
  o.degenerate = true;
  o.min_information_eigenvalue = 3.5;
  const odometry_t m = odometryMessage(o, OutputFrame{2, 9});
  EXPECT_EQ(m.utime, 1234);
  EXPECT_EQ(m.parent_frame, "V");
  EXPECT_EQ(m.child_frame, "I");
  EXPECT_EQ(m.position[0], 1.0);
  EXPECT_EQ(m.position[2], 3.0);
  EXPECT_EQ(m.orientation[0], 1.0);  // w of the identity
  EXPECT_EQ(m.velocity[2], -0.5);
  EXPECT_EQ(m.angular_velocity[1], 0.1);
  EXPECT_EQ(m.pose_covariance[0 * 6 + 5], 7.0);  // row-major
  EXPECT_EQ(m.pose_covariance[5 * 6 + 0], 0.0);
  EXPECT_EQ(m.velocity_covariance[4], 1e-2);
  EXPECT_EQ(m.num_residuals, 42);
  EXPECT_EQ(m.degenerate, 1);
  EXPECT_EQ(m.min_information_eigenvalue, 3.5);
  EXPECT_EQ(m.epoch, 2);
  EXPECT_EQ(m.correction_id, 9);
}
