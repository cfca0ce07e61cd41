#include "livo/vio/camera_rotation_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

namespace livo::vio {

namespace {
constexpr int kMaxIterations = 10;
constexpr double kStepDone = 1e-8;        // rad
constexpr double kNumericStep = 1e-6;     // rad, central differences of the Sampson error
constexpr double kInlierCauchyScales = 3.0;
constexpr int kSolveEvery = 10;           // pairs
constexpr double kTopUpFraction = 0.7;

/// A pair's relative pose C0_T_C1 = (R, t) through the extrinsic rotation R_I_C, and R_C0_W.
struct RelativePose {
  Mat3 R, R_C0_W;
  Vec3 t;
  Vec3 c_W;  // c1 − c0, world
};

RelativePose relativePose(const TrackPair& p, const Mat3& R_I_C, const Vec3& t_I_C) {
  RelativePose r;
  r.R_C0_W = (p.T_W_I0.linear() * R_I_C).transpose();
  r.R = r.R_C0_W * (p.T_W_I1.linear() * R_I_C);
  r.c_W = p.T_W_I1 * t_I_C - p.T_W_I0 * t_I_C;
  r.t = r.R_C0_W * r.c_W;
  return r;
}

/// Track i's essential matrix (its rows' baseline under a rolling shutter).
Mat3 trackEssential(const TrackPair& p, const RelativePose& r, size_t i) {
  if (p.readout_shift_W.empty()) return so3::hat(r.t) * r.R;
  return so3::hat(r.t + r.R_C0_W * p.readout_shift_W[i]) * r.R;
}

Vec3 normalised(const Vec3& ray) { return ray / ray.z(); }
}  // namespace

double RotationEstimate::maxStdDeg() const {
  const Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (covariance + covariance.transpose()));
  return std::sqrt(std::max(0.0, es.eigenvalues().maxCoeff())) * 180.0 / M_PI;
}

double sampsonError(const Vec3& x0, const Vec3& x1, const Mat3& E) {
  const Vec3 Ex1 = E * x1, Etx0 = E.transpose() * x0;
  const double d = Ex1.head<2>().squaredNorm() + Etx0.head<2>().squaredNorm();
  return d > 0.0 ? x0.dot(Ex1) / std::sqrt(d) : 0.0;
}

