#include "octomap_node.hpp"

#include <filesystem>
#include <sstream>

#include "livo/colored_cloud_t.hpp"
#include "livo/keyframe_t.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/map_inputs.hpp"
#include "livo/messages.hpp"
#include "livo/octomap_t.hpp"
#include "livo/registered_scan_t.hpp"

namespace livo {
namespace octomap_export {

OctomapNode::OctomapNode(lcm::LCM& lcm, const NodeOptions& node_options, const OctomapNodeOptions& options,
                         const SensorRig& rig, std::string output_dir)
    : node_(lcm, node_options),
      options_(options),
      builder_(options.core, rig.lidar ? rig.lidar->T_I_L : Pose3::Identity()),
      output_dir_(std::move(output_dir)) {
  if (options_.publish_period_s > 0) node_.declareOutput(options_.output_channel);
  node_.subscribe<registered_scan_t>(options_.scan_channel, [this](const registered_scan_t& m) {
    RegisteredScanView v;
    if (const std::string why = viewRegisteredScan(m, &v); !why.empty()) {
      node_.reject(options_.scan_channel, why);
      return;
    }
    std::string error;
    if (!builder_.addScan(v, &error)) {
      node_.reject(options_.scan_channel, error);
      return;
    }
    periodic(m.utime);
  });
  if (options_.core.colour) {
    node_.subscribe<colored_cloud_t>(options_.colour_channel, [this](const colored_cloud_t& m) {
      const size_t n = static_cast<size_t>(std::max(0, m.num_points));
      if (m.x.size() != n || m.r.size() != n || m.g.size() != n || m.b.size() != n) {
        node_.reject(options_.colour_channel, "arrays disagree with num_points");
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
    if (const std::string why = keyframeProblem(m); !why.empty()) {
      node_.reject(options_.keyframe_channel, why);
      return;
    }
    const point_cloud_t& c = m.cloud;
    Keyframe k;
    k.utime = m.utime;
    k.T_W_I = poseFrom(m.position, m.orientation);
    for (int i = 0; i < c.num_points; ++i) {
      const Eigen::Vector3f p(c.x[i], c.y[i], c.z[i]);
      if (p.allFinite()) k.points.push_back(p);
    }
    if (!builder_.addKeyframe(m.id, std::move(k))) node_.reject(options_.keyframe_channel, "pose is not finite");
  });
  node_.subscribe<loop_correction_t>(options_.correction_channel, [this](const loop_correction_t& m) {
    std::map<int64_t, Pose3> corrected;
    if (const std::string why = correctedKeyframePoses(m, &corrected); !why.empty()) {
      node_.reject(options_.correction_channel, why);
      return;
    }
    const int moved = builder_.applyCorrection(corrected);
    std::ostringstream s;
    s << "loop correction: " << moved << " keyframes moved, points by up to " << builder_.lastCorrectionShift()
      << " m; ";
    if (builder_.lastCorrectionRebuilt()) s << "rebuilt from " << builder_.keyframes() << " keyframes";
    else s << "tree kept (rebuild_tolerance " << options_.core.rebuild_tolerance << " m)";
    node_.info(s.str());
    if (builder_.lastCorrectionRebuilt()) publishTree(m.utime);
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
  const std::string bytes = builder_.map().binaryBytes();
  octomap_t msg;
  msg.utime = utime;
  msg.frame = "W";
  msg.tree_type = "OcTree";
  msg.resolution = options_.core.resolution;
  msg.binary = 1;
  msg.size = static_cast<int32_t>(bytes.size());
  msg.data.assign(bytes.begin(), bytes.end());
  node_.publish(options_.output_channel, msg);
}

bool OctomapNode::writeFiles() {
  std::error_code ec;
  std::filesystem::create_directories(output_dir_, ec);
  const bool ok = builder_.map().writeBinary(btPath()) && builder_.map().writeFull(otPath());
  if (!ok) node_.error("cannot write " + btPath() + " / " + otPath());
  return ok;
}

void OctomapNode::finish() {
  if (finished_) return;
  finished_ = true;
  if (writeFiles())
    node_.info("wrote " + btPath() + " and " + otPath() + " (" + std::to_string(builder_.map().leafCount()) + " leaves; " +
               std::to_string(builder_.keyframes()) + " keyframe clouds on disk, " +
               std::to_string(builder_.storedKeyframeBytes() / 1000000) + " MB)");
}

}  // namespace octomap_export
}  // namespace livo
