#include "livo/report/map_views.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <opencv2/imgproc.hpp>

namespace livo::report {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
const cv::Scalar kPathColour(255, 229, 0);  // BGR: cyan
const cv::Scalar kPathOutline(40, 40, 40);
const cv::Scalar kStartColour(60, 180, 60);
const cv::Scalar kEndColour(40, 40, 220);

double fraction(std::vector<double>& v, double q) {
  const size_t k = std::min(v.size() - 1, static_cast<size_t>(std::floor(q * static_cast<double>(v.size() - 1) + 0.5)));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

// The square of `size` pixels a splat covers around pixel (u, v): [lo, lo + size).
int splatStart(int centre, int size) { return centre - (size - 1) / 2; }

// Darkens pixels that lie behind their neighbours (eye-dome lighting). `depth`: larger is farther,
// infinite where no point; `log_depth`: compare logarithms (a perspective depth), else metres.
void eyeDomeShade(cv::Mat& image, const cv::Mat1f& depth, double strength, bool log_depth) {
  if (strength <= 0.0) return;
  constexpr int kStep = 2;
  const int offsets[8][2] = {{-kStep, 0},      {kStep, 0},     {0, -kStep},     {0, kStep},
                             {-kStep, -kStep}, {kStep, kStep}, {-kStep, kStep}, {kStep, -kStep}};
  cv::Mat1f d(depth.size(), kInf);
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u) {
      const float z = depth(v, u);
      if (std::isfinite(z)) d(v, u) = log_depth ? std::log2(std::max(z, 1e-3f)) : z;
    }
  for (int v = 0; v < d.rows; ++v)
    for (int u = 0; u < d.cols; ++u) {
      const float z = d(v, u);
      if (!std::isfinite(z)) continue;
      double obscurance = 0.0;
      for (const auto& o : offsets) {
        const int a = u + o[0], b = v + o[1];
        if (a < 0 || b < 0 || a >= d.cols || b >= d.rows || !std::isfinite(d(b, a))) continue;
        obscurance += std::max(0.0f, z - d(b, a));
      }
      const double shade = std::exp(-strength * obscurance);
      cv::Vec3b& px = image.at<cv::Vec3b>(v, u);
      for (int c = 0; c < 3; ++c) px[c] = static_cast<uint8_t>(std::lround(px[c] * shade));
    }
}

void drawMarkers(cv::Mat& image, const cv::Point2d& start, const cv::Point2d& end) {
  for (const auto& [p, colour] : {std::make_pair(start, kStartColour), std::make_pair(end, kEndColour)}) {
    const cv::Point c(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)));
    cv::circle(image, c, 9, kPathOutline, cv::FILLED, cv::LINE_AA);
    cv::circle(image, c, 7, colour, cv::FILLED, cv::LINE_AA);
  }
}

void drawPolylines(cv::Mat& image, const std::vector<std::vector<cv::Point>>& lines) {
  cv::polylines(image, lines, false, kPathOutline, 5, cv::LINE_AA);
  cv::polylines(image, lines, false, kPathColour, 2, cv::LINE_AA);
}

cv::Point fixedPoint(const cv::Point2d& p) {  // OpenCV's line functions take whole pixels
  return {static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y))};
}

}  // namespace

Box3 percentileBox(const std::vector<Vec3>& points, double lower, double upper) {
  std::vector<double> axis[3];
  for (const Vec3& p : points)
    if (p.allFinite())
      for (int a = 0; a < 3; ++a) axis[a].push_back(p[a]);
  if (axis[0].empty()) throw std::invalid_argument("percentileBox: no finite point");
  Box3 box;
  for (int a = 0; a < 3; ++a) {
    box.min[a] = fraction(axis[a], lower);
    box.max[a] = fraction(axis[a], upper);
  }
  return box;
}

Box3 withTrajectory(Box3 box, const Trajectory& trajectory) {
  for (const StampedPose& p : trajectory) {
    const Vec3 t = p.pose.translation();
    if (!t.allFinite()) continue;
    box.min = box.min.cwiseMin(t);
    box.max = box.max.cwiseMax(t);
  }
  return box;
}

TopViewFrame topViewFrame(const Box3& box, int long_side_px, int min_short_px, double margin) {
  const Vec3 c = box.centre();
  double w = std::max(box.size().x(), 1.0), h = std::max(box.size().y(), 1.0);
  const double pad = margin * std::max(w, h);
  w += 2 * pad, h += 2 * pad;
  TopViewFrame f;
  f.metres_per_pixel = std::max(w, h) / long_side_px;
  const double min_short = min_short_px * f.metres_per_pixel;
  w = std::max(w, min_short), h = std::max(h, min_short);
  f.width = static_cast<int>(std::ceil(w / f.metres_per_pixel - 1e-9));
  f.height = static_cast<int>(std::ceil(h / f.metres_per_pixel - 1e-9));
  f.x_min = c.x() - 0.5 * f.width * f.metres_per_pixel;
  f.y_max = c.y() + 0.5 * f.height * f.metres_per_pixel;
  return f;
}