RotationEstimate solveCameraRotation(const std::deque<TrackPair>& pairs, const Pose3& T_I_C_rig, const Vec3& initial,
                                     double cauchy, double focal) {
  RotationEstimate e;
  e.correction = initial;
  e.pairs = static_cast<int>(pairs.size());
  e.covariance = Mat3::Identity();  // (1 rad)²: unknown until solved
  const Mat3 R_rig = T_I_C_rig.linear();
  const Vec3 t_I_C = T_I_C_rig.translation();
  const double c2 = cauchy * cauchy;
  for (int it = 0; it < kMaxIterations; ++it) {
    // Sampson errors and their numeric Jacobian at e.correction; per pair its score Σ w J r
    Mat3 H = Mat3::Zero();
    Vec3 g = Vec3::Zero();
    std::vector<Vec3> scores;
    scores.reserve(pairs.size());
    double sum_r2 = 0.0;
    int n = 0, inliers = 0;
    for (const TrackPair& p : pairs) {
      RelativePose rel[7];  // at φ, then φ ± h along each axis
      for (int k = 0; k < 7; ++k) {
        Vec3 phi = e.correction;
        if (k > 0) phi[(k - 1) / 2] += (k % 2 == 1 ? kNumericStep : -kNumericStep);
        rel[k] = relativePose(p, R_rig * so3::Exp(phi), t_I_C);
      }
      Vec3 score = Vec3::Zero();
      for (size_t i = 0; i < p.x0.size(); ++i) {
        const double r = sampsonError(p.x0[i], p.x1[i], trackEssential(p, rel[0], i));
        Vec3 J;
        for (int a = 0; a < 3; ++a)
          J[a] = (sampsonError(p.x0[i], p.x1[i], trackEssential(p, rel[1 + 2 * a], i)) -
                  sampsonError(p.x0[i], p.x1[i], trackEssential(p, rel[2 + 2 * a], i))) /
                 (2.0 * kNumericStep);
        const double w = 1.0 / (1.0 + r * r / c2);
        H += w * J * J.transpose();
        g += w * J * r;
        score += w * J * r;
        ++n;
        if (std::abs(r) < kInlierCauchyScales * cauchy) sum_r2 += r * r, ++inliers;
      }
      scores.push_back(score);
    }
    e.residuals = n;
    e.rms_px = inliers > 0 ? std::sqrt(sum_r2 / inliers) * focal : 0.0;
    const Eigen::LDLT<Mat3> ldlt(H);
    if (n < 3 || ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return e;
    const Vec3 step = -ldlt.solve(g);
    // cluster-robust covariance at this linearisation: H⁻¹ (Σ_k s_k s_kᵀ) H⁻¹ · K / (K − 1)
    Mat3 B = Mat3::Zero();
    for (const Vec3& s : scores) B += s * s.transpose();
    const double K = static_cast<double>(scores.size());
    const Mat3 Hinv = ldlt.solve(Mat3::Identity());
    e.covariance = Hinv * B * Hinv * (K > 1.0 ? K / (K - 1.0) : 1.0);
    e.correction += step;
    if (step.norm() < kStepDone) break;
  }
  return e;
}

CameraRotationCalibration::CameraRotationCalibration(const RotationCalibrationOptions& options,
                                                     const CameraProjection& camera, const Pose3& T_I_C_rig)
    : options_(options), camera_(camera), T_I_C_rig_(T_I_C_rig) {}

void CameraRotationCalibration::reset() {
  restartTracks();
  pairs_.clear();
  pairs_since_solve_ = 0;
  pairs_closed_ = 0;
  estimate_ = RotationEstimate();
}

void CameraRotationCalibration::restartTracks() {
  key_utime_ = -1;
  key_ray_.clear();
  key_dt_.clear();
  key_px_.clear();
  cur_px_.clear();
  prev_pyramid_.clear();
}

void CameraRotationCalibration::applyCorrection(const Pose3& T_corrected_odom) {
  key_T_W_I_ = T_corrected_odom * key_T_W_I_;
  key_v_W_ = T_corrected_odom.linear() * key_v_W_;
}

FusedCameraRotation fuseWithRig(const Pose3& T_I_C_rig, const RotationEstimate& estimate, double rig_std) {
  FusedCameraRotation f;
  const Mat3 info_pairs = estimate.covariance.inverse();
  // rig_std 0: no stated uncertainty, the estimate is taken whole
  const Mat3 info = info_pairs + (rig_std > 0.0 ? Mat3(Mat3::Identity() / (rig_std * rig_std)) : Mat3(Mat3::Zero()));
  f.covariance = info.inverse();
  f.correction = f.covariance * (info_pairs * estimate.correction);
  f.T_I_C = T_I_C_rig;
  f.T_I_C.linear() = T_I_C_rig.linear() * so3::Exp(f.correction);
  return f;
}

std::string cameraRotationOverlay(const FusedCameraRotation& fused, const RotationEstimate& estimate, int pairs_closed,
                                  double rig_std) {
  constexpr double kDeg = 180.0 / M_PI;
  const auto stds = [&](const Mat3& P) {
    std::ostringstream s;
    s << std::fixed << std::setprecision(3) << std::sqrt(P(0, 0)) * kDeg << " / " << std::sqrt(P(1, 1)) * kDeg << " / "
      << std::sqrt(P(2, 2)) * kDeg;
    return s.str();
  };
  const Vec3 e = estimate.correction * kDeg, c = fused.correction * kDeg;
  const Eigen::Quaterniond q(fused.T_I_C.linear());
  std::ostringstream s;
  s << std::fixed << std::setprecision(4);
  s << "# livo-vio: the camera's rotation against the LiDAR-inertial body, from " << estimate.pairs << " image pairs (the newest of "
    << pairs_closed << "), Sampson RMS " << std::setprecision(2) << estimate.rms_px << " px.\n"
    << std::setprecision(4) << "# The pairs turn the rig's camera by (" << e.x() << ", " << e.y() << ", " << e.z()
    << ") deg in its own frame, 1-sigma " << stds(estimate.covariance) << " deg;\n"
    << "# fused with the rig's rotation at 1-sigma " << rig_std * kDeg << " deg: (" << c.x() << ", " << c.y() << ", "
    << c.z() << ") deg, 1-sigma " << stds(fused.covariance) << " deg.\n"
    << "# Merge it over the config (livo-config merge CONFIG --overlay THIS, scripts/run_pipeline.sh --overlay THIS).\n"
    << std::setprecision(9) << "# As a rig entry: T_I_C: {translation: [" << fused.T_I_C.translation().x() << ", "
    << fused.T_I_C.translation().y() << ", " << fused.T_I_C.translation().z() << "], rotation: [" << q.w() << ", "
    << q.x() << ", " << q.y() << ", " << q.z() << "]}\n";
  s << "rig:\n  camera:\n    T_I_C: [";
  const Eigen::Matrix4d M = fused.T_I_C.matrix();
  for (int r = 0; r < 4; ++r)
    for (int col = 0; col < 4; ++col) s << (r || col ? (col ? ", " : ",\n            ") : "") << M(r, col);
  s << "]\n";
  return s.str();
}

bool CameraRotationCalibration::converged() const {
  return estimate_.pairs >= options_.min_pairs && estimate_.maxStdDeg() <= options_.apply_std_deg;
}

Pose3 CameraRotationCalibration::calibratedExtrinsic() const {
  Pose3 T = T_I_C_rig_;
  T.linear() = T_I_C_rig_.linear() * so3::Exp(estimate_.correction);
  return T;
}

Vec3 CameraRotationCalibration::rayAtStamp(const cv::Point2f& px, const RollingShutter& shutter) const {
  const Vec3 ray = camera_.pixelRay(Eigen::Vector2d(px.x, px.y));
  if (!shutter.active()) return ray;
  // the row's camera, R_I_Cᵀ Exp(ω dt) R_I_C, turned back to the stamp's
  const Mat3& R = T_I_C_rig_.linear();
  return R.transpose() * (shutter.rotationSince(shutter.rowTime(px.y)) * (R * ray));
}

void CameraRotationCalibration::startPair(const cv::Mat& grey, int64_t utime, const Pose3& T_W_I, const Vec3& v_W,
                                          const RollingShutter& shutter) {
  // the tracks that survived go on; below kTopUpFraction of max_corners, corners fill the image
  // up to max_corners away from them (the detector costs as much as the tracking)
  key_px_ = cur_px_;
  const int missing = options_.max_corners - static_cast<int>(cur_px_.size());
  if (static_cast<double>(cur_px_.size()) < kTopUpFraction * options_.max_corners && missing > 0) {
    cv::Mat mask(grey.size(), CV_8UC1, cv::Scalar(255));
    const int radius = static_cast<int>(std::lround(options_.min_corner_distance_px));
    for (const cv::Point2f& p : cur_px_) cv::circle(mask, p, radius, cv::Scalar(0), -1);
    std::vector<cv::Point2f> corners;
    cv::goodFeaturesToTrack(grey, corners, missing, options_.corner_quality, options_.min_corner_distance_px, mask);
    key_px_.insert(key_px_.end(), corners.begin(), corners.end());
  }
  cur_px_ = key_px_;
  key_ray_.resize(key_px_.size());
  key_dt_.resize(key_px_.size());
  for (size_t i = 0; i < key_px_.size(); ++i) {
    key_ray_[i] = rayAtStamp(key_px_[i], shutter);
    key_dt_[i] = shutter.rowTime(key_px_[i].y);
  }
  key_utime_ = utime;
  key_T_W_I_ = T_W_I;
  key_v_W_ = v_W;
}

bool CameraRotationCalibration::addImage(const cv::Mat& grey, int64_t utime, const Pose3& T_W_I, const Vec3& v_W,
                                         const RollingShutter& shutter) {
  const cv::Size window(options_.klt_window_px, options_.klt_window_px);
  std::vector<cv::Mat> pyramid;
  cv::buildOpticalFlowPyramid(grey, pyramid, window, options_.klt_levels);
  if (key_utime_ < 0 || prev_pyramid_.empty() || utime <= key_utime_) {
    cur_px_.clear();
    startPair(grey, utime, T_W_I, v_W, shutter);
    prev_pyramid_ = std::move(pyramid);
    return false;
  }

  // track from the last image, and back: a corner that does not come back to itself is lost
  if (!cur_px_.empty()) {
    std::vector<cv::Point2f> fwd, back;
    std::vector<uchar> st_fwd, st_back;
    std::vector<float> err;
    const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01);
    cv::calcOpticalFlowPyrLK(prev_pyramid_, pyramid, cur_px_, fwd, st_fwd, err, window, options_.klt_levels, stop);
    back = cur_px_;
    cv::calcOpticalFlowPyrLK(pyramid, prev_pyramid_, fwd, back, st_back, err, window, options_.klt_levels, stop,
                             cv::OPTFLOW_USE_INITIAL_FLOW);
    const float max_err2 = static_cast<float>(options_.max_track_error_px * options_.max_track_error_px);
    size_t kept = 0;
    for (size_t i = 0; i < cur_px_.size(); ++i) {
      const cv::Point2f d = back[i] - cur_px_[i];
      const bool inside = fwd[i].x >= 0.0f && fwd[i].y >= 0.0f && fwd[i].x <= grey.cols - 1.0f && fwd[i].y <= grey.rows - 1.0f;
      if (!st_fwd[i] || !st_back[i] || !inside || d.dot(d) > max_err2) continue;
      key_px_[kept] = key_px_[i];
      key_ray_[kept] = key_ray_[i];
      key_dt_[kept] = key_dt_[i];
      cur_px_[kept] = fwd[i];
      ++kept;
    }
    key_px_.resize(kept);
    key_ray_.resize(kept);
    key_dt_.resize(kept);
    cur_px_.resize(kept);
  }
  prev_pyramid_ = std::move(pyramid);

  const int min_tracks = options_.min_tracks;
  const double baseline = (T_W_I.translation() - key_T_W_I_.translation()).norm();
  bool solved = false;
  if (baseline >= options_.min_baseline && static_cast<int>(cur_px_.size()) >= min_tracks) {
    TrackPair pair;
    pair.T_W_I0 = key_T_W_I_;
    pair.T_W_I1 = T_W_I;
    // tracks on moving objects and bad tracks out: the essential matrix's RANSAC inliers
    std::vector<cv::Point2d> x0(cur_px_.size()), x1(cur_px_.size());
    std::vector<Vec3> h0(cur_px_.size()), h1(cur_px_.size());
    for (size_t i = 0; i < cur_px_.size(); ++i) {
      h0[i] = normalised(key_ray_[i]);
      h1[i] = normalised(rayAtStamp(cur_px_[i], shutter));
      x0[i] = cv::Point2d(h0[i].x(), h0[i].y());
      x1[i] = cv::Point2d(h1[i].x(), h1[i].y());
    }
    const double focal = camera_.rig().fx;
    std::vector<uchar> inlier;
    const cv::Mat E = cv::findEssentialMat(x0, x1, cv::Mat::eye(3, 3, CV_64F), cv::RANSAC, 0.999,
                                           options_.ransac_threshold_px / focal, 1000, inlier);
    if (!E.empty() && inlier.size() == cur_px_.size()) {
      for (size_t i = 0; i < cur_px_.size(); ++i)
        if (inlier[i]) {
          pair.x0.push_back(h0[i]);
          pair.x1.push_back(h1[i]);
          if (shutter.active()) pair.readout_shift_W.push_back(v_W * shutter.rowTime(cur_px_[i].y) - key_v_W_ * key_dt_[i]);
        }
    }
    if (static_cast<int>(pair.x0.size()) >= min_tracks) {
      pairs_.push_back(std::move(pair));
      ++pairs_closed_;
      while (static_cast<int>(pairs_.size()) > options_.window_pairs) pairs_.pop_front();
      // solved again every kSolveEvery pairs: it moves slowly, and the window is hundreds of pairs
      if (++pairs_since_solve_ >= kSolveEvery) {
        estimate_ = solveCameraRotation(pairs_, T_I_C_rig_, estimate_.correction, options_.cauchy_px / focal, focal);
        pairs_since_solve_ = 0;
        solved = true;
      }
    }
    startPair(grey, utime, T_W_I, v_W, shutter);
  } else if (static_cast<int>(cur_px_.size()) < min_tracks || 1e-6 * static_cast<double>(utime - key_utime_) > options_.max_pair_time) {
    startPair(grey, utime, T_W_I, v_W, shutter);
  }
  return solved;
}

}  // namespace livo::vio
