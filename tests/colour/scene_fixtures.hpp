// Constructed scenes for the colouring tests: a camera looking along +z of the world (body =
// camera = world at identity unless moved), a textured back wall and a foreground box, rendered
// exactly and sampled as LiDAR-like rows of points.
#pragma once

#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

#include "livo/colour/colour_image.hpp"
#include "livo/sensor_rig.hpp"

namespace livo_test {

inline livo::CameraRig testCamera(bool distorted) {
  livo::CameraRig c;
  c.width = 320;
  c.height = 240;
  c.fx = c.fy = 200.0;
  c.cx = 159.5;
  c.cy = 119.5;
  if (distorted) c.distortion = {{-0.05, 0.01, 0.0005, -0.0003}};
  return c;
}

/// Wall at z = 5 (grey level from a smooth pattern of x, y) and a box face at z = 2 covering
/// |x| < 0.4, |y| < 0.3 (grey level 40).
struct WallAndBox {
  static constexpr double kWallZ = 5.0, kBoxZ = 2.0, kBoxHalfX = 0.4, kBoxHalfY = 0.3;
  static double wallGrey(double x, double y) { return 150.0 + 60.0 * std::sin(1.3 * x) * std::cos(0.9 * y); }
  static constexpr double kBoxGrey = 40.0;
  static bool inBox(double x, double y) { return std::abs(x) < kBoxHalfX && std::abs(y) < kBoxHalfY; }

  /// Image seen from the camera at the world origin looking along +z (no distortion), times `gain`.
  static livo::colour::ColourImage render(const livo::CameraRig& cam, int64_t utime, double gain = 1.0,
                                          float exposure = 0.0f) {
    livo::colour::ColourImage img;
    img.utime = utime;
    img.exposure_time = exposure;
    img.pixels = cv::Mat(cam.height, cam.width, CV_8UC1);
    for (int v = 0; v < cam.height; ++v)
      for (int u = 0; u < cam.width; ++u) {
        const double xn = (u - cam.cx) / cam.fx, yn = (v - cam.cy) / cam.fy;
        double g = inBox(xn * kBoxZ, yn * kBoxZ) ? kBoxGrey : wallGrey(xn * kWallZ, yn * kWallZ);
        img.pixels.at<uint8_t>(v, u) = static_cast<uint8_t>(std::lround(std::min(255.0, g * gain)));
      }
    return img;
  }

  /// LiDAR-like rows: wall points every `step` m in x, rows every `row` m in y; box points likewise.
  static void points(double step, double row, std::vector<float>* x, std::vector<float>* y, std::vector<float>* z) {
    for (double yy = -2.0; yy <= 2.0; yy += row)
      for (double xx = -3.0; xx <= 3.0; xx += step) {
        x->push_back(float(xx)), y->push_back(float(yy)), z->push_back(float(kWallZ));
      }
    for (double yy = -kBoxHalfY + 0.02; yy < kBoxHalfY - 0.01; yy += row * kBoxZ / kWallZ)
      for (double xx = -kBoxHalfX + 0.01; xx < kBoxHalfX - 0.01; xx += step) {
        x->push_back(float(xx)), y->push_back(float(yy)), z->push_back(float(kBoxZ));
      }
  }
};

}  // namespace livo_test
