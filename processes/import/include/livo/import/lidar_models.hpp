// What the importer knows of each LiDAR model the rig may name (livo::kLidarModels): its beams,
// scan pattern, the field layout its driver writes, and the datasheet's range and range noise. A
// starter rig guesses the model from the rings and time layout a log shows (guessLidarModel); the
// rig check compares the rings of the rig's model with the log's.
#pragma once

#include <string>
#include <vector>

namespace livo::import {

enum class LidarFamily { kVelodyne, kOuster, kHesai, kLivox };

struct LidarModelFacts {
  std::string model;  // as livo::kLidarModels names it
  int rings = 0;      // beams (Livox: scan lines)
  bool solid_state = false;
  LidarFamily family = LidarFamily::kVelodyne;
  double max_range = 100.0;       // m
  double range_noise_std = 0.03;  // m
  std::string source;             // where max_range and range_noise_std come from
};

/// Every model of livo::kLidarModels, with the figures config/rigs/ states for it.
const std::vector<LidarModelFacts>& lidarModelFacts();
/// nullptr if `model` is not one of them.
const LidarModelFacts* findLidarModel(const std::string& model);

struct LidarModelGuess {
  const LidarModelFacts* facts = nullptr;  // never null
  bool exact = false;                      // a model with exactly these rings (and family) exists
  std::string reason;                      // e.g. "16 rings, Velodyne time layout (time: float s)"
};

/// The model a log's LiDAR most likely is: the input's own name for it (`named_model`, e.g. from
/// Ouster metadata) if it is a known model, else by rings and family, the family told by the
/// PointCloud2 time layout (`layout`, the importer's lidar_point_layout: time -> Velodyne, t ->
/// Ouster, timestamp -> Hesai, offset_time or a solid-state pattern -> Livox); a ring count no
/// model has gives the model with the nearest count (exact = false).
LidarModelGuess guessLidarModel(int rings, bool solid_state, const std::string& layout, const std::string& named_model);

}  // namespace livo::import
