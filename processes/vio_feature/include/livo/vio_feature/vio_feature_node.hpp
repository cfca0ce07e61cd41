// The livo-vio-feature node: IMU, CAMERA (and DEPTH, WHEEL, REGISTERED_SCAN) in; VISUAL_STATE
// (visual_state_t, the coupling with livo-lio-graph) and VISUAL_ODOMETRY (the same as odometry_t,
// for the evaluation and the tools) out, around a VioFeatureEstimator (the core without LCM). The
// node checks and converts the messages (vio_feature_messages.hpp), buffers them and decides when
// an image is processed.
//
// Determinism: images wait in a queue and are processed once the IMU has passed their time and,
// for what the rig has, a wheel reading has, their depth image has arrived and a REGISTERED_SCAN
// ending after them has (each of the last three at most *_max_wait_s of IMU beyond the image), so
// the output depends only on the messages' contents and stamps, not on how the channels interleave.
// An estimator restart (an IMU gap) starts a new epoch of the frame V.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include <lcm/lcm-cpp.hpp>
#include <opencv2/core.hpp>

#include "livo/image_t.hpp"
#include "livo/imu_t.hpp"
#include "livo/node.hpp"
#include "livo/reason_counts.hpp"
#include "livo/registered_scan_t.hpp"
#include "livo/sample_queue.hpp"
#include "livo/sensor_feed.hpp"
#include "livo/vio_feature/vio_feature_config.hpp"
#include "livo/vio_feature/vio_feature_estimator.hpp"
#include "livo/wheel_odometry_t.hpp"

namespace livo::vio_feature {

class VioFeatureNode {
 public:
  VioFeatureNode(lcm::LCM& lcm, NodeOptions node_options, VioFeatureNodeOptions options);
  Node& node() { return node_; }
  const VioFeatureEstimator& estimator() const { return estimator_; }
  /// Restarts so far (= the current epoch).
  int32_t epoch() const { return estimator_.epoch(); }

  struct Counts {
    int64_t images = 0;            // processed
    int64_t tracked = 0;           // ... giving a state
    int64_t bad_images = 0;        // refused (size, decoding)
    int64_t dropped = 0;           // dropped from a full queue (no IMU)
    int64_t with_depth_image = 0;  // processed with their depth image
    int64_t with_lidar = 0;        // processed with LiDAR points
  };
  Counts counts() const;
  std::string summary() const;
  /// Why images gave no state, and how often (bad, out of order, dropped, before initialisation,
  /// rejected by the window).
  const ReasonCounts& refusals() const { return refused_; }
  /// At shutdown: "images refused by reason: N x why; ..." as a warning, so the final HEALTH
  /// carries it (livo-report lists it); nothing when every image gave a state.
  void reportRefusals();

 private:
  struct PendingImage {
    int64_t utime = 0;  // camera clock (the message's)
    int64_t t = 0;      // IMU clock
    cv::Mat grey;
  };
  void onImu(const imu_t& m);
  void onWheel(const wheel_odometry_t& m);
  void onImage(const image_t& m);
  void onDepth(const image_t& m);
  void onScan(const registered_scan_t& m);
  /// Whether an image may be processed: what it waits for has come (vio_feature_node.hpp's top).
  bool ready(const PendingImage& p) const;
  /// Processes the waiting images, oldest first, as long as they are ready.
  void processReady();
  void process(const PendingImage& p);

  Node node_;
  VioFeatureNodeOptions options_;
  VioFeatureEstimator estimator_;
  SampleQueue<PendingImage> pending_;        // by IMU-clock time, in arrival order
  std::map<int64_t, cv::Mat> depth_images_;  // by camera utime
  SampleQueue<BodyScan> scans_;              // by sweep end; watermark(): the REGISTERED_SCAN one
  SensorFeed imu_, wheel_;                   // into the estimator; their watermarks
  std::string init_note_;                    // the last reason the estimator gave for not initialising yet
  int64_t bad_images_ = 0;                   // Counts::bad_images
  int64_t dropped_ = 0;                      // Counts::dropped
  ReasonCounts refused_;                     // why images gave no state
};

}  // namespace livo::vio_feature
