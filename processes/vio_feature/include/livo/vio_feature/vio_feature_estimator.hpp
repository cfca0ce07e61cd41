// livo-vio-feature's core without LCM: one image at a time through the front end and the back end.
// Per image:
//   1. the gyro's rotation since the previous image predicts where the features move (the hint);
//   2. the FeatureTracker tracks the grey image (KLT, outlier checks, new corners, keyframe);
//   3. depth for the features from the image's registered depth image (RGB-D) and from the LiDAR:
//      the registered scans that ended between lidar_depth_window_s and lidar_lag_s before the
//      image, moved into the camera at the image's time with the window's poses;
//   4. the SlidingWindowEstimator adds the frame; when it restarts (an IMU gap) the tracker starts
//      over and a new epoch of the frame V begins.
// The caller (the node) buffers the inputs and hands an image over once the IMU has passed its time
// (and whatever else it waits for: see vio_feature_node.hpp); the IMU and wheel samples are added
// as they come. Deterministic: the output depends only on the inputs and their order.
#pragma once

#include <cstdint>
#include <deque>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "livo/sensor_samples.hpp"
#include "livo/vio_feature/feature_depth.hpp"
#include "livo/vio_feature/feature_tracker.hpp"
#include "livo/vio_feature/sliding_window_estimator.hpp"
#include "livo/vio_feature/vio_feature_options.hpp"

namespace livo::vio_feature {

/// A registered LiDAR scan for feature depth: the points in the body frame at the sweep's end,
/// those in front of the camera.
struct BodyScan {
  int64_t t = 0;  // end of sweep (IMU clock)
  std::vector<Vec3> points_I;
};

/// One image's input: the image (the camera's size) and what depth there is for it.
struct ImageInput {
  int64_t utime = 0;                            // camera clock (the image's stamp)
  cv::Mat grey;                                 // CV_8UC1 (CV_8UC3 R, G, B is converted: FeatureTracker::track)
  const cv::Mat* depth = nullptr;               // its registered depth image (CV_32F metres along z), if any
  const std::deque<BodyScan>* scans = nullptr;  // the recent registered scans, oldest first, if any
};

struct ImageOutcome {
  FrameResult frame;              // the sliding window's result (its state when kInitialized / kTracked)
  int32_t epoch = 0;              // the frame V's epoch the state is in
  bool restarted = false;         // the window restarted on this image (frame.note says why): a new epoch
  bool with_depth_image = false;  // its depth image lent depths
  bool with_lidar = false;        // LiDAR points gave at least one feature a depth
  /// A state to publish: initialised or tracked, and no restart.
  bool hasState() const {
    return !restarted &&
           (frame.status == FrameResult::Status::kInitialized || frame.status == FrameResult::Status::kTracked);
  }
};

class VioFeatureEstimator {
 public:
  struct Stats {
    int64_t images = 0;            // processed
    int64_t tracked = 0;           // ... giving a state
    int64_t with_depth_image = 0;  // processed with their depth image
    int64_t with_lidar = 0;        // processed with LiDAR points
  };

  explicit VioFeatureEstimator(VioFeatureOptions options);

  /// Buffers an IMU sample (IMU clock); false with `why` for a non-finite or non-increasing one.
  bool addImu(const ImuSample& s, std::string* why = nullptr) { return window_.addImu(s, why); }
  /// Buffers a wheel reading (IMU clock); the same checks.
  bool addWheel(const WheelSample& s, std::string* why = nullptr) { return window_.addWheel(s, why); }
  /// An image's time on the IMU clock (its stamp + camera_time_offset_s).
  int64_t imuTime(int64_t camera_utime) const { return camera_utime + offset_us_; }
  /// The previous image's time on the IMU clock (INT64_MIN before any): a later image must be later.
  int64_t lastImageTime() const { return last_image_t_; }
  /// Processes one image; the IMU (and wheels) must be buffered up to imuTime(in.utime) and
  /// images must come in time order.
  ImageOutcome addImage(const ImageInput& in);

  const SlidingWindowEstimator& window() const { return window_; }
  /// Restarts so far (= the current epoch).
  int32_t epoch() const { return epoch_; }
  const Stats& stats() const { return stats_; }
  const VioFeatureOptions& options() const { return options_; }

 private:
  /// Depth from the scans moved into the camera at t (the window's poses); how many features got one.
  int lidarDepth(int64_t t, const std::deque<BodyScan>& scans, std::vector<FeatureObservation>* features);

  VioFeatureOptions options_;
  SlidingWindowEstimator window_;
  FeatureTracker tracker_;
  LidarDepthMap lidar_map_;
  int64_t offset_us_ = 0;
  int64_t last_image_t_ = INT64_MIN;
  int32_t epoch_ = 0;
  Stats stats_;
};

}  // namespace livo::vio_feature
