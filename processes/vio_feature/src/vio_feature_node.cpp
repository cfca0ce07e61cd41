#include "livo/vio_feature/vio_feature_node.hpp"

#include <chrono>
#include <sstream>

#include "livo/camera_image.hpp"
#include "livo/message_checks.hpp"
#include "livo/messages.hpp"
#include "livo/odometry_t.hpp"
#include "livo/sensor_messages.hpp"
#include "livo/time.hpp"
#include "livo/visual_state_t.hpp"

namespace livo::vio_feature {

namespace {

constexpr size_t kMaxPendingImages = 30;  // images waiting for the IMU (1.5 s at 20 Hz)
constexpr size_t kMaxDepthImages = 30;

}  // namespace

VioFeatureNode::VioFeatureNode(lcm::LCM& lcm, NodeOptions node_options, VioFeatureNodeOptions options)
    : node_(lcm, std::move(node_options)),
      opts_(std::move(options)),
      estimator_(opts_.window),
      tracker_(CameraProjection(opts_.camera), opts_.tracker),
      lidar_map_(CameraProjection(opts_.camera), opts_.lidar_depth),
      offset_us_(toUtime(opts_.window.camera_time_offset_s)) {
  node_.declareOutput(opts_.visual_state_channel);
  node_.declareOutput(opts_.odometry_channel);
  node_.subscribe<imu_t>(opts_.imu_channel, [this](const imu_t& m) { onImu(m); });
  node_.subscribe<image_t>(opts_.camera_channel, [this](const image_t& m) { onImage(m); });
  if (opts_.use_depth_image) node_.subscribe<image_t>(opts_.depth_channel, [this](const image_t& m) { onDepth(m); });
  if (opts_.window.use_wheel)
    node_.subscribe<wheel_odometry_t>(opts_.wheel_channel, [this](const wheel_odometry_t& m) { onWheel(m); });
  if (opts_.use_lidar_depth)
    node_.subscribe<registered_scan_t>(opts_.registered_scan_channel, [this](const registered_scan_t& m) { onScan(m); });
}

void VioFeatureNode::onImu(const imu_t& m) {
  std::string why;
  if (!estimator_.addImu(fromMessage(m), &why)) {
    node_.reject(opts_.imu_channel, why);
    return;
  }
  imu_watermark_ = m.utime;
  processReady();
}

void VioFeatureNode::onWheel(const wheel_odometry_t& m) {
  std::string why;
  if (!estimator_.addWheel(fromMessage(m), &why)) {
    node_.reject(opts_.wheel_channel, why);
    return;
  }
  wheel_watermark_ = m.utime;
  processReady();
}

void VioFeatureNode::onImage(const image_t& m) {
  PendingImage p;
  p.utime = m.utime;
  p.t = m.utime + offset_us_;
  std::string why;
  if (!decodeGrey(rawImage(m), opts_.camera.width, opts_.camera.height, &p.grey, &why)) {
    node_.reject(opts_.camera_channel, why);
    refused_.add(why);
    ++counts_.bad_images;
    return;
  }
  if ((!pending_.empty() && p.t <= pending_.back().t) || p.t <= last_image_t_) {
    node_.reject(opts_.camera_channel, "image not later than the previous one");
    refused_.add("image not later than the previous one");
    return;
  }
  if (pending_.size() >= kMaxPendingImages) {
    node_.warn("no IMU up to " + std::to_string(pending_.front().t) + ": image dropped");
    refused_.add("dropped waiting for the IMU");
    pending_.pop_front();
    ++counts_.dropped;
  }
  pending_.push_back(std::move(p));
  processReady();
}

void VioFeatureNode::onDepth(const image_t& m) {
  cv::Mat depth;
  std::string why;
  if (!decodeDepth(rawImage(m), opts_.camera.width, opts_.camera.height, &depth, &why)) {
    node_.reject(opts_.depth_channel, why);
    return;
  }
  depth_images_[m.utime] = depth;
  while (depth_images_.size() > kMaxDepthImages) depth_images_.erase(depth_images_.begin());
  processReady();
}

void VioFeatureNode::onScan(const registered_scan_t& m) {
  if (const std::string why = registeredScanProblem(m); !why.empty()) {
    node_.reject(opts_.registered_scan_channel, why);
    return;
  }
  // into the body frame at the sweep's end, keeping what lies in front of the camera
  const Pose3 T_I_W = poseFrom(m.position, m.orientation).inverse();
  const Pose3 T_C_I = opts_.window.T_I_C.inverse();
  StoredScan s;
  s.t = m.utime;
  const point_cloud_t& c = m.cloud;
  s.points_I.reserve(static_cast<size_t>(c.num_points) / 2);
  for (int32_t i = 0; i < c.num_points; ++i) {
    const Vec3 p_I = T_I_W * Vec3(c.x[i], c.y[i], c.z[i]);
    if ((T_C_I * p_I).z() > opts_.lidar_depth.min_depth) s.points_I.push_back(p_I);
  }
  if (!scans_.empty() && s.t <= scans_.back().t) {
    node_.reject(opts_.registered_scan_channel, "scan not later than the previous one");
    return;
  }
  scans_.push_back(std::move(s));
  scan_watermark_ = m.utime;
  const int64_t keep = scan_watermark_ - toUtime(opts_.lidar_depth_window_s + opts_.lidar_max_wait_s + 0.2);
  while (scans_.size() > 1 && scans_.front().t < keep) scans_.pop_front();
  processReady();
}

bool VioFeatureNode::ready(const PendingImage& p) const {
  if (imu_watermark_ < p.t) return false;
  auto waited = [&](double max_wait_s) { return imu_watermark_ >= p.t + toUtime(max_wait_s); };
  if (opts_.window.use_wheel && wheel_watermark_ < p.t && !waited(opts_.wheel_max_wait_s)) return false;
  if (opts_.use_depth_image && !depth_images_.count(p.utime) && !waited(opts_.depth_max_wait_s)) return false;
  if (opts_.use_lidar_depth && scan_watermark_ < p.t - toUtime(opts_.lidar_lag_s) && !waited(opts_.lidar_max_wait_s))
    return false;
  return true;
}

void VioFeatureNode::processReady() {
  while (!pending_.empty() && ready(pending_.front())) {
    process(pending_.front());
    pending_.pop_front();
  }
}

int VioFeatureNode::lidarDepth(int64_t t, std::vector<FeatureObservation>* features) {
  Pose3 T_W_It;
  if (!estimator_.poseAt(t, &T_W_It)) return 0;
  const Pose3 T_C_W = (T_W_It * opts_.window.T_I_C).inverse();
  std::vector<Vec3> points_C;
  for (const StoredScan& s : scans_) {
    // the scans that ended lidar_lag_s before the image at the latest: the same set however the
    // channels interleave (a later one may or may not have arrived)
    if (s.t < t - toUtime(opts_.lidar_depth_window_s) || s.t > t - toUtime(opts_.lidar_lag_s)) continue;
    Pose3 T_W_Is;
    if (!estimator_.poseAt(s.t, &T_W_Is)) continue;  // older than the window, or past the IMU
    const Pose3 T_C_Is = T_C_W * T_W_Is;
    for (const Vec3& p : s.points_I) points_C.push_back(T_C_Is * p);
  }
  if (points_C.empty()) return 0;
  lidar_map_.setPoints(points_C);
  return lidar_map_.assign(features);
}

void VioFeatureNode::process(const PendingImage& p) {
  const auto t0 = std::chrono::steady_clock::now();
  // the gyro's rotation since the previous image predicts where the features move
  Mat3 R_I;
  const bool hint = last_image_t_ != INT64_MIN && estimator_.gyroRotation(last_image_t_, p.t, &R_I);
  const Mat3 R_IC = opts_.window.T_I_C.linear();
  const Mat3 R_cur_prev = R_IC.transpose() * R_I.transpose() * R_IC;
  last_image_t_ = p.t;
  TrackedFrame tracked = tracker_.track(p.utime, p.grey, hint ? &R_cur_prev : nullptr);
  if (opts_.use_depth_image) {
    const auto it = depth_images_.find(p.utime);
    if (it != depth_images_.end()) {
      depthFromImage(it->second, opts_.depth_image, &tracked.features);
      ++counts_.with_depth_image;
      depth_images_.erase(depth_images_.begin(), std::next(it));
    }
  }
  if (opts_.use_lidar_depth && lidarDepth(p.t, &tracked.features) > 0) ++counts_.with_lidar;
  FrameFeatures frame;
  frame.utime = p.utime;
  frame.keyframe = tracked.keyframe;
  frame.features.reserve(tracked.features.size());
  for (const FeatureObservation& o : tracked.features) frame.features.push_back({o.id, o.xy, o.depth});
  const bool was_initialized = estimator_.initialized();
  const FrameResult r = estimator_.addFrame(frame);
  node_.recordWork("image", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  ++counts_.images;
  if (was_initialized && !estimator_.initialized()) {
    ++epoch_;
    tracker_.reset();
    node_.warn("visual state reset to epoch " + std::to_string(epoch_) + ": " + r.note);
    node_.publishHealthNow();
    refused_.add("the visual state restarted (" + r.note + ")");
    return;
  }
  if (r.status == FrameResult::Status::kRejected) {
    node_.reject(opts_.camera_channel, r.note);
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
  ++counts_.tracked;
  publish(r);
}

void VioFeatureNode::publish(const FrameResult& r) {
  const VisualState& s = r.state;
  visual_state_t v;
  v.utime = s.utime;
  poseTo(s.pose, v.position, v.orientation);
  vec3To(s.velocity, v.velocity);
  vec3To(s.gyro_bias, v.gyro_bias);
  vec3To(s.accel_bias, v.accel_bias);
  matrixTo<6>(s.pose_covariance, v.pose_covariance);
  v.status = r.status == FrameResult::Status::kInitialized ? visual_state_t::STATUS_INITIALIZED
                                                           : visual_state_t::STATUS_TRACKING;
  v.features = r.features_in_graph;
  v.features_with_depth = r.features_with_depth;
  v.epoch = epoch_;
  node_.publish(opts_.visual_state_channel, v);

  odometry_t o;
  o.utime = s.utime;
  o.parent_frame = "V";
  o.child_frame = "I";
  poseTo(s.pose, o.position, o.orientation);
  vec3To(s.velocity, o.velocity);
  vec3To(Vec3::Zero(), o.angular_velocity);
  matrixTo<6>(s.pose_covariance, o.pose_covariance);
  matrixTo<3>(Mat3(Mat3::Identity() * 1e-2), o.velocity_covariance);
  o.num_residuals = 2 * r.features_in_graph;
  o.degenerate = r.features_in_graph < 20 ? 1 : 0;
  o.min_information_eigenvalue = 0.0;
  o.epoch = epoch_;
  o.correction_id = 0;
  node_.publish(opts_.odometry_channel, o);
}

void VioFeatureNode::reportRefusals() {
  if (!refused_.empty()) node_.warn(refused_.summary("images refused"));
}

std::string VioFeatureNode::summary() const {
  std::ostringstream s;
  s << counts_.images << " images: " << counts_.tracked << " with a state";
  if (opts_.use_depth_image) s << ", " << counts_.with_depth_image << " with their depth image";
  if (opts_.use_lidar_depth) s << ", " << counts_.with_lidar << " with LiDAR depth";
  if (counts_.bad_images) s << ", " << counts_.bad_images << " refused";
  if (counts_.dropped) s << ", " << counts_.dropped << " dropped waiting for the IMU";
  if (epoch_) s << "; " << epoch_ << " restarts";
  return s.str();
}

}  // namespace livo::vio_feature
