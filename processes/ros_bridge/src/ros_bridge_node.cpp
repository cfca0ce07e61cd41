#include "livo/ros_bridge/ros_bridge_node.hpp"

#include <iostream>
#include <set>
#include <thread>

#include <ros/callback_queue.h>

#include "livo/ros_bridge/ros_output_messages.hpp"

namespace livo::ros_bridge {

namespace {

int64_t nowNs() {
  const ros::Time t = ros::Time::now();
  return static_cast<int64_t>(t.sec) * 1000000000LL + t.nsec;
}

}  // namespace

RosBridgeNode::RosBridgeNode(lcm::LCM& lcm, const NodeOptions& node_options, const RosBridgeNodeOptions& options,
                             ros::NodeHandle& ros_node)
    : lcm_(lcm),
      node_(lcm, node_options),
      options_(options),
      input_(options_.input, *this, report_, "the arrival time") {
  subscribeInputs(ros_node);
  advertiseOutputs(ros_node);
}

void RosBridgeNode::subscribeInputs(ros::NodeHandle& ros_node) {
  const import::ChannelNames& ch = options_.input.channels;
  std::set<std::string> subscribed;
  for (const auto& [role, topic] : input_.roleTopics()) {
    if (!subscribed.insert(topic).second) continue;  // a topic named for two roles has the first (as the converter)
    const uint32_t queue =
        static_cast<uint32_t>(role == std::string("imu") ? options_.imu_queue : options_.sensor_queue);
    boost::function<void(const topic_tools::ShapeShifter::ConstPtr&)> callback =
        [this, topic = topic, where = "topic " + topic](const topic_tools::ShapeShifter::ConstPtr& m) {
          onRosMessage(topic, where, *m);
        };
    subscribers_.push_back(ros_node.subscribe<topic_tools::ShapeShifter>(topic, queue, callback, ros::VoidConstPtr(),
                                                                         ros::TransportHints().tcpNoDelay()));
    converted_[topic] = 0;
  }
  for (const std::string* c : {&ch.imu, &ch.lidar, &ch.camera, &ch.camera_right, &ch.depth, &ch.ground_truth})
    node_.declareOutput(*c);
}

void RosBridgeNode::advertiseOutputs(ros::NodeHandle& ros_node) {
  const RosOutputTopics& out = options_.outputs;
  if (!out.odometry.empty() || out.tf)
    node_.subscribe<odometry_t>(options_.odometry_channel, [this](const odometry_t& m) { onOdometry(m); });
  if (!out.odometry.empty()) odometry_publisher_ = ros_node.advertise<nav_msgs::Odometry>(out.odometry, 1000);
  if (out.tf) tf_ = std::make_unique<tf2_ros::TransformBroadcaster>();
  if (!out.registered_scan.empty()) {
    scan_publisher_ = ros_node.advertise<sensor_msgs::PointCloud2>(out.registered_scan, 10);
    node_.subscribe<registered_scan_t>(options_.registered_scan_channel,
                                       [this](const registered_scan_t& m) { onRegisteredScan(m); });
  }
  if (!out.colored_cloud.empty()) {
    cloud_publisher_ = ros_node.advertise<sensor_msgs::PointCloud2>(out.colored_cloud, 10);
    node_.subscribe<colored_cloud_t>(options_.colored_cloud_channel,
                                     [this](const colored_cloud_t& m) { onColouredCloud(m); });
  }
}

void RosBridgeNode::onRosMessage(const std::string& topic, const std::string& where,
                                 const topic_tools::ShapeShifter& message) {
  bytes_.resize(message.size());
  ros::serialization::OStream stream(bytes_.data(), static_cast<uint32_t>(bytes_.size()));
  message.write(stream);
  import::RosWireMessage m;
  m.topic = &topic;
  m.type = &message.getDataType();
  m.md5sum = &message.getMD5Sum();
  m.format = import::RosWireFormat::kRos1;
  m.receive_time_ns = nowNs();
  m.data = bytes_.data();
  m.size = bytes_.size();
  m.where = where;
  const auto start = std::chrono::steady_clock::now();
  if (input_.handle(m)) ++converted_[topic];
  node_.recordWork(topic, std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  printNewNotes();
}

void RosBridgeNode::onOdometry(const odometry_t& odometry) {
  try {
    if (odometry_publisher_) {
      odometry_publisher_.publish(odometryToRos(odometry, options_.frames));
      ++sent_[options_.outputs.odometry];
    }
    if (tf_) {
      tf_->sendTransform(odometryTransform(odometry, options_.frames));
      ++sent_["/tf"];
    }
  } catch (const std::invalid_argument& e) {
    node_.reject(options_.odometry_channel, e.what());
  }
}

void RosBridgeNode::onRegisteredScan(const registered_scan_t& scan) {
  if (scan_publisher_.getNumSubscribers() == 0) return;
  try {
    scan_publisher_.publish(registeredScanToRos(scan, options_.frames));
    ++sent_[options_.outputs.registered_scan];
  } catch (const std::invalid_argument& e) {
    node_.reject(options_.registered_scan_channel, e.what());
  }
}

void RosBridgeNode::onColouredCloud(const colored_cloud_t& cloud) {
  if (cloud_publisher_.getNumSubscribers() == 0) return;
  try {
    cloud_publisher_.publish(colouredCloudToRos(cloud, options_.frames));
    ++sent_[options_.outputs.colored_cloud];
  } catch (const std::invalid_argument& e) {
    node_.reject(options_.colored_cloud_channel, e.what());
  }
}

void RosBridgeNode::printNewNotes() {
  const std::vector<std::string>& notes = report_.notes();
  for (; notes_printed_ < notes.size(); ++notes_printed_) node_.info(notes[notes_printed_]);
}

void RosBridgeNode::publishQueued() {
  if (outgoing_.empty()) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_publish_ < kPublishSpacing) return;
  const Outgoing& o = outgoing_.front();
  node_.publishRaw(o.channel, o.bytes.data(), static_cast<int>(o.bytes.size()));
  outgoing_.pop_front();
  last_publish_ = now;
}

int RosBridgeNode::run() {
  installSignalHandlers();
  node_.setCoalesceProgress(true);
  node_.announce();
  ros::CallbackQueue* queue = ros::getGlobalCallbackQueue();
  int rc = 0;
  while (!shutdownRequested() && ros::ok()) {
    queue->callAvailable(ros::WallDuration(0));
    publishQueued();
    const int r = lcm_.handleTimeout(1);
    if (r < 0 && shutdownRequested()) break;  // a signal interrupted the wait
    if (r < 0) {
      node_.error("LCM provider failed; shutting down");
      rc = 1;
      break;
    }
    node_.flushProgress();
    node_.tick();
  }
  finish();
  return rc;
}

void RosBridgeNode::finish() {
  if (finished_) return;
  finished_ = true;
  input_.finish();
  while (!outgoing_.empty()) {  // what was converted still goes out, at the same pace
    publishQueued();
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  printNewNotes();
  node_.finish();
  std::cerr << "[" << node_.name() << "] ROS messages converted:";
  for (const auto& [topic, n] : converted_) std::cerr << " " << topic << " " << n;
  std::cerr << "; sent:";
  for (const auto& [topic, n] : sent_) std::cerr << " " << topic << " " << n;
  std::cerr << "; skipped " << report_.skippedTotal() << "\n";
  for (const auto& [reason, s] : report_.skipped())
    std::cerr << "[" << node_.name() << "]   skipped " << s.count << ": " << reason << "\n";
}

}  // namespace livo::ros_bridge
