#include "livo/vio_feature/feature_tracker.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace livo::vio_feature {

namespace {

bool inside(const cv::Point2f& p, int width, int height, int border) {
  return p.x >= border && p.y >= border && p.x <= width - 1 - border && p.y <= height - 1 - border;
}

/// Keeps the elements of `v` whose `keep` entry is set, in order.
template <typename T>
void keepSelected(const std::vector<uint8_t>& keep, std::vector<T>* v) {
  size_t j = 0;
  for (size_t i = 0; i < v->size(); ++i)
    if (keep[i]) (*v)[j++] = (*v)[i];
  v->resize(j);
}

}  // namespace

FeatureTracker::FeatureTracker(const CameraProjection& camera, const FeatureTrackerOptions& options)
    : camera_(camera), options_(options), focal_(0.5 * (camera.rig().fx + camera.rig().fy)) {}

void FeatureTracker::reset() {
  prev_pyramid_.clear();
  tracks_.clear();
  keyframe_xy_.clear();
  R_cur_keyframe_.setIdentity();
}

Eigen::Vector2d FeatureTracker::normalised(const cv::Point2f& pixel) const {
  const Vec3 ray = camera_.pixelRay(Eigen::Vector2d(pixel.x, pixel.y));
  // Rays at or beyond 90 degrees (only a fisheye has them) have no point on the z = 1 plane; they
  // are put far out, where the RANSAC rejects them and the parallax ignores them.
  if (!(ray.z() > 1e-6)) return Eigen::Vector2d::Constant(1e6);
  return ray.head<2>() / ray.z();
}

TrackedFrame FeatureTracker::track(int64_t utime, const cv::Mat& image, const Mat3* R_cur_prev) {
  const CameraRig& rig = camera_.rig();
  if (image.cols != rig.width || image.rows != rig.height)
    throw std::invalid_argument("FeatureTracker: image is " + std::to_string(image.cols) + "x" +
                                std::to_string(image.rows) + ", the camera " + std::to_string(rig.width) + "x" +
                                std::to_string(rig.height));
  cv::Mat grey;
  if (image.type() == CV_8UC1)
    grey = image;
  else if (image.type() == CV_8UC3)
    cv::cvtColor(image, grey, cv::COLOR_RGB2GRAY);
  else
    throw std::invalid_argument("FeatureTracker: image type must be CV_8UC1 or CV_8UC3");

  std::vector<cv::Mat> pyramid;  // with the gradients, which KLT needs of the image it tracks from
  cv::buildOpticalFlowPyramid(grey, pyramid, cv::Size(options_.window_px, options_.window_px), options_.pyramid_levels,
                              true);

  TrackedFrame frame;
  frame.utime = utime;
  const bool first = prev_pyramid_.empty();
  if (!first) followTracks(pyramid, R_cur_prev, &frame);

  cv::Mat half;  // the pyramid holds (image, gradient) per level: [2] is the half-resolution image
  if (pyramid.size() > 2)
    half = pyramid[2];
  else
    cv::pyrDown(grey, half);
  frame.new_features = detect(half, &tracks_);
  frame.tracked = static_cast<int>(tracks_.size()) - frame.new_features;

  if (R_cur_prev) R_cur_keyframe_ = *R_cur_prev * R_cur_keyframe_;
  frame.parallax_px = parallaxSinceKeyframe(tracks_);
  frame.keyframe =
      first || frame.tracked < options_.keyframe_min_tracked || frame.parallax_px >= options_.keyframe_parallax_px;

  const double dt = first ? 0.0 : 1e-6 * static_cast<double>(utime - prev_utime_);
  frame.features.reserve(tracks_.size());
  for (const Track& t : tracks_) {
    FeatureObservation o;
    o.id = t.id;
    o.pixel = Eigen::Vector2d(t.pixel.x, t.pixel.y);
    o.xy = t.xy;
    if (t.length > 1 && dt > 0.0) o.xy_velocity = (t.xy - t.xy_prev) / dt;
    o.track_length = t.length;
    frame.features.push_back(o);
  }

  if (frame.keyframe) {
    keyframe_xy_.clear();
    for (const Track& t : tracks_) keyframe_xy_.emplace(t.id, t.xy);
    R_cur_keyframe_.setIdentity();
  }
  prev_pyramid_ = std::move(pyramid);
  prev_utime_ = utime;
  return frame;
}

