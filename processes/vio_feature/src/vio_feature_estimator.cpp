#include "livo/vio_feature/vio_feature_estimator.hpp"

#include <iterator>
#include <utility>

#include "livo/time.hpp"

namespace livo::vio_feature {

VioFeatureEstimator::VioFeatureEstimator(VioFeatureOptions options)
    : options_(std::move(options)),
      window_(options_.window),
      tracker_(CameraProjection(options_.camera), options_.tracker),
      lidar_map_(CameraProjection(options_.camera), options_.lidar_depth),
      offset_us_(toUtime(options_.window.camera_time_offset_s)) {}

int VioFeatureEstimator::lidarDepth(int64_t t, const std::deque<BodyScan>& scans,
                                    std::vector<FeatureObservation>* features) {
  Pose3 T_W_It;
  if (!window_.poseAt(t, &T_W_It)) return 0;
  const Pose3 T_C_W = (T_W_It * options_.window.T_I_C).inverse();
  std::vector<Vec3> points_C;
  for (const BodyScan& s : scans) {
    // the scans that ended lidar_lag_s before the image at the latest: the same set however the
    // channels interleave (a later one may or may not have arrived)
    if (s.t < t - toUtime(options_.lidar_depth_window_s) || s.t > t - toUtime(options_.lidar_lag_s)) continue;
    Pose3 T_W_Is;
    if (!window_.poseAt(s.t, &T_W_Is)) continue;  // older than the window, or past the IMU
    const Pose3 T_C_Is = T_C_W * T_W_Is;
    for (const Vec3& p : s.points_I) points_C.push_back(T_C_Is * p);
  }
  if (points_C.empty()) return 0;
  lidar_map_.setPoints(points_C);
  return lidar_map_.assign(features);
}

ImageOutcome VioFeatureEstimator::addImage(const ImageInput& in) {
  ImageOutcome out;
  const int64_t t = imuTime(in.utime);
  // the gyro's rotation since the previous image predicts where the features move
  Mat3 R_I;
  const bool hint = last_image_t_ != INT64_MIN && window_.gyroRotation(last_image_t_, t, &R_I);
  const Mat3 R_IC = options_.window.T_I_C.linear();
  const Mat3 R_cur_prev = R_IC.transpose() * R_I.transpose() * R_IC;
  last_image_t_ = t;
  TrackedFrame tracked = tracker_.track(in.utime, in.grey, hint ? &R_cur_prev : nullptr);
  if (options_.use_depth_image && in.depth) {
    depthFromImage(*in.depth, options_.depth_image, &tracked.features);
    out.with_depth_image = true;
    ++stats_.with_depth_image;
  }
  if (options_.use_lidar_depth && in.scans && lidarDepth(t, *in.scans, &tracked.features) > 0) {
    out.with_lidar = true;
    ++stats_.with_lidar;
  }
  FrameFeatures frame;
  frame.utime = in.utime;
  frame.keyframe = tracked.keyframe;
  frame.features.reserve(tracked.features.size());
  for (const FeatureObservation& o : tracked.features) frame.features.push_back({o.id, o.xy, o.depth});
  const bool was_initialized = window_.initialized();
  out.frame = window_.addFrame(frame);
  ++stats_.images;
  if (was_initialized && !window_.initialized()) {
    ++epoch_;
    tracker_.reset();
    out.restarted = true;
  }
  out.epoch = epoch_;
  if (out.hasState()) ++stats_.tracked;
  return out;
}

}  // namespace livo::vio_feature
