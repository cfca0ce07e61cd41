#include "livo/octomap/octomap_node.hpp"

#include <filesystem>
#include <sstream>

#include "livo/colored_cloud_t.hpp"
#include "livo/correction_frames.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/map_inputs.hpp"
#include "livo/messages.hpp"
#include "livo/octomap_t.hpp"
#include "livo/registered_scan_t.hpp"

namespace livo::octomap {

OctomapNode::OctomapNode(lcm::LCM& lcm, const NodeOptions& node_options, const OctomapNodeOptions& options,
                         const SensorRig& rig, std::string output_dir)
    : node_(lcm, node_options),
      options_(options),
      builder_(options.core, rig.lidar ? rig.lidar->T_I_L : Pose3::Identity()),
      output_dir_(std::move(output_dir)) {
  if (options_.publish_period_s > 0) node_.declareOutput(options_.octomap_channel);
  node_.subscribe<registered_scan_t>(options_.registered_scan_channel, [this](const registered_scan_t& m) {
    const auto add = [this](const RegisteredScanView& v, std::string* why) { return builder_.addScan(v, why); };
    if (!takeRegisteredScan(node_, options_.registered_scan_channel, m, placeInMap(m.epoch, m.correction_id), add))
      return;
    if (builder_.takeRebuildFinished()) {
      node_.info("staged rebuild done: the map is rebuilt from " + std::to_string(builder_.keyframes()) + " keyframes" +
                 (builder_.rebuilding() ? " (another started: keyframes moved while it ran)" : ""));
      publishTree(m.utime);
    }
    periodic(m.utime);
  });
  if (options_.core.colour) {
    node_.subscribe<colored_cloud_t>(options_.colored_cloud_channel, [this](const colored_cloud_t& m) {
      const size_t n = static_cast<size_t>(std::max(0, m.num_points));
      if (m.x.size() != n || m.r.size() != n || m.g.size() != n || m.b.size() != n) {
        node_.reject(options_.colored_cloud_channel, "arrays disagree with num_points");
        return;
      }
      std::vector<Eigen::Vector3f> p(n);
      std::vector<std::array<uint8_t, 3>> rgb(n);
      for (size_t i = 0; i < n; ++i) {
        p[i] = Eigen::Vector3f(m.x[i], m.y[i], m.z[i]);
        rgb[i] = {m.r[i], m.g[i], m.b[i]};
      }
      builder_.map().setColours(p, rgb);
    });
  }
  node_.subscribe<keyframe_t>(options_.keyframe_channel, [this](const keyframe_t& m) {
    Keyframe k;
    const bool cloud = true;  // rebuilds cast the keyframe's cloud
    if (!takeKeyframePose(
            node_, options_.keyframe_channel, m, cloud, [&] { return placeInMap(m.epoch, m.correction_id); }, &k.T_W_I))
      return;
    const point_cloud_t& c = m.cloud;
    k.utime = m.utime;
    for (int i = 0; i < c.num_points; ++i) {
      const Eigen::Vector3f p(c.x[i], c.y[i], c.z[i]);
      if (p.allFinite()) k.points.push_back(p);
    }
    if (!builder_.addKeyframe(m.id, std::move(k))) node_.reject(options_.keyframe_channel, "pose is not finite");
  });
  node_.subscribe<loop_correction_t>(options_.loop_correction_channel, [this](const loop_correction_t& m) {
    MapCorrection c;
    if (!takeMapCorrection(node_, options_.loop_correction_channel, m, &frame_, &c)) return;
    const int moved = builder_.applyCorrection(c.corrected, c.step.unlisted);
    std::ostringstream s;
    s << "loop correction " << m.correction_id << ": " << moved << " keyframes moved, points by up to "
      << builder_.lastCorrectionShift() << " m; ";
    const bool staged = options_.core.rebuild_keyframes_per_scan > 0;
    if (builder_.lastCorrectionRebuilt() && staged)
      s << "staged rebuild from " << builder_.keyframes() << " keyframes, " << options_.core.rebuild_keyframes_per_scan
        << " a scan";
    else if (builder_.lastCorrectionRebuilt())
      s << "rebuilt from " << builder_.keyframes() << " keyframes";
    else if (builder_.rebuilding())
      s << "a staged rebuild is under way (what it cast before is taken up when it ends)";
    else
      s << "tree kept (rebuild_tolerance " << options_.core.rebuild_tolerance << " m)";
    node_.info(s.str());
    if (builder_.lastCorrectionRebuilt() && !staged) publishTree(m.utime);
  });
}

MapFrame::Placed OctomapNode::placeInMap(int32_t epoch, int64_t correction_id) {
  return frame_.place(epoch, correction_id, [&](int32_t old_epoch) {
    // the LIO was reset: the old map is finished as it is, written beside the final one, and a
    // new map starts in the new odometry frame
    const std::string name = options_.map_name + "_epoch" + std::to_string(old_epoch);
    node_.warn("odometry epoch " + std::to_string(epoch) + " (LIO reset): the map of epoch " +
               std::to_string(old_epoch) + (output_dir_.empty() ? " is dropped" : " goes to " + mapPath(name, ".bt")) +
               "; a new map starts");
    builder_.finishRebuild();
    if (!output_dir_.empty()) writeFiles(name);
    builder_ = OctomapBuilder(options_.core, builder_.lidarExtrinsics());
    last_publish_ = last_write_ = INT64_MIN;  // the new epoch's clock may be behind the old one's
  });
}

void OctomapNode::periodic(int64_t utime) {
  if (options_.publish_period_s > 0 &&
      (last_publish_ == INT64_MIN || utime - last_publish_ >= static_cast<int64_t>(options_.publish_period_s * 1e6))) {
    publishTree(utime);
  }
  if (options_.write_period_s > 0 &&
      (last_write_ == INT64_MIN || utime - last_write_ >= static_cast<int64_t>(options_.write_period_s * 1e6))) {
    last_write_ = utime;
    writeFiles();
  }
}

void OctomapNode::publishTree(int64_t utime) {
  if (options_.publish_period_s <= 0) return;
  last_publish_ = utime;
  // the tiles in memory: the area updated in the last tile_idle_s (all of a small map), so the
  // message stays bounded however large the map grows; the files hold all of it
  const std::string bytes = builder_.map().binaryBytes(true);
  octomap_t msg;
  msg.utime = utime;
  msg.frame = "W";
  msg.tree_type = "OcTree";
  msg.resolution = options_.core.resolution;
  msg.binary = 1;
  msg.size = static_cast<int32_t>(bytes.size());
  msg.data.assign(bytes.begin(), bytes.end());
  node_.publish(options_.octomap_channel, msg);
}

std::string OctomapNode::mapPath(const std::string& name, const char* extension) const {
  return output_dir_ + "/" + name + extension;
}

bool OctomapNode::writeFiles() { return writeFiles(options_.map_name); }

bool OctomapNode::writeFiles(const std::string& name) {
  std::error_code ec;
  std::filesystem::create_directories(output_dir_, ec);
  const std::string bt = mapPath(name, ".bt"), ot = mapPath(name, ".ot");
  const bool ok = builder_.map().writeBinary(bt) && builder_.map().writeFull(ot);
  if (!ok) node_.error("cannot write " + bt + " / " + ot);
  return ok;
}

void OctomapNode::finish() {
  if (finished_) return;
  finished_ = true;
  builder_.finishRebuild();
  if (writeFiles())
    node_.info("wrote " + btPath() + " and " + otPath() + " (" + std::to_string(builder_.map().leafCount()) +
               " leaves; " + std::to_string(builder_.keyframes()) + " keyframe clouds on disk (" +
               std::to_string(builder_.keyframesNotKept()) + " not kept: keyframe_spacing), " +
               std::to_string(builder_.storedKeyframeBytes() / 1000000) + " MB; tiles " +
               std::to_string(builder_.map().residentTiles()) + " in memory, " +
               std::to_string(builder_.map().spilledTiles()) + " on disk, " +
               std::to_string(builder_.map().spilledBytes() / 1000000) + " MB)");
}

}  // namespace livo::octomap
