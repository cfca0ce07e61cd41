// livo-ros-bridge's node: a ROS 1 node and an LCM node in one thread.
//   ROS -> LCM: each configured topic is subscribed as raw serialised messages
//               (topic_tools::ShapeShifter, any type) and converted by livo-import's own
//               RosMessageConverter, as livo-import rosbag converts a bag's; published on the
//               sensor channels.
//   LCM -> ROS: ODOMETRY -> nav_msgs/Odometry (+ /tf world -> body), REGISTERED_SCAN and
//               COLORED_CLOUD -> sensor_msgs/PointCloud2 (ros_output_messages.hpp); the clouds are
//               converted only while a ROS node subscribes to them.
// Each input message's conversion time is recorded as the work "work:<topic>" (HEALTH, the summary).
// run() alternates between the two (ROS's callback queue, then LCM with a 1 ms wait), so neither
// side waits more than about a millisecond for the other and the livo::Node is used from one thread.
// The converted sensor messages go out in order, at most one per kPublishSpacing: an LCM
// subscription holds at most 30 unhandled messages (LCM's default queue capacity) and drops the
// rest, so a burst (the 200 IMU samples held while their units are decided, a driver's batch)
// must not reach the consumers faster than they handle it.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>
#include <topic_tools/shape_shifter.h>

#include "livo/colored_cloud_t.hpp"
#include "livo/import/import_report.hpp"
#include "livo/import/ros_message_converter.hpp"
#include "livo/node.hpp"
#include "livo/odometry_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "livo/ros_bridge/ros_bridge_config.hpp"

namespace livo::ros_bridge {

class RosBridgeNode : private import::MessageObserver {
 public:
  /// The least time between two converted messages published on LCM.
  static constexpr std::chrono::microseconds kPublishSpacing{1000};

  /// Subscribes and advertises on both sides; `ros_node` must be started (ros::init).
  RosBridgeNode(lcm::LCM& lcm, const NodeOptions& node_options, const RosBridgeNodeOptions& options,
                ros::NodeHandle& ros_node);

  /// Bridges until SIGINT / SIGTERM or ROS shuts down; then finish(). Returns 0, or 1 if the LCM
  /// provider failed.
  int run();
  /// Emits what the IMU unit check still holds, publishes what is queued, ends the livo::Node and
  /// prints the summary. Idempotent.
  void finish();

  Node& node() { return node_; }
  /// ROS messages converted, per input topic.
  const std::map<std::string, int64_t>& converted() const { return converted_; }
  /// ROS messages published, per output topic.
  const std::map<std::string, int64_t>& sent() const { return sent_; }

 private:
  struct Outgoing {  // a converted message, encoded
    std::string channel;
    std::vector<uint8_t> bytes;
  };

  void subscribeInputs(ros::NodeHandle& ros_node);
  void advertiseOutputs(ros::NodeHandle& ros_node);
  /// `where` names the topic in the report's skip examples ("topic /imu").
  void onRosMessage(const std::string& topic, const std::string& where, const topic_tools::ShapeShifter& message);
  void onOdometry(const odometry_t& odometry);
  void onRegisteredScan(const registered_scan_t& scan);
  void onColouredCloud(const colored_cloud_t& cloud);
  void printNewNotes();

  // import::MessageObserver: the converted sensor messages, queued for LCM
  void observe(const std::string& channel, const imu_t& msg) override { enqueue(channel, msg); }
  void observe(const std::string& channel, const point_cloud_t& msg) override { enqueue(channel, msg); }
  void observe(const std::string& channel, const image_t& msg) override { enqueue(channel, msg); }
  void observe(const std::string& channel, const pose_t& msg) override { enqueue(channel, msg); }
  template <class Msg>
  void enqueue(const std::string& channel, const Msg& msg) {
    Outgoing& o = outgoing_.emplace_back();
    o.channel = channel;
    o.bytes.resize(static_cast<size_t>(msg.getEncodedSize()));
    msg.encode(o.bytes.data(), 0, static_cast<int>(o.bytes.size()));
  }
  /// Publishes the oldest queued message if kPublishSpacing has passed since the last one.
  void publishQueued();

  lcm::LCM& lcm_;
  Node node_;
  RosBridgeNodeOptions options_;
  import::ImportReport report_;
  import::RosMessageConverter input_;  // to this node's MessageObserver: the LCM queue
  std::vector<ros::Subscriber> subscribers_;
  ros::Publisher odometry_publisher_, scan_publisher_, cloud_publisher_;
  std::unique_ptr<tf2_ros::TransformBroadcaster> tf_;
  std::vector<uint8_t> bytes_;     // the serialised message being converted
  std::deque<Outgoing> outgoing_;  // converted, not yet published (in conversion order)
  std::chrono::steady_clock::time_point last_publish_{};
  std::map<std::string, int64_t> converted_, sent_;
  size_t notes_printed_ = 0;
  bool finished_ = false;
};

}  // namespace livo::ros_bridge