bool PerspectiveView::project(const Vec3& p, cv::Point2d* pixel, double* depth) const {
  const Vec3 q = R_C_W * (p - position);
  if (!(q.z() > kNear)) return false;
  *pixel = {f * q.x() / q.z() + cx, f * q.y() / q.z() + cy};
  *depth = q.z();
  return true;
}

Eigen::Vector2d majorHorizontalAxis(const std::vector<Vec3>& points) {
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  size_t n = 0;
  for (const Vec3& p : points)
    if (p.allFinite()) mean += p.head<2>(), ++n;
  if (n < 2) return Eigen::Vector2d::UnitX();
  mean /= static_cast<double>(n);
  Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();
  for (const Vec3& p : points)
    if (p.allFinite()) {
      const Eigen::Vector2d d = p.head<2>() - mean;
      cov += d * d.transpose();
    }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(cov);
  Eigen::Vector2d axis = eig.eigenvectors().col(1);  // eigenvalues ascending: the larger
  if (!axis.allFinite() || axis.norm() < 0.5) return Eigen::Vector2d::UnitX();
  const int larger = std::abs(axis.x()) >= std::abs(axis.y()) ? 0 : 1;
  if (axis[larger] < 0) axis = -axis;
  return axis.normalized();
}

PerspectiveView obliqueView(const Box3& box, const Eigen::Vector2d& major_axis, int width, double elevation_deg,
                            double azimuth_deg, double distance_factor) {
  const double deg = M_PI / 180.0;
  // the camera stands on the side across the major axis, turned by the azimuth
  const Eigen::Vector2d across(-major_axis.y(), major_axis.x());
  const double a = azimuth_deg * deg, e = elevation_deg * deg;
  const Eigen::Vector2d side(std::cos(a) * across.x() - std::sin(a) * across.y(),
                             std::sin(a) * across.x() + std::cos(a) * across.y());
  const Vec3 centre = box.centre();
  const double radius = std::max(0.5 * box.size().norm(), 0.5);
  const Vec3 back(std::cos(e) * side.x(), std::cos(e) * side.y(), std::sin(e));  // from the centre to the camera
  PerspectiveView v;
  v.position = centre + distance_factor * radius * back;
  const Vec3 forward = -back;
  const Vec3 right = forward.cross(Vec3::UnitZ()).normalized();
  const Vec3 down = forward.cross(right);
  v.R_C_W.row(0) = right.transpose();
  v.R_C_W.row(1) = down.transpose();
  v.R_C_W.row(2) = forward.transpose();

  double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
  for (int k = 0; k < 8; ++k) {
    const Vec3 corner((k & 1) ? box.max.x() : box.min.x(), (k & 2) ? box.max.y() : box.min.y(),
                      (k & 4) ? box.max.z() : box.min.z());
    const Vec3 q = v.R_C_W * (corner - v.position);
    xmin = std::min(xmin, q.x() / q.z()), xmax = std::max(xmax, q.x() / q.z());
    ymin = std::min(ymin, q.y() / q.z()), ymax = std::max(ymax, q.y() / q.z());
  }
  const double aspect = (ymax - ymin) / std::max(xmax - xmin, 1e-9);
  v.width = width;
  v.height = static_cast<int>(std::lround(std::clamp(aspect, 0.45, 0.8) * width));
  constexpr double kMargin = 0.04;
  v.f = std::min(v.width * (1 - 2 * kMargin) / std::max(xmax - xmin, 1e-9),
                 v.height * (1 - 2 * kMargin) / std::max(ymax - ymin, 1e-9));
  v.cx = 0.5 * v.width - v.f * 0.5 * (xmin + xmax);
  v.cy = 0.5 * v.height - v.f * 0.5 * (ymin + ymax);
  return v;
}

cv::Mat cropToContent(const cv::Mat& image, const cv::Vec3b& background, int margin_px) {
  int x0 = image.cols, y0 = image.rows, x1 = -1, y1 = -1;
  for (int y = 0; y < image.rows; ++y) {
    const cv::Vec3b* row = image.ptr<cv::Vec3b>(y);
    for (int x = 0; x < image.cols; ++x) {
      if (row[x] == background) continue;
      x0 = std::min(x0, x), x1 = std::max(x1, x);
      y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
  }
  if (x1 < 0) return image;
  x0 = std::max(0, x0 - margin_px), y0 = std::max(0, y0 - margin_px);
  x1 = std::min(image.cols - 1, x1 + margin_px), y1 = std::min(image.rows - 1, y1 + margin_px);
  return image(cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1)).clone();
}

