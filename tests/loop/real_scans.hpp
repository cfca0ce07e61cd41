// Readers of the real scans in ../shared/data/lidar (float32 xyz .bin files, binary PLY with
// float properties, "vK x y z qx qy qz qw" graph files, KITTI pose lines).
#pragma once

#include <string>
#include <vector>

#include "livo/loop/point_types.hpp"

namespace livo::loop::testing {

Points readXyzBin(const std::string& path);
/// Binary little-endian PLY whose vertex properties are all float32, x y z first.
Points readFloatPly(const std::string& path);
/// Poses of "vK x y z qx qy qz qw" lines, in file order.
std::vector<Pose3> readGraphPoses(const std::string& path);
Pose3 readMatrix4(const std::string& path);

}  // namespace livo::loop::testing
