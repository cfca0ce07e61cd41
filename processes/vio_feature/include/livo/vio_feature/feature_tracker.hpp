// The front end of the feature-based visual subsystem (VINS-Mono / Ground-Fusion style): corners
// tracked from image to image with pyramidal KLT (started where a gyro rotation predicts, if one is
// given), outliers rejected by a forward-backward KLT check and a fundamental-matrix RANSAC from the
// previous image and from the last keyframe, new Shi-Tomasi corners detected where the image has
// room (a mask around the existing tracks, longest tracks first, keeps them evenly spread), and the
// keyframe decision by parallax and by tracked count.
//
// Pixels go through CameraProjection only (pixelRay, project), so the distortion model is
// transparent: the RANSAC and the parallax work on undistorted points on a virtual pinhole with
// the rig's focal length, as VINS does, which holds for a fisheye lens too (rays within 90 degrees
// of the axis).
//
//   FeatureTracker tracker(CameraProjection(rig), FeatureTrackerOptions{});
//   TrackedFrame f = tracker.track(image.utime, grey, &R_cur_prev /* or nullptr */);
#pragma once

#include <cstdint>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "livo/camera_projection.hpp"
#include "livo/so3.hpp"

namespace livo::vio_feature {

struct FeatureTrackerOptions {
  int max_features = 150;              // corners kept per image
  double min_distance_px = 30.0;       // no new corner closer than this to a track, no track this
                                       // close to a longer one (the even spread)
  double quality_level = 0.01;         // Shi-Tomasi, relative to the image's strongest corner (new
                                       // corners are found on the half-resolution image)
  int border_px = 8;                   // tracks and corners stay this far inside the image
  int pyramid_levels = 3;              // KLT levels above the full image
  int window_px = 21;                  // KLT window side
  int max_iterations = 30;             // KLT iterations per level
  double klt_epsilon = 0.01;           // KLT convergence, px
  bool backward_check = true;          // track back and compare with where the track came from
  double backward_threshold_px = 0.5;  // largest forward-backward distance kept
  bool ransac = true;                  // fundamental-matrix RANSAC on the virtual pinhole
  double ransac_threshold_px = 0.5;    // epipolar distance on the virtual pinhole (VINS: 1 px at f 460)
  double ransac_confidence = 0.99;
  bool keyframe_ransac = true;         // a second RANSAC from the last keyframe (the drift of a track
                                       // builds up over images; a longer baseline shows it)
  double keyframe_parallax_px = 10.0;  // mean parallax since the last keyframe (rotation taken out
                                       // with the hints, virtual pinhole px) that makes a keyframe
  int keyframe_min_tracked = 50;       // fewer tracks from the previous image make a keyframe
};

struct FeatureObservation {
  uint64_t id = 0;
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();        // distorted image coordinates
  Eigen::Vector2d xy = Eigen::Vector2d::Zero();           // undistorted normalised (z = 1)
  Eigen::Vector2d xy_velocity = Eigen::Vector2d::Zero();  // of xy, per second (0 when new)
  int track_length = 1;                                   // images this feature was seen in
  double depth = 0.0;                                     // m along z, 0 = unknown (feature_depth)
};

struct TrackedFrame {
  int64_t utime = 0;
  std::vector<FeatureObservation> features;  // by increasing id: the oldest tracks first
  bool keyframe = false;
  double parallax_px = 0.0;   // mean parallax since the last keyframe (virtual pinhole px)
  int tracked = 0;            // tracks carried over from the previous image (after every check
                              // and the thinning of crowded tracks)
  int new_features = 0;       // corners detected in this image
  int rejected_ransac = 0;    // tracks dropped by the fundamental-matrix RANSAC
  int rejected_backward = 0;  // tracks dropped by the forward-backward check
};

class FeatureTracker {
 public:
  FeatureTracker(const CameraProjection& camera, const FeatureTrackerOptions& options);

  /// Tracks the previous image's features into `image` (CV_8UC1; CV_8UC3 R, G, B is converted)
  /// and tops them up with new corners. `R_cur_prev` (rotation from the previous camera frame to
  /// this one, e.g. integrated gyro) predicts where each feature moves and takes the rotation out
  /// of the parallax; without it KLT starts at the previous pixel. Throws std::invalid_argument
  /// for an image of another size or type.
  TrackedFrame track(int64_t utime, const cv::Mat& image, const Mat3* R_cur_prev = nullptr);

  /// Forgets every track (the next image starts afresh and is a keyframe); ids keep increasing.
  void reset();

  const FeatureTrackerOptions& options() const { return options_; }

 private:
  struct Track {
    uint64_t id;
    int length;
    cv::Point2f pixel;
    Eigen::Vector2d xy;
    Eigen::Vector2d xy_prev;  // in the previous image (= xy when new)
  };
  Eigen::Vector2d normalised(const cv::Point2f& pixel) const;
  /// KLT from the previous image into `pyramid` (started where R_cur_prev predicts), then the
  /// border, forward-backward and RANSAC checks; counts the rejections in `frame`.
  void followTracks(const std::vector<cv::Mat>& pyramid, const Mat3* R_cur_prev, TrackedFrame* frame);
  /// Inlier flags of a fundamental-matrix RANSAC from `from` to `to` (xy; all set if too few).
  std::vector<uint8_t> epipolarInliers(const std::vector<Eigen::Vector2d>& from,
                                       const std::vector<Eigen::Vector2d>& to) const;
  /// Drops the tracks that fail the RANSAC from the previous image (and from the last keyframe,
  /// if keyframe_ransac); the count.
  int rejectByRansac(std::vector<Track>* tracks) const;
  /// New corners on `half` (the image at half resolution) away from `tracks` (longest first;
  /// too-close shorter tracks are dropped); the count.
  int detect(const cv::Mat& half, std::vector<Track>* tracks);
  /// Mean parallax of the tracks since the last keyframe, rotation-compensated, in virtual px.
  double parallaxSinceKeyframe(const std::vector<Track>& tracks) const;

  CameraProjection camera_;
  FeatureTrackerOptions options_;
  double focal_;  // the virtual pinhole's focal length, px
  uint64_t next_id_ = 0;
  int64_t prev_utime_ = 0;
  std::vector<cv::Mat> prev_pyramid_;
  std::vector<Track> tracks_;
  std::unordered_map<uint64_t, Eigen::Vector2d> keyframe_xy_;  // track id -> xy at the last keyframe
  Mat3 R_cur_keyframe_ = Mat3::Identity();                     // hinted rotation since that keyframe
};

}  // namespace livo::vio_feature