ColouredPoints pointsBelowCut(const ColouredPoints& points, const TrajectoryHeight& height, double cut_above_m) {
  ColouredPoints out;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points.position[i];
    if (!p.allFinite() || p.z() > height.at(p.x(), p.y()) + cut_above_m) continue;
    out.position.push_back(p);
    out.rgb.push_back(points.rgb[i]);
  }
  return out;
}

cv::Mat renderTopView(const ColouredPoints& points, const TopViewFrame& frame, const SplatStyle& style,
                      cv::Mat1f* top_z) {
  cv::Mat image(frame.height, frame.width, CV_8UC3,
                cv::Scalar(style.background[0], style.background[1], style.background[2]));
  cv::Mat1f depth(frame.height, frame.width, kInf);  // -z: the highest point is the nearest
  const int size =
      std::clamp(static_cast<int>(std::lround(style.point_size_m / frame.metres_per_pixel)), 1, style.max_px);
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points.position[i];
    if (!p.allFinite()) continue;
    const cv::Point2d px = frame.pixel(p.x(), p.y());
    if (!(px.x > -size && px.y > -size && px.x < frame.width + size && px.y < frame.height + size)) continue;
    const int u0 = splatStart(static_cast<int>(std::floor(px.x)), size);
    const int v0 = splatStart(static_cast<int>(std::floor(px.y)), size);
    const float d = -p.z();
    const cv::Vec3b bgr(points.rgb[i][2], points.rgb[i][1], points.rgb[i][0]);
    for (int v = std::max(v0, 0); v < std::min(v0 + size, frame.height); ++v)
      for (int u = std::max(u0, 0); u < std::min(u0 + size, frame.width); ++u)
        if (d < depth(v, u)) {
          depth(v, u) = d;
          image.at<cv::Vec3b>(v, u) = bgr;
        }
  }
  eyeDomeShade(image, depth, style.edl_strength, false);
  if (top_z) {
    *top_z = cv::Mat1f(depth.size(), std::numeric_limits<float>::quiet_NaN());
    for (int v = 0; v < depth.rows; ++v)
      for (int u = 0; u < depth.cols; ++u)
        if (std::isfinite(depth(v, u))) (*top_z)(v, u) = -depth(v, u);
  }
  return image;
}

cv::Mat renderPerspective(const ColouredPoints& points, const PerspectiveView& view, const SplatStyle& style,
                          cv::Mat1f* depth_out) {
  cv::Mat image(view.height, view.width, CV_8UC3,
                cv::Scalar(style.background[0], style.background[1], style.background[2]));
  cv::Mat1f depth(view.height, view.width, kInf);
  for (size_t i = 0; i < points.size(); ++i) {
    cv::Point2d px;
    double z = 0.0;
    if (!points.position[i].allFinite() || !view.project(points.position[i].cast<double>(), &px, &z)) continue;
    const int size = std::clamp(static_cast<int>(std::lround(style.point_size_m * view.f / z)), 1, style.max_px);
    if (!(px.x > -size && px.y > -size && px.x < view.width + size && px.y < view.height + size)) continue;
    const int u0 = splatStart(static_cast<int>(std::floor(px.x)), size);
    const int v0 = splatStart(static_cast<int>(std::floor(px.y)), size);
    const cv::Vec3b bgr(points.rgb[i][2], points.rgb[i][1], points.rgb[i][0]);
    const float d = static_cast<float>(z);
    for (int v = std::max(v0, 0); v < std::min(v0 + size, view.height); ++v)
      for (int u = std::max(u0, 0); u < std::min(u0 + size, view.width); ++u)
        if (d < depth(v, u)) {
          depth(v, u) = d;
          image.at<cv::Vec3b>(v, u) = bgr;
        }
  }
  eyeDomeShade(image, depth, style.edl_strength, true);
  if (depth_out) *depth_out = depth;
  return image;
}

