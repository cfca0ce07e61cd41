// Adaptive plane extraction (APGC-LVIW, "LiDAR subsystem", improvement 2): planes found by RANSAC
// one after another in a cloud given in the sensor's frame, each with
// - a distance threshold that adapts to the range of the cloud's centroid (a far cloud is noisier:
//   the beam footprint and the range noise grow with range),
// - a normal-consistency check: an inlier must also have a local normal (from its neighbours)
//   that agrees with the plane's, so that a bush or a kerb crossing a wall does not join it,
// - the ground-direction constraint: a plane below the sensor that is nearly horizontal is the
//   ground only if its normal is within a few degrees of up; a tilted one there is refused,
// - a quality, the mean absolute distance of its inliers, accepted only well inside the
//   threshold.
// The paper leaves the constants and the threshold's formula open; the choices are in the options
// below and measured in processes/lio_graph/README.md.
#pragma once

#include <cstdint>
#include <vector>

#include "livo/plane.hpp"
#include "livo/so3.hpp"

namespace livo::lio_graph {

struct PlaneExtractionOptions {
  // threshold = clamp(threshold_base + threshold_per_metre * |centroid|, threshold_min, threshold_max)
  double threshold_base = 0.03;        // m
  double threshold_per_metre = 0.004;  // m per metre of the centroid's range
  double threshold_min = 0.03;         // m
  double threshold_max = 0.20;         // m
  int min_inliers = 30;                // points a plane needs (after the normal check)
  int max_planes = 8;                  // planes per cloud
  int ransac_iterations = 150;
  int score_sample = 1500;               // RANSAC scores hypotheses on at most this many points
  int normal_neighbours = 8;             // points of each local normal
  double normal_max_angle_deg = 20.0;    // a consistent inlier's local normal is this close
  double min_consistent_fraction = 0.6;  // of the distance inliers, else the plane is refused
  Vec3 up = Vec3::UnitZ();               // in the cloud's frame (the filter's gravity direction)
  double ground_below = 0.5;             // m: a plane whose centroid is this far below the sensor ...
  double ground_candidate_deg = 30.0;    // ... with a normal this close to up is a ground candidate,
  double ground_max_tilt_deg = 8.0;      // accepted as the ground only within this tilt
  double max_quality_ratio = 0.5;        // accepted when mean |distance| <= ratio * threshold
  uint32_t seed = 1;                     // RANSAC's sampling (deterministic)
};

struct ExtractedPlane {
  Plane plane;  // in the cloud's frame; normal towards the sensor (offset >= 0)
  Vec3 centroid = Vec3::Zero();
  double threshold = 0.0;  // the adaptive distance threshold it was found with
  double quality = 0.0;    // mean absolute distance of its inliers, m
  bool ground = false;
  std::vector<int> inliers;  // indices into the cloud
};

struct PlaneExtractionStats {
  int accepted = 0;
  int refused_inconsistent = 0;  // too few inliers with an agreeing local normal
  int refused_quality = 0;       // mean distance above max_quality_ratio * threshold
  int refused_ground_tilt = 0;   // a ground candidate tilted beyond ground_max_tilt_deg
};

/// The planes of `points` (sensor frame), most supported first. Deterministic for a seed.
std::vector<ExtractedPlane> extractPlanes(const std::vector<Vec3>& points, const PlaneExtractionOptions& options,
                                          PlaneExtractionStats* stats = nullptr);

/// The adaptive distance threshold for a cloud whose centroid is at `centroid` (sensor frame).
double adaptiveThreshold(const Vec3& centroid, const PlaneExtractionOptions& options);

}  // namespace livo::lio_graph
