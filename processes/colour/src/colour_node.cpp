#include "livo/colour/colour_node.hpp"

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <sstream>

#include "livo/colored_cloud_t.hpp"
#include "livo/coloured_point_files.hpp"
#include "livo/correction_frames.hpp"
#include "livo/image_t.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/map_inputs.hpp"
#include "livo/message_checks.hpp"
#include "livo/messages.hpp"
#include "livo/odometry_t.hpp"
#include "livo/registered_scan_t.hpp"

namespace livo::colour {

namespace {
const CameraRig& requireCamera(const SensorRig& rig) {
  if (!rig.camera) throw ConfigError("livo-colour: the rig has no camera (rig.camera)");
  return *rig.camera;
}
}  // namespace

ColourNode::ColourNode(lcm::LCM& lcm, const NodeOptions& node_options, const ColourNodeOptions& options,
                       const SensorRig& rig, std::string output_dir)
    : node_(lcm, node_options),
      options_(options),
      pipeline_(options.core, requireCamera(rig)),
      output_dir_(std::move(output_dir)) {
  if (options_.camera_channel.empty()) options_.camera_channel = rig.channels.camera;
  node_.declareOutput(options_.colored_cloud_channel);

  node_.subscribe<registered_scan_t>(options_.registered_scan_channel, [this](const registered_scan_t& m) {
    const auto add = [this](const RegisteredScanView& v, std::string* why) { return pipeline_.addScan(v, why); };
    if (!takeRegisteredScan(node_, options_.registered_scan_channel, m, placeInMap(m.epoch, m.correction_id), add))
      return;
    publishRecoloured(m.utime);
    if (first_scan_utime_ == INT64_MIN) first_scan_utime_ = m.utime;
    if (m.utime - last_status_utime_ >= kStatusPeriodUs) {
      // a long run says where its memory and disk go, once a minute of sensor time
      last_status_utime_ = m.utime;
      const ColourMap& map = pipeline_.map();
      std::ostringstream s;
      s << "map after " << std::fixed << std::setprecision(0) << (m.utime - first_scan_utime_) * 1e-6
        << " s of scans: " << map.residentPoints() << " points in " << map.residentTiles() << " tiles in memory, "
        << map.spilledTiles() << " tiles on disk (" << std::setprecision(1) << map.spilledBytes() / 1e6 << " MB), "
        << map.tilesEvictedForMemory() << " sent early for memory; voxel index " << map.indexBytes() / 1e6 << " MB";
      node_.info(s.str());
    }
  });
  node_.subscribe<odometry_t>(options_.odometry_channel, [this](const odometry_t& m) {
    if (const std::string why = poseProblem(m.position, m.orientation); !why.empty()) {
      node_.reject(options_.odometry_channel, why);
      return;
    }
    const MapFrame::Placed placed = placeInMap(m.epoch, m.correction_id);
    if (placed.placement != MapFrame::Placement::kUse) {
      node_.reject(options_.odometry_channel, placed.why);
      return;
    }
    pipeline_.addPose(m.utime, placed.to_map * poseFrom(m.position, m.orientation));
  });
  node_.subscribe<image_t>(options_.camera_channel, [this](const image_t& m) {
    ColourImage img;
    std::string error;
    const int64_t dropped = pipeline_.stats().images_dropped;
    const CameraRig& camera = pipeline_.camera();
    if (!decodeColourImage(rawImage(m), camera.width, camera.height, &img, &error) ||
        !pipeline_.addImage(std::move(img), &error)) {
      node_.reject(options_.camera_channel, error);
      return;
    }
    if (pipeline_.stats().images_dropped > dropped)
      node_.warn("more than " + std::to_string(options_.core.max_pending_images) +
                 " images wait for registered scans: the oldest is dropped");
    publishRecoloured(m.utime);
  });
  node_.subscribe<keyframe_t>(options_.keyframe_channel, [this](const keyframe_t& m) {
    Pose3 T_map_I;
    const bool cloud = false;  // the colour map keeps only the keyframe poses
    if (takeKeyframePose(
            node_, options_.keyframe_channel, m, cloud, [&] { return placeInMap(m.epoch, m.correction_id); }, &T_map_I))
      pipeline_.addKeyframe(m.id, m.utime, T_map_I);
  });
  node_.subscribe<loop_correction_t>(options_.loop_correction_channel, [this](const loop_correction_t& m) {
    MapCorrection c;
    if (!takeMapCorrection(node_, options_.loop_correction_channel, m, &frame_, &c)) return;
    const int moved = pipeline_.applyCorrection(c.corrected, c.step.unlisted);
    std::ostringstream s;
    s << "loop correction " << m.correction_id << ": " << moved << " keyframes moved the map";
    node_.info(s.str());
    publishRecoloured(m.utime);
  });
  node_.subscribeRaw(options_.colour_save_channel, [this](const void*, int) { saveMap(); });
}

MapFrame::Placed ColourNode::placeInMap(int32_t epoch, int64_t correction_id) {
  return frame_.place(epoch, correction_id, [&](int32_t old_epoch) {
    // the LIO was reset: the old map is finished as it is, written beside the final one, and a
    // new map starts in the new odometry frame
    pipeline_.flush();
    publishRecoloured(node_.lastSensorTime());
    const std::string name = options_.map_name + "_epoch" + std::to_string(old_epoch);
    node_.warn("odometry epoch " + std::to_string(epoch) + " (LIO reset): the map of epoch " +
               std::to_string(old_epoch) + (output_dir_.empty() ? " is dropped" : " goes to " + mapPath(name, ".ply")) +
               "; a new map starts");
    if (!output_dir_.empty()) saveMap(name);
    const CameraRig camera = pipeline_.camera();
    pipeline_ = ColouringPipeline(options_.core, camera);
  });
}

void ColourNode::publishRecoloured(int64_t utime) {
  const std::vector<uint32_t> ids = pipeline_.takeRecoloured();
  const size_t chunk = static_cast<size_t>(options_.max_points_per_message);
  for (size_t begin = 0; begin < ids.size(); begin += chunk) {
    const size_t n = std::min(chunk, ids.size() - begin);
    colored_cloud_t out;
    out.utime = utime;
    out.frame = "W";
    out.num_points = static_cast<int32_t>(n);
    out.x.resize(n);
    out.y.resize(n);
    out.z.resize(n);
    out.r.resize(n);
    out.g.resize(n);
    out.b.resize(n);
    for (size_t i = 0; i < n; ++i) {
      const MapPoint& p = pipeline_.map().point(ids[begin + i]);
      out.x[i] = p.position.x();
      out.y[i] = p.position.y();
      out.z[i] = p.position.z();
      out.r[i] = static_cast<uint8_t>(std::lround(std::clamp(p.colour[0], 0.0f, 255.0f)));
      out.g[i] = static_cast<uint8_t>(std::lround(std::clamp(p.colour[1], 0.0f, 255.0f)));
      out.b[i] = static_cast<uint8_t>(std::lround(std::clamp(p.colour[2], 0.0f, 255.0f)));
    }
    node_.publish(options_.colored_cloud_channel, out);
  }
}

std::string ColourNode::mapPath(const std::string& name, const char* extension) const {
  return output_dir_ + "/" + name + extension;
}
std::string ColourNode::plyPath() const { return mapPath(options_.map_name, ".ply"); }
std::string ColourNode::pcdPath() const { return mapPath(options_.map_name, ".pcd"); }

bool ColourNode::saveMap() { return saveMap(options_.map_name); }

bool ColourNode::saveMap(const std::string& name) {
  pipeline_.settleMap();  // the tiles on disk too, corrected
  // streamed from the map (resident tiles, then those on disk one at a time): no copy of it
  PointStream pts;
  pts.visit = [this](const auto& emit) {
    pipeline_.map().forEachPoint([&](const MapPoint& p) {
      if (!p.coloured()) return;
      std::array<uint8_t, 3> c;
      for (int k = 0; k < 3; ++k) c[k] = static_cast<uint8_t>(std::lround(std::clamp(p.colour[k], 0.0f, 255.0f)));
      emit(p.position, c);
    });
  };
  pts.visit([&pts](const Eigen::Vector3f&, const std::array<uint8_t, 3>&) { ++pts.count; });
  std::error_code ec;
  std::filesystem::create_directories(output_dir_, ec);
  std::string error;
  const std::string ply = mapPath(name, ".ply"), pcd = mapPath(name, ".pcd");
  if (!writePly(ply, pts, &error) || !writePcd(pcd, pts, &error)) {
    node_.error(error);
    return false;
  }
  const ColourMap& map = pipeline_.map();
  std::ostringstream s;
  s << "wrote " << pts.count << " coloured points to " << ply << " and " << pcd
    << " (map tiles: " << map.residentTiles() << " in memory with " << map.residentPoints() << " points, "
    << map.tilesEvictedForMemory() << " sent to disk early for memory, " << map.spilledTiles()
    << " on disk; spill file " << std::fixed << std::setprecision(1) << map.spilledBytes() / 1e6 << " MB live of "
    << map.spillWrittenBytes() / 1e6 << " MB written; scan points left out: " << pipeline_.stats().points_out_of_reach
    << " out of reach, " << pipeline_.stats().points_out_of_view << " outside the view cone, "
    << pipeline_.stats().points_pruned << " left the map uncoloured)";
  node_.info(s.str());
  return true;
}

void ColourNode::finish() {
  if (finished_) return;
  finished_ = true;
  pipeline_.flush();
  publishRecoloured(node_.lastSensorTime());
  saveMap();
}

}  // namespace livo::colour