std::vector<std::pair<size_t, size_t>> pathPieces(const Trajectory& trajectory,
                                                  const std::vector<double>& reset_stamps) {
  std::vector<double> steps;
  for (size_t i = 1; i < trajectory.size(); ++i) {
    const double d = (trajectory[i].pose.translation() - trajectory[i - 1].pose.translation()).norm();
    if (std::isfinite(d)) steps.push_back(d);
  }
  const double jump = std::max(5.0, steps.empty() ? 0.0 : 20.0 * fraction(steps, 0.5));
  std::vector<double> resets = reset_stamps;
  std::sort(resets.begin(), resets.end());
  std::vector<std::pair<size_t, size_t>> pieces;
  auto close = [&](size_t end) {
    if (!pieces.empty() && pieces.back().second == 0) pieces.back().second = end;
  };
  for (size_t i = 0; i < trajectory.size(); ++i) {
    if (!trajectory[i].pose.translation().allFinite()) {
      close(i);
      continue;
    }
    bool start = pieces.empty() || pieces.back().second != 0;  // none open
    if (!start) {
      const double t0 = trajectory[i - 1].stamp, t1 = trajectory[i].stamp;
      const auto r = std::upper_bound(resets.begin(), resets.end(), t0);  // a reset in (t0, t1]
      start = (r != resets.end() && *r <= t1) ||
              (trajectory[i].pose.translation() - trajectory[i - 1].pose.translation()).norm() > jump;
      if (start) close(i);
    }
    if (start) pieces.emplace_back(i, 0);
  }
  close(trajectory.size());
  return pieces;
}

Trajectory newestEpoch(const Trajectory& trajectory, const std::vector<double>& reset_stamps) {
  if (reset_stamps.empty()) return trajectory;
  const double last = *std::max_element(reset_stamps.begin(), reset_stamps.end());
  Trajectory out;
  for (const StampedPose& p : trajectory)
    if (p.stamp >= last) out.push_back(p);
  return out;
}

namespace {
Vec3 position(const Trajectory& t, size_t i) { return t[i].pose.translation(); }
}  // namespace

void drawPathTopView(cv::Mat& image, const Trajectory& trajectory, const TopViewFrame& frame,
                     const std::vector<double>& reset_stamps) {
  const auto pieces = pathPieces(trajectory, reset_stamps);
  if (pieces.empty()) return;
  std::vector<std::vector<cv::Point>> lines;
  for (const auto& [begin, end] : pieces) {
    lines.emplace_back();
    for (size_t i = begin; i < end; ++i) {
      const cv::Point q = fixedPoint(frame.pixel(position(trajectory, i).x(), position(trajectory, i).y()));
      if (lines.back().empty() || lines.back().back() != q) lines.back().push_back(q);
    }
  }
  drawPolylines(image, lines);
  const Vec3 a = position(trajectory, pieces.front().first);
  const Vec3 b = position(trajectory, pieces.back().second - 1);
  drawMarkers(image, frame.pixel(a.x(), a.y()), frame.pixel(b.x(), b.y()));
}

void drawPathPerspective(cv::Mat& image, const cv::Mat1f& depth, const Trajectory& trajectory,
                         const PerspectiveView& view, const std::vector<double>& reset_stamps) {
  const auto pieces = pathPieces(trajectory, reset_stamps);
  if (pieces.empty()) return;
  // Visible where no drawn point is clearly in front of it.
  auto visible = [&](const Vec3& p, cv::Point* out) {
    cv::Point2d px;
    double z = 0.0;
    if (!view.project(p, &px, &z)) return false;
    const int u = static_cast<int>(std::floor(px.x)), v = static_cast<int>(std::floor(px.y));
    if (u < 0 || v < 0 || u >= depth.cols || v >= depth.rows) return false;
    *out = fixedPoint(px);
    return !(depth(v, u) < z - 0.3 - 0.02 * z);
  };
  std::vector<std::vector<cv::Point>> lines;
  for (const auto& [begin, end] : pieces) {
    lines.emplace_back();
    for (size_t i = begin; i < end; ++i) {
      // samples about a pixel apart along the segment to the next position
      const Vec3 a = position(trajectory, i), b = i + 1 < end ? position(trajectory, i + 1) : a;
      cv::Point2d pa, pb;
      double za = 0.0, zb = 0.0;
      int n = 1;
      if (view.project(a, &pa, &za) && view.project(b, &pb, &zb))
        n = std::clamp(static_cast<int>(std::ceil(cv::norm(pb - pa))), 1, 2000);
      for (int k = 0; k < n; ++k) {
        cv::Point q;
        if (visible(a + (b - a) * (static_cast<double>(k) / n), &q)) {
          if (lines.back().empty() || lines.back().back() != q) lines.back().push_back(q);
        } else if (!lines.back().empty()) {
          lines.emplace_back();
        }
      }
    }
    lines.emplace_back();
  }
  lines.erase(std::remove_if(lines.begin(), lines.end(), [](const auto& l) { return l.size() < 2; }), lines.end());
  drawPolylines(image, lines);
  cv::Point2d start, finish;
  double z = 0.0;
  if (view.project(position(trajectory, pieces.front().first), &start, &z) &&
      view.project(position(trajectory, pieces.back().second - 1), &finish, &z))
    drawMarkers(image, start, finish);
}

}  // namespace livo::report
