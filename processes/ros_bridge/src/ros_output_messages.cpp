#include "livo/ros_bridge/ros_output_messages.hpp"

#include <cstring>
#include <stdexcept>
#include <string>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace livo::ros_bridge {

namespace {

using Mat3 = Eigen::Matrix3d;
using Mat6 = Eigen::Matrix<double, 6, 6, Eigen::RowMajor>;

Eigen::Quaterniond orientationOf(const double q_wxyz[4]) {
  return Eigen::Quaterniond(q_wxyz[0], q_wxyz[1], q_wxyz[2], q_wxyz[3]).normalized();
}

/// [rotation (right perturbation, body); position (world)] -> ROS's [position; rotation about the
/// world axes]: a body-frame rotation error d is the world-frame error R d.
Mat6 rosPoseCovariance(const double covariance[36], const Mat3& R) {
  const Mat6 livo = Eigen::Map<const Mat6>(covariance);
  Mat6 J = Mat6::Zero();
  J.block<3, 3>(0, 3) = Mat3::Identity();  // position <- position
  J.block<3, 3>(3, 0) = R;                 // world rotation <- body rotation
  return J * livo * J.transpose();
}

sensor_msgs::PointField field(const char* name, uint32_t offset, uint8_t datatype) {
  sensor_msgs::PointField f;
  f.name = name;
  f.offset = offset;
  f.datatype = datatype;
  f.count = 1;
  return f;
}

sensor_msgs::PointCloud2 emptyCloud(int64_t utime, const std::string& frame, uint32_t points, uint32_t point_step) {
  sensor_msgs::PointCloud2 c;
  c.header.stamp = rosTime(utime);
  c.header.frame_id = frame;
  c.height = 1;
  c.width = points;
  c.is_bigendian = false;
  c.point_step = point_step;
  c.row_step = point_step * points;
  c.data.resize(static_cast<size_t>(c.row_step));
  c.is_dense = true;
  return c;
}

template <class T>
void put(sensor_msgs::PointCloud2& c, uint32_t point, uint32_t offset, T value) {
  std::memcpy(&c.data[static_cast<size_t>(point) * c.point_step + offset], &value, sizeof(T));
}

}  // namespace

ros::Time rosTime(int64_t utime) {
  if (utime < 0) throw std::invalid_argument("stamp " + std::to_string(utime) + " us is before 1970: no ROS time");
  ros::Time t;
  t.sec = static_cast<uint32_t>(utime / 1000000);
  t.nsec = static_cast<uint32_t>((utime % 1000000) * 1000);
  return t;
}

nav_msgs::Odometry odometryToRos(const odometry_t& o, const RosFrames& frames) {
  nav_msgs::Odometry m;
  m.header.stamp = rosTime(o.utime);
  m.header.frame_id = frames.world;
  m.child_frame_id = frames.body;
  const Eigen::Quaterniond q = orientationOf(o.orientation);
  m.pose.pose.position.x = o.position[0];
  m.pose.pose.position.y = o.position[1];
  m.pose.pose.position.z = o.position[2];
  m.pose.pose.orientation.x = q.x();
  m.pose.pose.orientation.y = q.y();
  m.pose.pose.orientation.z = q.z();
  m.pose.pose.orientation.w = q.w();
  const Mat3 R = q.toRotationMatrix();
  Eigen::Map<Mat6>(m.pose.covariance.data()) = rosPoseCovariance(o.pose_covariance, R);
  const Eigen::Vector3d v_body = R.transpose() * Eigen::Vector3d(o.velocity[0], o.velocity[1], o.velocity[2]);
  m.twist.twist.linear.x = v_body.x();
  m.twist.twist.linear.y = v_body.y();
  m.twist.twist.linear.z = v_body.z();
  m.twist.twist.angular.x = o.angular_velocity[0];
  m.twist.twist.angular.y = o.angular_velocity[1];
  m.twist.twist.angular.z = o.angular_velocity[2];
  const Mat3 velocity_cov = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(o.velocity_covariance);
  Mat6 twist_cov = Mat6::Zero();
  twist_cov.block<3, 3>(0, 0) = R.transpose() * velocity_cov * R;
  Eigen::Map<Mat6>(m.twist.covariance.data()) = twist_cov;
  return m;
}

geometry_msgs::TransformStamped odometryTransform(const odometry_t& o, const RosFrames& frames) {
  geometry_msgs::TransformStamped t;
  t.header.stamp = rosTime(o.utime);
  t.header.frame_id = frames.world;
  t.child_frame_id = frames.body;
  const Eigen::Quaterniond q = orientationOf(o.orientation);
  t.transform.translation.x = o.position[0];
  t.transform.translation.y = o.position[1];
  t.transform.translation.z = o.position[2];
  t.transform.rotation.x = q.x();
  t.transform.rotation.y = q.y();
  t.transform.rotation.z = q.z();
  t.transform.rotation.w = q.w();
  return t;
}

sensor_msgs::PointCloud2 registeredScanToRos(const registered_scan_t& scan, const RosFrames& frames) {
  using sensor_msgs::PointField;
  const point_cloud_t& p = scan.cloud;
  const uint32_t n = static_cast<uint32_t>(p.num_points);
  sensor_msgs::PointCloud2 c = emptyCloud(scan.utime, frames.world, n, 22);
  c.fields = {field("x", 0, PointField::FLOAT32),     field("y", 4, PointField::FLOAT32),
              field("z", 8, PointField::FLOAT32),     field("intensity", 12, PointField::FLOAT32),
              field("time", 16, PointField::FLOAT32), field("ring", 20, PointField::INT16)};
  for (uint32_t i = 0; i < n; ++i) {
    put(c, i, 0, p.x[i]);
    put(c, i, 4, p.y[i]);
    put(c, i, 8, p.z[i]);
    put(c, i, 12, p.intensity[i]);
    put(c, i, 16, p.time_offset[i]);
    put(c, i, 20, p.ring[i]);
  }
  return c;
}

sensor_msgs::PointCloud2 colouredCloudToRos(const colored_cloud_t& cloud, const RosFrames& frames) {
  using sensor_msgs::PointField;
  const uint32_t n = static_cast<uint32_t>(cloud.num_points);
  sensor_msgs::PointCloud2 c = emptyCloud(cloud.utime, frames.world, n, 16);
  c.fields = {field("x", 0, PointField::FLOAT32), field("y", 4, PointField::FLOAT32),
              field("z", 8, PointField::FLOAT32), field("rgb", 12, PointField::FLOAT32)};
  for (uint32_t i = 0; i < n; ++i) {
    put(c, i, 0, cloud.x[i]);
    put(c, i, 4, cloud.y[i]);
    put(c, i, 8, cloud.z[i]);
    const uint32_t rgb = (static_cast<uint32_t>(static_cast<uint8_t>(cloud.r[i])) << 16) |
                         (static_cast<uint32_t>(static_cast<uint8_t>(cloud.g[i])) << 8) |
                         static_cast<uint32_t>(static_cast<uint8_t>(cloud.b[i]));
    put(c, i, 12, rgb);  // the bits of a float32, as PCL packs rgb
  }
  return c;
}

}  // namespace livo::ros_bridge