void FeatureTracker::followTracks(const std::vector<cv::Mat>& pyramid, const Mat3* R_cur_prev, TrackedFrame* frame) {
  if (tracks_.empty()) return;
  const CameraRig& rig = camera_.rig();
  std::vector<cv::Point2f> prev_pts, cur_pts;
  prev_pts.reserve(tracks_.size());
  cur_pts.reserve(tracks_.size());
  for (const Track& t : tracks_) {
    prev_pts.push_back(t.pixel);
    Eigen::Vector2d predicted;
    if (R_cur_prev &&
        camera_.project(*R_cur_prev * camera_.pixelRay(Eigen::Vector2d(t.pixel.x, t.pixel.y)), &predicted))
      cur_pts.emplace_back(static_cast<float>(predicted.x()), static_cast<float>(predicted.y()));
    else
      cur_pts.push_back(t.pixel);
  }
  const cv::Size window(options_.window_px, options_.window_px);
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, options_.max_iterations,
                                  options_.klt_epsilon);
  std::vector<uint8_t> status;
  std::vector<float> error;
  cv::calcOpticalFlowPyrLK(prev_pyramid_, pyramid, prev_pts, cur_pts, status, error, window, options_.pyramid_levels,
                           criteria, cv::OPTFLOW_USE_INITIAL_FLOW);
  for (size_t i = 0; i < status.size(); ++i)
    if (status[i] && !inside(cur_pts[i], rig.width, rig.height, options_.border_px)) status[i] = 0;
  keepSelected(status, &prev_pts);
  keepSelected(status, &cur_pts);
  keepSelected(status, &tracks_);

  if (options_.backward_check && !tracks_.empty()) {
    std::vector<cv::Point2f> back_pts = prev_pts;
    std::vector<uint8_t> back_status;
    cv::calcOpticalFlowPyrLK(pyramid, prev_pyramid_, cur_pts, back_pts, back_status, error, window,
                             options_.pyramid_levels, criteria, cv::OPTFLOW_USE_INITIAL_FLOW);
    const double max_d2 = options_.backward_threshold_px * options_.backward_threshold_px;
    for (size_t i = 0; i < back_status.size(); ++i) {
      const cv::Point2f d = back_pts[i] - prev_pts[i];
      const bool keep = back_status[i] && d.x * d.x + d.y * d.y <= max_d2;
      frame->rejected_backward += !keep;
      back_status[i] = keep;
    }
    keepSelected(back_status, &cur_pts);
    keepSelected(back_status, &tracks_);
  }

  for (size_t i = 0; i < tracks_.size(); ++i) {
    Track& t = tracks_[i];
    t.xy_prev = t.xy;
    t.pixel = cur_pts[i];
    t.xy = normalised(cur_pts[i]);
    ++t.length;
  }
  if (options_.ransac) frame->rejected_ransac = rejectByRansac(&tracks_);
}

std::vector<uint8_t> FeatureTracker::epipolarInliers(const std::vector<Eigen::Vector2d>& from,
                                                     const std::vector<Eigen::Vector2d>& to) const {
  std::vector<uint8_t> inlier(from.size(), 1);
  if (from.size() < 8) return inlier;
  // Undistorted points on a virtual pinhole with the rig's focal length, so that the threshold is
  // in pixels and the model holds for any lens.
  const CameraRig& rig = camera_.rig();
  auto onPinhole = [&](const Eigen::Vector2d& xy) {
    return cv::Point2f(static_cast<float>(focal_ * xy.x() + rig.cx), static_cast<float>(focal_ * xy.y() + rig.cy));
  };
  std::vector<cv::Point2f> a, b;
  a.reserve(from.size());
  b.reserve(to.size());
  for (size_t i = 0; i < from.size(); ++i) a.push_back(onPinhole(from[i])), b.push_back(onPinhole(to[i]));
  // OpenCV's RANSAC draws from a fixed seed: the same input gives the same inliers.
  std::vector<uint8_t> mask;
  const cv::Mat F =
      cv::findFundamentalMat(a, b, cv::FM_RANSAC, options_.ransac_threshold_px, options_.ransac_confidence, mask);
  if (!F.empty() && mask.size() == from.size()) inlier = mask;
  return inlier;
}

