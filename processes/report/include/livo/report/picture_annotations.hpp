// What a map picture needs besides the map: a scale bar, the axes' directions and a colour scale.
// Drawn with OpenCV on 8-bit BGR images.
#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace livo::report {

/// 1, 2 or 5 times a power of ten: the largest not above `at_most` (for a scale bar's length).
double roundLength(double at_most);

/// "20 m", "0.5 m", "2 km".
std::string lengthLabel(double metres);

/// A scale bar (about a fifth of the width) in a white box at the bottom left.
void drawScaleBar(cv::Mat& image, double metres_per_pixel);

/// Arrows for world x (right) and y (up) in a white box at the bottom right, for a top view.
void drawAxesTopView(cv::Mat& image);

/// The colour of t in [0, 1] on the height scale (OpenCV's turbo map: blue low, red high), BGR.
cv::Vec3b heightColour(double t);

/// The image with a panel on its right: a vertical colour bar from `low` (bottom) to `high`
/// (top) in metres with ticks, under `title` (two lines at most, split at '\n').
cv::Mat withHeightLegend(const cv::Mat& image, double low, double high, const std::string& title);

}  // namespace livo::report
