// livo-colour's node: REGISTERED_SCAN, ODOMETRY, CAMERA, KEYFRAME and LOOP_CORRECTION in;
// COLORED_CLOUD out (the points coloured or recoloured since the previous message, after every
// scan); the map written as PLY and PCD on exit and whenever a message arrives on COLOUR_SAVE.
#pragma once

#include <memory>
#include <string>

#include "livo/colour/colour_config.hpp"
#include "livo/colour/colouring_pipeline.hpp"
#include "livo/correction_frames.hpp"
#include "livo/node.hpp"
#include "livo/sensor_rig.hpp"

namespace livo::colour {

class ColourNode {
 public:
  /// Throws ConfigError if the rig has no camera.
  ColourNode(lcm::LCM& lcm, const NodeOptions& node_options, const ColourNodeOptions& options, const SensorRig& rig,
             std::string output_dir);

  /// Processes the images still queued, publishes what they coloured, writes the map files.
  void finish();
  /// Writes <output_dir>/<map_name>.ply and .pcd (coloured points only); false on failure.
  bool saveMap();
  /// The same as <output_dir>/<name>.ply and .pcd.
  bool saveMap(const std::string& name);

  Node& node() { return node_; }
  const ColouringPipeline& pipeline() const { return pipeline_; }
  std::string plyPath() const;
  std::string pcdPath() const;

 private:
  void publishRecoloured(int64_t utime);
  std::string mapPath(const std::string& name, const char* extension) const;
  /// Where a pose of (epoch, correction) goes in the map; a newer epoch (a LIO reset) first
  /// writes the map as <map_name>_epoch<N>.ply/.pcd and starts a new one.
  MapFrame::Placed placeInMap(int32_t epoch, int64_t correction_id);

  Node node_;
  ColourNodeOptions options_;
  ColouringPipeline pipeline_;
  std::string output_dir_;
  bool finished_ = false;
  MapFrame frame_;  // the map's odometry epoch and loop correction
  static constexpr int64_t kStatusPeriodUs = 60000000;
  int64_t last_status_utime_ = INT64_MIN / 2;
  int64_t first_scan_utime_ = INT64_MIN;
};

}  // namespace livo::colour
