#include "loop_outputs.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "livo/time.hpp"
#include "livo/trajectory_io.hpp"
#include "voxel_grid.hpp"

namespace livo::loop {

void writeKeyframeTrajectory(const std::string& path, const LoopCloser& closer) {
  Trajectory t;
  closer.forEachPose([&](int64_t id, const Pose3& pose) { t.push_back({toSeconds(closer.utime(id)), pose}); });
  writeTum(path, t);
}

void writeLoopsJson(const std::string& path, const LoopCloser& closer) {
  nlohmann::json loops = nlohmann::json::array();
  for (const AcceptedLoop& l : closer.loops()) {
    const Quat q(l.T_to_from.linear());
    const Vec3 t = l.T_to_from.translation();
    loops.push_back({{"from_id", l.from_id},
                     {"to_id", l.to_id},
                     {"from_time", toSeconds(l.from_utime)},
                     {"to_time", toSeconds(l.to_utime)},
                     {"T_to_from", {{"translation", {t.x(), t.y(), t.z()}}, {"rotation_wxyz", {q.w(), q.x(), q.y(), q.z()}}}},
                     {"coarse_inliers", l.coarse_inliers},
                     {"fitness", l.fitness},
                     {"overlap", l.overlap},
                     {"residual_translation", l.residual_translation},
                     {"residual_rotation_deg", l.residual_rotation * 180.0 / M_PI},
                     {"corrected", l.corrected},
                     {"merged", l.merged}});
  }
  // graph segments: one per odometry epoch (a LIO reset starts a new one, with no edge to the last)
  nlohmann::json epochs = nlohmann::json::array();
  closer.forEachPose([&](int64_t id, const Pose3&) {
    if (epochs.empty() || epochs.back()["epoch"] != closer.epoch(id))
      epochs.push_back({{"epoch", closer.epoch(id)}, {"first_id", id}, {"last_id", id}, {"num_keyframes", 0}});
    epochs.back()["last_id"] = id;
    epochs.back()["num_keyframes"] = epochs.back()["num_keyframes"].get<int64_t>() + 1;
  });
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << nlohmann::json{{"num_keyframes", closer.size()},
                        {"loops", loops},
                        {"corrections", closer.corrections()},
                        {"graph_nodes", closer.graph().poses().size()},
                        {"epochs", epochs},
                        {"odometry_edges_across_epochs", closer.odometryEdgesAcrossEpochs()}}
             .dump(2)
      << "\n";
}

void writeGlobalMapPly(const std::string& path, const LoopCloser& closer, double voxel_size) {
  // keyframe by keyframe into per-voxel sums: memory grows with the mapped area, not the run
  VoxelCentroids centroids(voxel_size);
  // the graph's nodes: a keyframe that joined one saw what it saw, from within merge_distance
  // (all keyframes would cost ten times as long at exit after a long drive on one route)
  for (const auto& [id, pose] : closer.graph().poses())
    for (const Vec3& p : closer.mapCloud(id)) centroids.add(pose * p);
  const Points map = centroids.centroids();
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << map.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (const Vec3& p : map) {
    const float xyz[3] = {static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z())};
    out.write(reinterpret_cast<const char*>(xyz), sizeof(xyz));
  }
}

void writeLoopOutputs(const std::string& dir, const LoopCloser& closer, double map_voxel_size) {
  std::filesystem::create_directories(dir);
  writeKeyframeTrajectory(dir + "/keyframes.tum", closer);
  writeLoopsJson(dir + "/loops.json", closer);
  writeGlobalMapPly(dir + "/global_map.ply", closer, map_voxel_size);
}

}  // namespace livo::loop
