#include "livo/report/picture_annotations.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "livo/text_format.hpp"

namespace livo::report {

namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
const cv::Scalar kInk(30, 30, 30);
const cv::Scalar kPaper(255, 255, 255);

// Text and marks grow with the picture: 1 when its longer side is 1600 pixels (readable when a
// browser shows it 1000 pixels wide), never below 0.75.
double scaleOf(const cv::Mat& image) { return std::clamp(std::max(image.cols, image.rows) / 1600.0, 0.75, 2.0); }
int px(double v, double scale) { return static_cast<int>(std::lround(v * scale)); }

cv::Size textSize(const std::string& s, double scale) {
  int baseline = 0;
  return cv::getTextSize(s, kFont, 0.9 * scale, 2, &baseline);
}

void text(cv::Mat& image, const std::string& s, cv::Point at, double scale) {
  cv::putText(image, s, at, kFont, 0.9 * scale, kInk, 2, cv::LINE_AA);
}

std::string number(double v) {  // at most two decimals, no trailing zeros
  std::string s = formatFixed(v, 2);
  while (s.find('.') != std::string::npos && (s.back() == '0' || s.back() == '.')) {
    const bool dot = s.back() == '.';
    s.pop_back();
    if (dot) break;
  }
  return s == "-0" ? "0" : s;
}

}  // namespace

double roundLength(double at_most) {
  if (!(at_most > 0)) return 0.0;
  const double p = std::pow(10.0, std::floor(std::log10(at_most)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * p <= at_most * (1 + 1e-12)) return m * p;
  return p;
}

std::string lengthLabel(double metres) {
  if (metres >= 1000.0) return number(metres / 1000.0) + " km";
  if (metres < 0.01) return number(metres * 1000.0) + " mm";
  if (metres < 1.0) return number(metres * 100.0) + " cm";
  return number(metres) + " m";
}

void drawScaleBar(cv::Mat& image, double metres_per_pixel) {
  const double length = roundLength(0.2 * image.cols * metres_per_pixel);
  if (!(length > 0)) return;
  const double k = scaleOf(image);
  const int bar = std::max(1, static_cast<int>(std::lround(length / metres_per_pixel)));
  const std::string label = lengthLabel(length);
  const cv::Size t = textSize(label, k);
  const int x = px(14, k), y = image.rows - px(14, k);
  cv::rectangle(image, cv::Point(x - px(8, k), y - px(20, k) - t.height),
                cv::Point(x + std::max(bar, t.width) + px(8, k), y + px(8, k)), kPaper, cv::FILLED);
  cv::rectangle(image, cv::Point(x, y - px(7, k)), cv::Point(x + bar, y), kInk, cv::FILLED);
  text(image, label, cv::Point(x, y - px(15, k)), k);
}

void drawAxesTopView(cv::Mat& image) {
  const double k = scaleOf(image);
  const int len = px(50, k), x = image.cols - px(36, k) - len, y = image.rows - px(20, k);
  cv::rectangle(image, cv::Point(x - px(14, k), y - len - px(28, k)), cv::Point(image.cols - px(6, k), y + px(12, k)),
                kPaper, cv::FILLED);
  cv::arrowedLine(image, cv::Point(x, y), cv::Point(x + len, y), kInk, 2, cv::LINE_AA, 0, 0.25);
  cv::arrowedLine(image, cv::Point(x, y), cv::Point(x, y - len), kInk, 2, cv::LINE_AA, 0, 0.25);
  text(image, "x", cv::Point(x + len + px(5, k), y + px(8, k)), k);
  text(image, "y", cv::Point(x + px(8, k), y - len - px(4, k)), k);
}

cv::Vec3b heightColour(double t) {
  static const cv::Mat lut = [] {
    cv::Mat ramp(1, 256, CV_8UC1), out;
    for (int i = 0; i < 256; ++i) ramp.at<uint8_t>(0, i) = static_cast<uint8_t>(i);
    cv::applyColorMap(ramp, out, cv::COLORMAP_TURBO);
    return out;
  }();
  const int i = std::clamp(static_cast<int>(std::lround(255.0 * (std::isfinite(t) ? t : 0.0))), 0, 255);
  return lut.at<cv::Vec3b>(0, i);
}

cv::Mat withHeightLegend(const cv::Mat& image, double low, double high, const std::string& title) {
  const double k = scaleOf(image);
  const int panel = px(250, k), bar_width = px(30, k), line = px(30, k);
  cv::Mat out(image.rows, image.cols + panel, CV_8UC3, kPaper);
  image.copyTo(out(cv::Rect(0, 0, image.cols, image.rows)));
  const int x = image.cols + px(24, k);
  int y = px(36, k);
  std::istringstream lines(title);
  for (std::string l; std::getline(lines, l); y += line) text(out, l, cv::Point(x - px(10, k), y), k);
  const int top = y, bottom = std::max(top + px(60, k), std::min(image.rows - px(30, k), top + px(420, k)));
  for (int v = top; v <= bottom; ++v) {
    const cv::Vec3b c = heightColour(static_cast<double>(bottom - v) / (bottom - top));
    cv::line(out, cv::Point(x, v), cv::Point(x + bar_width, v), cv::Scalar(c[0], c[1], c[2]), 1);
  }
  cv::rectangle(out, cv::Point(x, top), cv::Point(x + bar_width, bottom), kInk, 1);
  const double span = high - low;  // ticks at round heights
  if (span > 0) {
    const double step = roundLength(span / 4.0);
    for (double h = std::ceil(low / step - 1e-9) * step; h <= high + 1e-9; h += step) {
      const int v = bottom - static_cast<int>(std::lround((h - low) / span * (bottom - top)));
      cv::line(out, cv::Point(x + bar_width, v), cv::Point(x + bar_width + px(6, k), v), kInk, 1);
      text(out, (h > 1e-9 ? "+" : "") + number(std::abs(h) < 1e-9 ? 0.0 : h) + " m",
           cv::Point(x + bar_width + px(10, k), v + px(9, k)), k);
    }
  }
  return out;
}

}  // namespace livo::report
