// The colouring core: registered scans grow the map, each image colours the map points measured
// near its time that it sees unoccluded, and loop corrections move the map.
//
// Timing. A registered scan is a world-frame cloud; a world point needs only the camera pose at
// the image time t_img (body pose interpolated from ODOMETRY / scan poses, times T_I_C). The
// point's own measurement time t_p = cloud.utime + time_offset decides which images it may take
// colour from: only those with |t_img - t_p| <= max_time_difference. That keeps pose drift and
// moving objects from smearing colours across long gaps, and the same window defines the set of
// points that build the depth buffer, so an object in front of the camera at t_img was measured
// near t_img and hides what is behind it. An image is processed once a scan ending at or after
// t_img + max_time_difference has arrived (every point that may take its colour is in) and the
// poses bracket t_img, or at flush(); so the result depends on the stamps, not on arrival order.
#pragma once

#include <cmath>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "livo/camera_projection.hpp"
#include "livo/colour/colour_image.hpp"
#include "livo/colour/colour_map.hpp"
#include "livo/colour/colour_options.hpp"
#include "livo/colour/depth_buffer.hpp"
#include "livo/colour/pose_history.hpp"
#include "livo/colour/view_cone.hpp"
#include "livo/map_inputs.hpp"

namespace livo::colour {

/// One colour sample accepted into the map (for diagnostics and the bars).
struct Observation {
  uint32_t point = 0;
  int64_t image_utime = 0;
  Eigen::Vector2d pixel;
  Eigen::Vector3d camera_center;
  Eigen::Vector3f colour;  // normalised, as accumulated
};

struct ColouringStats {
  int64_t scans = 0, points_in = 0, points_rejected = 0;
  int64_t points_out_of_reach = 0;  // beyond max_depth + map_margin from the body: not mapped
  int64_t points_out_of_view = 0;   // outside the widened view cone (map_only_in_view): not mapped
  int64_t points_pruned = 0;        // left the map uncoloured once no image could colour them any more
  int64_t images = 0, images_without_pose = 0, images_dropped = 0;  // dropped: waited beyond max_pending_images
  int64_t projected = 0, occluded = 0, accepted = 0, outliers = 0;
  int64_t gain_estimates = 0;
  double last_gain = 1.0;
};

class ColouringPipeline {
 public:
  ColouringPipeline(const ColourOptions& options, const CameraRig& camera);

  /// Body pose samples (ODOMETRY, REGISTERED_SCAN).
  void addPose(int64_t utime, const Pose3& T_W_I);
  /// Adds a scan's points to the map (non-finite points are skipped and counted, points farther
  /// than max_depth + map_margin from the body and, with map_only_in_view, points outside the
  /// camera's widened view cone counted and left out) and processes
  /// the images it makes ready. False (and nothing changes) for a scan older than the last one.
  bool addScan(const RegisteredScanView& scan, std::string* error);
  /// Queues an image; processes it at once if it is ready. False if older than the last image.
  bool addImage(ColourImage image, std::string* error);
  /// Processes every queued image that has a pose (end of stream).
  void flush();

  /// A keyframe: later scans' points are anchored to it until the next one.
  void addKeyframe(int64_t id, int64_t utime, const Pose3& T_W_I);
  /// Corrected keyframe poses: points anchored to each keyframe move by corrected * current^-1;
  /// those anchored to a keyframe the correction does not list (the loop closure had not seen it
  /// yet) move by `unlisted`, the correction's transform. Returns the number of keyframes that moved.
  int applyCorrection(const std::map<int64_t, Pose3>& corrected, const Pose3& unlisted = Pose3::Identity());

  /// Ids of points coloured or recoloured since the last call (ascending), and of coloured points
  /// that came back from disk moved by a correction.
  std::vector<uint32_t> takeRecoloured();
  /// Brings the map tiles on disk up to date with the corrections (see ColourMap); then
  /// map().forEachPoint visits one point per voxel. For the files.
  void settleMap();
  void setObserver(std::function<void(const Observation&)> observer) { observer_ = std::move(observer); }

  const ColourMap& map() const { return map_; }
  const ColouringStats& stats() const { return stats_; }
  const ColourOptions& options() const { return options_; }
  const CameraRig& camera() const { return camera_.rig(); }
  size_t pendingImages() const { return images_.size(); }

