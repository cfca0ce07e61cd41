// A floor plan from the OctoMap: the occupied voxels in a band of heights around the trajectory's
// (the walls, furniture and trunks at the height the sensor moved at, not the floor or the
// ceiling), seen from above and coloured by their height above the trajectory.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <octomap/OcTree.h>
#include <opencv2/core.hpp>

#include "livo/report/map_views.hpp"
#include "livo/report/trajectory_height.hpp"

namespace livo::report {

struct SliceBand {
  double below_m = 0.5;  // the band reaches this far below the trajectory's height there
  double above_m = 1.0;  // and this far above it
};

struct OccupiedVoxel {
  Vec3 centre = Vec3::Zero();
  double size = 0.0;    // m: a leaf, or a larger cube where octomap pruned eight equal ones
  double height = 0.0;  // its centre above the trajectory's height there, clamped to the band
};

/// The occupied leaves whose vertical extent overlaps the band at their centre's horizontal
/// position (more than touching it), in the tree's leaf order.
std::vector<OccupiedVoxel> occupiedVoxelsInBand(const ::octomap::OcTree& tree, const TrajectoryHeight& height,
                                                const SliceBand& band);

/// Reads an octomap .bt file (binary OcTree); throws std::runtime_error naming it if it cannot.
std::unique_ptr<::octomap::OcTree> readOctomapBinary(const std::string& path);

/// The voxels from above on white: each fills its square, coloured by its height in the band
/// (heightColour, the band's bottom blue, its top red); the highest voxel wins a pixel.
cv::Mat renderSlice(const std::vector<OccupiedVoxel>& voxels, const TopViewFrame& frame, const SliceBand& band);

}  // namespace livo::report
