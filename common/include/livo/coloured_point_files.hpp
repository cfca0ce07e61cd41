// Coloured points as files: binary little-endian PLY (x y z float, red green blue uchar) and
// binary PCD v0.7 (x y z rgb, rgb packed as PCL does), both readable back. livo-colour writes its
// RGB map with them (colour_map.ply / .pcd), livo-report reads it for its pictures and report.html.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace livo {

struct ColouredPoints {
  std::vector<Eigen::Vector3f> position;
  std::vector<std::array<uint8_t, 3>> rgb;
  size_t size() const { return position.size(); }
};

/// Visits `count` coloured points, the same ones in the same order at every call: a map too large
/// to copy is written straight from where it is.
struct PointStream {
  size_t count = 0;
  std::function<void(const std::function<void(const Eigen::Vector3f&, const std::array<uint8_t, 3>&)>&)> visit;
};
/// Writes atomically (temporary file, then rename); false with `error` on failure (also when the
/// stream visits other than `count` points).
bool writePly(const std::string& path, const PointStream& points, std::string* error);
bool writePcd(const std::string& path, const PointStream& points, std::string* error);
bool writePly(const std::string& path, const ColouredPoints& points, std::string* error);
bool writePcd(const std::string& path, const ColouredPoints& points, std::string* error);
/// Reads the files written above (binary, these fields; others are refused with a message).
bool readPly(const std::string& path, ColouredPoints* points, std::string* error);
bool readPcd(const std::string& path, ColouredPoints* points, std::string* error);

}  // namespace livo
