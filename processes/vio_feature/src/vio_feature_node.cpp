#include "livo/vio_feature/vio_feature_node.hpp"

#include <chrono>
#include <iterator>
#include <sstream>
#include <utility>

#include "livo/camera_image.hpp"
#include "livo/message_checks.hpp"
#include "livo/sensor_messages.hpp"
#include "livo/time.hpp"
#include "livo/vio_feature/vio_feature_messages.hpp"

namespace livo::vio_feature {

namespace {

constexpr size_t kMaxPendingImages = 30;  // images waiting for the IMU (1.5 s at 20 Hz)
constexpr size_t kMaxDepthImages = 30;

}  // namespace

VioFeatureNode::VioFeatureNode(lcm::LCM& lcm, NodeOptions node_options, VioFeatureNodeOptions options)
    : node_(lcm, std::move(node_options)), options_(std::move(options)), estimator_(options_.core) {
  node_.declareOutput(options_.visual_state_channel);
  node_.declareOutput(options_.odometry_channel);
  node_.subscribe<imu_t>(options_.imu_channel, [this](const imu_t& m) { onImu(m); });
  node_.subscribe<image_t>(options_.camera_channel, [this](const image_t& m) { onImage(m); });
  if (options_.core.use_depth_image)
    node_.subscribe<image_t>(options_.depth_channel, [this](const image_t& m) { onDepth(m); });
  if (options_.core.window.use_wheel)
    node_.subscribe<wheel_odometry_t>(options_.wheel_channel, [this](const wheel_odometry_t& m) { onWheel(m); });
  if (options_.core.use_lidar_depth)
    node_.subscribe<registered_scan_t>(options_.registered_scan_channel,
                                       [this](const registered_scan_t& m) { onScan(m); });
}

void VioFeatureNode::onImu(const imu_t& m) {
  std::string why;
  const auto add = [&](std::string* w) { return estimator_.addImu(fromMessage(m), w); };
  if (imu_.take(node_, options_.imu_channel, m.utime, add, &why)) processReady();
}

void VioFeatureNode::onWheel(const wheel_odometry_t& m) {
  std::string why;
  const auto add = [&](std::string* w) { return estimator_.addWheel(fromMessage(m), w); };
  if (wheel_.take(node_, options_.wheel_channel, m.utime, add, &why)) processReady();
}

void VioFeatureNode::onImage(const image_t& m) {
  PendingImage p;
  p.utime = m.utime;
  p.t = estimator_.imuTime(m.utime);
  std::string why;
  if (!decodeGrey(rawImage(m), options_.core.camera.width, options_.core.camera.height, &p.grey, &why)) {
    node_.reject(options_.camera_channel, why);
    refused_.add(why);
    ++bad_images_;
    return;
  }
  if (!pending_.takes(p.t) || p.t <= estimator_.lastImageTime()) {
    node_.reject(options_.camera_channel, "image not later than the previous one");
    refused_.add("image not later than the previous one");
    return;
  }
  if (pending_.size() >= kMaxPendingImages) {
    node_.warn("no IMU up to " + std::to_string(pending_.front().t) + ": image dropped");
    refused_.add("dropped waiting for the IMU");
    pending_.popFront();
    ++dropped_;
  }
  const int64_t t = p.t;
  pending_.pushLater(t, std::move(p));
  processReady();
}

void VioFeatureNode::onDepth(const image_t& m) {
  cv::Mat depth;
  std::string why;
  if (!decodeDepth(rawImage(m), options_.core.camera.width, options_.core.camera.height, &depth, &why)) {
    node_.reject(options_.depth_channel, why);
    return;
  }
  depth_images_[m.utime] = depth;
  while (depth_images_.size() > kMaxDepthImages) depth_images_.erase(depth_images_.begin());
  processReady();
}

void VioFeatureNode::onScan(const registered_scan_t& m) {
  if (const std::string why = registeredScanProblem(m); !why.empty()) {
    node_.reject(options_.registered_scan_channel, why);
    return;
  }
  // into the body frame at the sweep's end, keeping what lies in front of the camera
  BodyScan s = toBodyScan(m, options_.core.window.T_I_C, options_.core.lidar_depth.min_depth);
  const int64_t t = s.t;
  if (!scans_.pushLater(t, std::move(s))) {
    node_.reject(options_.registered_scan_channel, "scan not later than the previous one");
    return;
  }
  const int64_t keep =
      scans_.watermark() - toUtime(options_.core.lidar_depth_window_s + options_.lidar_max_wait_s + 0.2);
  while (scans_.size() > 1 && scans_.front().t < keep) scans_.popFront();
  processReady();
}

bool VioFeatureNode::ready(const PendingImage& p) const {
  if (imu_.watermark() < p.t) return false;
  auto waited = [&](double max_wait_s) { return imu_.watermark() >= p.t + toUtime(max_wait_s); };
  if (options_.core.window.use_wheel && wheel_.watermark() < p.t && !waited(options_.wheel_max_wait_s)) return false;
  if (options_.core.use_depth_image && !depth_images_.count(p.utime) && !waited(options_.depth_max_wait_s))
    return false;
  if (options_.core.use_lidar_depth && scans_.watermark() < p.t - toUtime(options_.core.lidar_lag_s) &&
      !waited(options_.lidar_max_wait_s))
    return false;
  return true;
}

void VioFeatureNode::processReady() {
  pending_.popWhile([this](const PendingImage& p) { return ready(p); }, [this](const PendingImage& p) { process(p); });
}

void VioFeatureNode::process(const PendingImage& p) {
  const auto t0 = std::chrono::steady_clock::now();
  ImageInput in;
  in.utime = p.utime;
  in.grey = p.grey;
  const auto depth = options_.core.use_depth_image ? depth_images_.find(p.utime) : depth_images_.end();
  if (depth != depth_images_.end()) in.depth = &depth->second;
  if (options_.core.use_lidar_depth) in.scans = &scans_.samples();
  const ImageOutcome out = estimator_.addImage(in);
  if (depth != depth_images_.end()) depth_images_.erase(depth_images_.begin(), std::next(depth));
  node_.recordWork("image", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  const FrameResult& r = out.frame;
  if (out.restarted) {
    node_.warn("visual state reset to epoch " + std::to_string(out.epoch) + ": " + r.note);
    node_.publishHealthNow();
    refused_.add("the visual state restarted (" + r.note + ")");
    return;
  }
  if (r.status == FrameResult::Status::kRejected) {
    node_.reject(options_.camera_channel, r.note);
    refused_.add(r.note);
    return;
  }
  if (r.status == FrameResult::Status::kInitializing) {
    refused_.add("before the visual state was initialised (" + r.note + ")");
    if (r.note != init_note_) node_.info(r.note);  // what it waits for, once
    init_note_ = r.note;
    return;
  }
  init_note_.clear();
  if (r.status == FrameResult::Status::kInitialized) node_.info(r.note);
  node_.publish(options_.visual_state_channel, toVisualState(r, out.epoch));
  node_.publish(options_.odometry_channel, toOdometry(r, out.epoch));
}

void VioFeatureNode::reportRefusals() {
  if (!refused_.empty()) node_.warn(refused_.summary("images refused"));
}

VioFeatureNode::Counts VioFeatureNode::counts() const {
  const VioFeatureEstimator::Stats& e = estimator_.stats();
  Counts c;
  c.images = e.images;
  c.tracked = e.tracked;
  c.bad_images = bad_images_;
  c.dropped = dropped_;
  c.with_depth_image = e.with_depth_image;
  c.with_lidar = e.with_lidar;
  return c;
}

std::string VioFeatureNode::summary() const {
  const Counts c = counts();
  std::ostringstream s;
  s << c.images << " images: " << c.tracked << " with a state";
  if (options_.core.use_depth_image) s << ", " << c.with_depth_image << " with their depth image";
  if (options_.core.use_lidar_depth) s << ", " << c.with_lidar << " with LiDAR depth";
  if (c.bad_images) s << ", " << c.bad_images << " refused";
  if (c.dropped) s << ", " << c.dropped << " dropped waiting for the IMU";
  if (estimator_.epoch()) s << "; " << estimator_.epoch() << " restarts";
  if (estimator_.window().estimatesWheelScale())
    s << "; tyre scales " << estimator_.window().wheelScale().x() << " (left), " << estimator_.window().wheelScale().y()
      << " (right)";
  if (estimator_.window().estimatesWheelMounting()) s << "; " << wheelMountingText(estimator_.window().wheelMounting());
  return s.str();
}

}  // namespace livo::vio_feature
