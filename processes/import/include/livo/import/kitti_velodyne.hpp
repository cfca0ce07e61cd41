// KITTI Velodyne HDL-64E scans: .bin files (float32 x y z reflectance, or x y z only in some
// derived sets) and the text files of the unsynced raw data ("x y z r" per line), turned into
// point_cloud_t with per-point times and rings, which KITTI does not record:
//  - time: the HDL-64E turns clockwise seen from above (azimuth atan2(y, x) decreasing) at about
//    10 Hz; KITTI's sweep starts and ends facing backwards (azimuth +-180 deg) and faces forwards
//    (azimuth 0, the camera trigger, timestamps.txt) half way. So
//        time_offset = (pi - atan2(y, x)) / (2 pi) * sweep_duration.
//  - ring: from elevation with the sensor's nominal layout: 32 upper beams from +2.0 deg down in
//    1/3 deg steps, 32 lower beams from -8.83 deg down in 1/2 deg steps; ring 0 is the lowest
//    beam and 63 the highest (the Velodyne driver's order). An approximation: the real beams
//    deviate from the nominal angles by up to a few tenths of a degree.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "livo/point_cloud_t.hpp"

namespace livo::import {

enum class KittiPointFields { kAuto, kXyzi, kXyz };

struct KittiScan {
  std::vector<float> x, y, z, intensity;
  size_t size() const { return x.size(); }
};

/// Reads a .bin scan. kAuto: a size divisible by only one of 16 and 12 bytes per point decides;
/// if both, xyzi when every fourth value lies in [0, 1] (reflectance). Throws std::runtime_error
/// naming the file for a size that fits neither. `used` (optional) gets the layout chosen.
KittiScan readKittiBin(const std::string& path, KittiPointFields fields, KittiPointFields* used = nullptr);
/// Reads a text scan (x y z [r] per line); throws naming file and line.
KittiScan readKittiText(const std::string& path);

/// Nominal HDL-64E ring (0 = lowest beam) of a point at this elevation.
int hdl64RingFromElevation(double elevation_rad);
/// Time after the sweep start of a point at this azimuth (see above), in [0, sweep_duration).
double kittiTimeOffset(double x, double y, double sweep_duration);

/// Points with a non-finite coordinate are dropped (counted in `dropped`).
point_cloud_t kittiScanToCloud(const KittiScan& scan, int64_t start_utime, double sweep_duration,
                               int64_t* dropped = nullptr);

}  // namespace livo::import