 private:
  struct ActiveScan {
    uint32_t seq;  // scans added before it, plus one
    int64_t t_min, t_max;
    std::vector<std::pair<uint32_t, int64_t>> points;  // map point, measurement time
  };
  /// The cone within which an image of the scan's time window may see a point (camera at the
  /// scan pose; see ColourOptions::view_margin_deg).
  ViewCone viewCone(const RegisteredScanView& scan);
  void processReady(bool flushing);
  /// Colours the map points the image sees unoccluded (false: no pose at its time yet), in stages:
  struct Candidate;
  bool processImage(const ColourImage& image);
  /// The map points measured in [t0, t1], each once, in the order first measured (`seen`: a bit
  /// per map point, working storage).
  void windowPoints(int64_t t0, int64_t t1, std::vector<uint64_t>* seen, std::vector<uint32_t>* ids) const;
  /// Those of `ids` in front of the camera within [min_depth, max_depth] that project into the image.
  void projectedPoints(const std::vector<uint32_t>& ids, const Pose3& T_C_W, std::vector<Candidate>* candidates) const;
  /// The factor that takes the image's brightness to the reference exposure (1 without exposure times).
  double exposureScale(const ColourImage& image);
  /// The candidates inside the border that the depth buffer shows unoccluded: their ids and colour
  /// samples (exposure and vignetting taken out).
  void visibleSamples(const ColourImage& image, const std::vector<Candidate>& candidates, double exposure_scale,
                      std::vector<uint32_t>* ids, std::vector<Eigen::Vector3f>* observed);
  /// The image's gain against the map's colours (1 where too few points have them); `gain_observed`
  /// and `gain_mapped` are working storage.
  double imageGain(const std::vector<uint32_t>& ids, const std::vector<Eigen::Vector3f>& observed,
                   std::vector<Eigen::Vector3f>* gain_observed, std::vector<Eigen::Vector3f>* gain_mapped);
  /// The samples, divided by the gain, into the map's colours (outliers refused).
  void accumulateSamples(const ColourImage& image, const Pose3& T_W_C, const std::vector<Candidate>& candidates,
                         const std::vector<uint32_t>& ids, const std::vector<Eigen::Vector3f>& observed, double gain);
  int64_t windowUs() const { return static_cast<int64_t>(options_.max_time_difference * 1e6); }
  /// Forgets ids the map freed (tiles written to disk) and adds the points that came back moved.
  void afterTileChanges(std::vector<uint32_t> freed);
  void markRecoloured(uint32_t id);
  /// Removes the map points no kept scan refers to and no image has coloured: no image can colour
  /// them any more (their time windows have passed), so they would only hold memory.
  void pruneUncolourable();

  ColourOptions options_;
  CameraProjection camera_;
  DepthBuffer depth_;
  ColourMap map_;
  PoseHistory poses_;
  std::deque<ActiveScan> active_;
  std::deque<ColourImage> images_;                          // time order
  std::map<int64_t, std::pair<int64_t, Pose3>> keyframes_;  // id -> (utime, pose the map is in)
  int64_t last_scan_utime_ = INT64_MIN, last_image_utime_ = INT64_MIN;
  int64_t newest_scan_end_ = INT64_MIN;
  double reference_exposure_ = 0.0;
  uint32_t scan_seq_ = 0;
  std::vector<uint32_t> last_scan_;  // per map point: seq of the newest scan that measured it (0: none)
  int64_t last_prune_utime_ = INT64_MIN;
  double field_half_angle_ = M_PI_2;  // rad: the camera's axis to its farthest image corner
  struct Motion {
    int64_t utime;
    double rate, speed;  // rad/s, m/s between this scan pose and the previous
  };
  std::deque<Motion> motion_;  // the last 2 s of scan poses
  std::optional<std::pair<int64_t, Pose3>> last_scan_pose_;
  std::vector<uint64_t> window_seen_;  // per map point, a bit: taken for the image being coloured
  std::vector<uint8_t> recoloured_flag_;
  std::vector<uint32_t> recoloured_;
  // per-image working sets, kept between images: sized ~10^5 points they would otherwise be
  // allocated (fresh pages, page faults) and returned to the system for every image
  struct Candidate {  // a map point the image may see
    uint32_t id;
    Eigen::Vector2d pixel;
    double z;
  };
  std::vector<uint32_t> window_ids_;  // the map points of the image's time window, once each
  std::vector<Candidate> candidates_;
  std::vector<uint32_t> sampled_ids_;
  std::vector<Eigen::Vector3f> observed_, gain_observed_, gain_mapped_;
  std::vector<std::pair<uint32_t, int64_t>> spare_points_;  // a dropped scan's buffer, for the next
  std::vector<int> accepted_;                               // the scan's points the map takes: their indices, ...
  std::vector<Eigen::Vector3f> accepted_points_;            // ... positions ...
  std::vector<uint32_t> accepted_ids_;                      // ... and map ids
  // map reads are started this many points ahead of their use (the map and its index are far
  // larger than the cache)
  static constexpr size_t kReadAhead = 8;
  std::function<void(const Observation&)> observer_;
  ColouringStats stats_;
};

}  // namespace livo::colour
