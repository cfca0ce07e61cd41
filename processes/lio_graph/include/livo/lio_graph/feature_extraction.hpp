// LOAM / LIO-SAM feature extraction by local roughness: along each ring of a spinning LiDAR, the
// roughness of a point is the squared difference between the sum of its 2k neighbours' ranges and
// 2k times its own; rough points are edges, smooth ones planar (surface) points. Points beside an
// occlusion boundary or on a surface nearly parallel to the beam are never features. Each ring is
// split into sectors, so features spread around the sensor; a few edges per sector, their
// neighbours then skipped. Without rings (a Livox-style pattern, or a cloud without ring ids) every
// point is a surface candidate and there are no edges.
#pragma once

#include <cstdint>
#include <vector>

#include "livo/so3.hpp"

namespace livo::lio_graph {

struct FeatureOptions {
  int neighbours = 5;  // k each side
  int sectors = 6;     // per ring
  int max_edges_per_sector = 20;
  double edge_threshold = 1.0;     // roughness (m^2) above which a point may be an edge
  double surface_threshold = 0.1;  // roughness below which a point is planar
  double occlusion_gap = 0.3;      // m: range jump between neighbours that marks an occlusion
  double parallel_ratio = 0.02;    // |range jump| / range to both neighbours: beam grazing a surface
  double surface_voxel = 0.2;      // m: surface points downsampled (first point per voxel; 0.4 with
                                   // LIO-SAM's plane test: README, "Against livo-lio")
  double min_range = 1.0;          // m (the vehicle itself, rain, the mount)
};

/// A sweep's points in sensor order: `ring[i]` (negative or absent: no ring) and the time offset
/// order points along a ring.
struct RingCloud {
  std::vector<Vec3> points;        // sensor frame (deskewed)
  std::vector<int16_t> ring;       // one per point, or empty
  std::vector<float> time_offset;  // one per point
};

struct ScanFeatures {
  std::vector<Vec3> edges;     // same frame as the input
  std::vector<Vec3> surfaces;  // downsampled
};

ScanFeatures extractFeatures(const RingCloud& cloud, const FeatureOptions& options);

}  // namespace livo::lio_graph
