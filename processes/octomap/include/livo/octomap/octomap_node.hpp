// livo-octomap's node: REGISTERED_SCAN (and COLORED_CLOUD for a ColorOcTree), KEYFRAME and
// LOOP_CORRECTION in; OCTOMAP out every publish_period_s of sensor time; <map_name>.bt / .ot
// written every write_period_s of sensor time and on exit.
#pragma once

#include <string>

#include "livo/correction_frames.hpp"
#include "livo/node.hpp"
#include "livo/octomap/octomap_builder.hpp"
#include "livo/octomap/octomap_config.hpp"
#include "livo/sensor_rig.hpp"

namespace livo::octomap {

class OctomapNode {
 public:
  OctomapNode(lcm::LCM& lcm, const NodeOptions& node_options, const OctomapNodeOptions& options, const SensorRig& rig,
              std::string output_dir);

  void finish();
  bool writeFiles();
  /// Writes <output_dir>/<name>.bt and .ot.
  bool writeFiles(const std::string& name);
  void publishTree(int64_t utime);

  Node& node() { return node_; }
  const OctomapBuilder& builder() const { return builder_; }
  std::string btPath() const { return mapPath(options_.map_name, ".bt"); }
  std::string otPath() const { return mapPath(options_.map_name, ".ot"); }

 private:
  void periodic(int64_t utime);
  std::string mapPath(const std::string& name, const char* extension) const;
  /// Where a pose of (epoch, correction) goes in the map; a newer epoch (a LIO reset) first
  /// writes the map as <map_name>_epoch<N>.bt/.ot and starts a new one.
  MapFrame::Placed placeInMap(int32_t epoch, int64_t correction_id);

  Node node_;
  OctomapNodeOptions options_;
  OctomapBuilder builder_;
  std::string output_dir_;
  int64_t last_publish_ = INT64_MIN, last_write_ = INT64_MIN;
  bool finished_ = false;
  MapFrame frame_;  // the map's odometry epoch and loop correction
};

}  // namespace livo::octomap