int FeatureTracker::rejectByRansac(std::vector<Track>* tracks) const {
  // from the previous image
  std::vector<Eigen::Vector2d> from, to;
  for (const Track& t : *tracks) from.push_back(t.xy_prev), to.push_back(t.xy);
  std::vector<uint8_t> keep = epipolarInliers(from, to);
  // and from the last keyframe, over a longer baseline, where a track's drift has built up
  if (options_.keyframe_ransac) {
    from.clear();
    to.clear();
    std::vector<size_t> index;
    for (size_t i = 0; i < tracks->size(); ++i) {
      const auto kf = keyframe_xy_.find((*tracks)[i].id);
      if (!keep[i] || kf == keyframe_xy_.end()) continue;
      index.push_back(i);
      from.push_back(kf->second);
      to.push_back((*tracks)[i].xy);
    }
    const std::vector<uint8_t> inlier = epipolarInliers(from, to);
    for (size_t j = 0; j < index.size(); ++j) keep[index[j]] = keep[index[j]] && inlier[j];
  }
  const size_t before = tracks->size();
  keepSelected(keep, tracks);
  return static_cast<int>(before - tracks->size());
}

int FeatureTracker::detect(const cv::Mat& half, std::vector<Track>* tracks) {
  // On the half-resolution image: a quarter of the cost of the Shi-Tomasi image, the corners KLT
  // can follow at its window size all the same. Pixel (i, j) there covers (2i, 2j)..(2i+1, 2j+1).
  const int b = (options_.border_px + 1) / 2;
  cv::Mat mask(half.size(), CV_8UC1, cv::Scalar(0));
  mask(cv::Rect(b, b, std::max(0, half.cols - 2 * b), std::max(0, half.rows - 2 * b))).setTo(255);
  // Tracks by increasing id are tracks by decreasing length (every live track was seen in every
  // image since it was found): a track within min_distance of a longer one is dropped, as VINS does.
  const int radius = static_cast<int>(std::lround(0.5 * options_.min_distance_px));
  std::vector<uint8_t> keep(tracks->size(), 0);
  for (size_t i = 0; i < tracks->size(); ++i) {
    const cv::Point p(std::clamp(static_cast<int>((*tracks)[i].pixel.x * 0.5f), 0, half.cols - 1),
                      std::clamp(static_cast<int>((*tracks)[i].pixel.y * 0.5f), 0, half.rows - 1));
    if (mask.at<uint8_t>(p) == 0) continue;
    keep[i] = 1;
    cv::circle(mask, p, radius, cv::Scalar(0), cv::FILLED);
  }
  keepSelected(keep, tracks);

  const int wanted = options_.max_features - static_cast<int>(tracks->size());
  if (wanted <= 0) return 0;
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(half, corners, wanted, options_.quality_level, 0.5 * options_.min_distance_px, mask);
  for (const cv::Point2f& c : corners) {
    const cv::Point2f pixel(2.0f * c.x + 0.5f, 2.0f * c.y + 0.5f);
    const Eigen::Vector2d xy = normalised(pixel);
    tracks->push_back(Track{next_id_++, 1, pixel, xy, xy});
  }
  return static_cast<int>(corners.size());
}

double FeatureTracker::parallaxSinceKeyframe(const std::vector<Track>& tracks) const {
  double sum = 0.0;
  int n = 0;
  for (const Track& t : tracks) {
    const auto kf = keyframe_xy_.find(t.id);
    if (kf == keyframe_xy_.end()) continue;
    const Vec3 r = R_cur_keyframe_ * Vec3(kf->second.x(), kf->second.y(), 1.0);  // the keyframe's ray, rotated here
    if (!(r.z() > 1e-6)) continue;
    sum += focal_ * (t.xy - r.head<2>() / r.z()).norm();
    ++n;
  }
  return n > 0 ? sum / n : 0.0;
}

}  // namespace livo::vio_feature
