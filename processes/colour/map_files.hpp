// The coloured map as files: binary little-endian PLY (x y z float, red green blue uchar) and
// binary PCD v0.7 (x y z rgb, rgb packed as PCL does), both readable back here for tests.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace livo {
namespace colour {

struct ColouredPoints {
  std::vector<Eigen::Vector3f> position;
  std::vector<std::array<uint8_t, 3>> rgb;
  size_t size() const { return position.size(); }
};

/// Writes atomically (temporary file, then rename); false with `error` on failure.
bool writePly(const std::string& path, const ColouredPoints& points, std::string* error);
bool writePcd(const std::string& path, const ColouredPoints& points, std::string* error);
/// Reads the files written above (binary, these fields; others are refused with a message).
bool readPly(const std::string& path, ColouredPoints* points, std::string* error);
bool readPcd(const std::string& path, ColouredPoints* points, std::string* error);

}  // namespace colour
}  // namespace livo
