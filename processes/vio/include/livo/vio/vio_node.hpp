// The livo-vio node: CAMERA, STATE_PRIOR, REGISTERED_SCAN and LOOP_CORRECTION in,
// STATE_POSTERIOR out, around a VioEstimator.
//
// Every STATE_PRIOR is answered exactly once, with its utime and request id: valid = 1 with the
// updated state and covariance, or valid = 0 (the prior's numbers echoed) with the reason on
// HEALTH/stderr: no image at its time, a bad image, too few map points, a rejected update. A prior
// whose image has not arrived waits for it; it is answered valid = 0 as soon as a newer image
// arrives instead, or a newer prior is answered. Images (time on the IMU clock = utime +
// rig.camera.time_offset_s) wait for their prior in a small buffer bounded in time and count.
// The answer depends only on the contents and stamps of the messages and on the order of scans
// and priors (which lockstep replay reproduces), never on wall-clock time.
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <string>

#include <lcm/lcm-cpp.hpp>

#include "livo/correction_frames.hpp"
#include "livo/filter_state_t.hpp"
#include "livo/image_t.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/node.hpp"
#include "livo/reason_counts.hpp"
#include "livo/registered_scan_t.hpp"
#include "livo/vio/vio_config.hpp"
#include "livo/vio/vio_estimator.hpp"
#include "livo/vio/vio_messages.hpp"

namespace livo::vio {

class VioNode {
 public:
  VioNode(lcm::LCM& lcm, VioNodeOptions options, bool quiet = false);

  Node& node() { return node_; }
  const VioEstimator& estimator() const { return vio_; }

  struct Counts {
    int64_t priors = 0;          // STATE_PRIORs answered (each exactly once)
    int64_t updated = 0;         // ... with valid = 1
    int64_t kept = 0;            // ... with valid = 0
    int64_t images = 0;          // usable images received
    int64_t bad_images = 0;      // refused (size, decoding, black, blown out)
    int64_t unused_images = 0;   // dropped from the buffer without a prior
    int64_t scans = 0;           // registered scans taken into the map source
    int64_t epochs_started = 0;  // odometry epochs after the first (LIO resets): the map was dropped
  };
  const Counts& counts() const { return counts_; }
  /// Why priors were answered valid = 0, and how often.
  const std::map<std::string, int64_t>& keptReasons() const { return kept_reasons_.counts(); }
  /// At shutdown: "priors kept by reason: N x why; ..." as a warning, so the final HEALTH carries
  /// it (livo-report lists it under "Where the estimate was weak"); nothing when none was kept.
  void reportKeptReasons();

 private:
  struct BufferedImage {
    int64_t t = 0;  // IMU clock
    GreyImage image;
    std::string problem;  // non-empty: a bad image (kept so its prior gets the reason)
  };
  void onImage(const image_t& m);
  void onPrior(const filter_state_t& m);
  void onScan(const registered_scan_t& m);
  void onCorrection(const loop_correction_t& m);
  /// Answers every waiting prior that can be answered now, then trims the image buffer.
  void resolve();
  void process(const StatePrior& prior, const BufferedImage& image);
  void keep(const StatePrior& prior, const std::string& why);
  void trimImages();
  /// Where a pose of (epoch, correction) goes in the map; a newer epoch (a LIO reset) first drops
  /// the map, the waiting priors and the corrections of the old epoch.
  MapFrame::Placed placeInMap(int32_t epoch, int64_t correction_id);

  VioNodeOptions options_;
  Node node_;
  VioEstimator vio_;
  int64_t offset_us_ = 0;
  int64_t tolerance_us_ = 0;
  std::deque<BufferedImage> images_;  // by t
  std::deque<StatePrior> pending_;    // priors waiting for their image, by utime
  std::deque<int64_t> answered_ids_;  // recent request ids, to answer each only once
  Counts counts_;
  MapFrame frame_;  // the map's odometry epoch and loop correction
  ReasonCounts kept_reasons_;
  std::map<std::string, int64_t> last_warned_;  // reason -> sensor time of its last warning
};

}  // namespace livo::vio
