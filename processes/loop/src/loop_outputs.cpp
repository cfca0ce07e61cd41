#include "livo/loop/loop_outputs.hpp"

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "livo/loop/loop_information.hpp"
#include "livo/loop/voxel_grid.hpp"
#include "livo/spill_file.hpp"
#include "livo/time.hpp"
#include "livo/trajectory_io.hpp"

namespace livo::loop {

namespace {
std::vector<double> rowMajor(const Mat6& M) {
  std::vector<double> v(36);
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c) v[6 * r + c] = M(r, c);
  return v;
}
}  // namespace

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
    loops.push_back(
        {{"from_id", l.from_id},
         {"to_id", l.to_id},
         {"from_time", toSeconds(l.from_utime)},
         {"to_time", toSeconds(l.to_utime)},
         {"T_to_from", {{"translation", {t.x(), t.y(), t.z()}}, {"rotation_wxyz", {q.w(), q.x(), q.y(), q.z()}}}},
         {"information", rowMajor(informationFromCovariance(l.covariance))},
         {"coarse_inliers", l.coarse_inliers},
         {"fitness", l.fitness},
         {"overlap", l.overlap},
         {"residual_translation", l.residual_translation},
         {"residual_rotation_deg", l.residual_rotation * 180.0 / M_PI},
         {"correction_chi2", l.correction_chi2},
         {"optimum_shift_translation", l.optimum_shift_translation},
         {"optimum_shift_rotation_deg", l.optimum_shift_rotation * 180.0 / M_PI},
         {"odometry_sigma_rotation_deg",
          {std::sqrt(l.odometry_covariance(0, 0)) * 180.0 / M_PI, std::sqrt(l.odometry_covariance(1, 1)) * 180.0 / M_PI,
           std::sqrt(l.odometry_covariance(2, 2)) * 180.0 / M_PI}},
         {"odometry_sigma_translation",
          {std::sqrt(l.odometry_covariance(3, 3)), std::sqrt(l.odometry_covariance(4, 4)),
           std::sqrt(l.odometry_covariance(5, 5))}},
         {"corrected", l.corrected},
         {"merged", l.merged},
         {"sigma_rotation_deg",
          {std::sqrt(l.covariance(0, 0)) * 180.0 / M_PI, std::sqrt(l.covariance(1, 1)) * 180.0 / M_PI,
           std::sqrt(l.covariance(2, 2)) * 180.0 / M_PI}},
         {"sigma_translation",
          {std::sqrt(l.covariance(3, 3)), std::sqrt(l.covariance(4, 4)), std::sqrt(l.covariance(5, 5))}}});
  }
  nlohmann::json refused = nlohmann::json::array();
  size_t refused_by_odometry = 0;
  for (const RefusedLoop& f : closer.refusedLoops()) {
    refused_by_odometry += f.against == "odometry";
    const Vec3 t = f.T_to_from.translation();
    refused.push_back({{"from_id", f.from_id},
                       {"to_id", f.to_id},
                       {"merged", f.merged},
                       {"T_to_from_translation", {t.x(), t.y(), t.z()}},
                       {"against", f.against},
                       {"against_from_id", f.against_from_id},
                       {"against_to_id", f.against_to_id},
                       {"chi2", f.chi2},
                       {"path", f.path},
                       {"reason", f.reason}});
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
                        {"registrations", closer.registrations()},
                        {"registrations_rejected", closer.rejectedRegistrations().counts()},
                        {"refused_loops", refused},
                        {"num_refused_loops", closer.refusedLoops().size()},
                        {"refused_against_odometry", refused_by_odometry},
                        {"refused_against_loop", closer.refusedLoops().size() - refused_by_odometry},
                        {"graph_nodes", closer.graph().poses().size()},
                        {"epochs", epochs},
                        {"odometry_edges_across_epochs", closer.odometryEdgesAcrossEpochs()}}
             .dump(2)
      << "\n";
}

void writeGlobalMapPly(const std::string& path, const LoopCloser& closer, double voxel_size) {
  // The graph's nodes (a keyframe that joined one saw what it saw, from within merge_distance),
  // their map clouds at the final poses, downsampled to voxel centroids. Built slab by slab (x
  // ranges of kSlabVoxels voxels): the points go to a scratch file per slab first, so memory holds
  // the voxels of one slab, not of the whole map (1.1 M voxels, ~130 MB, after the 30 min soak).
  // Slabs in x order, each sorted by voxel, give VoxelCentroids' order over the whole map, and each
  // voxel sums its points in the same order: the file is what one VoxelCentroids would give.
  constexpr int64_t kSlabVoxels = 64;
  constexpr size_t kFlushPoints = 8192;
  struct Slab {
    std::vector<Vec3> buffer;
    std::vector<SpillFile::Record> records;
  };
  std::map<int64_t, Slab> slabs;
  std::unique_ptr<SpillFile> scratch;
  const double inv = voxel_size > 0 ? 1.0 / voxel_size : 0.0;
  for (const auto& [id, pose] : closer.graph().poses())
    for (const Vec3& p : closer.mapCloud(id)) {
      const Vec3 q = pose * p;
      if (!q.allFinite()) continue;
      const int64_t vx = static_cast<int64_t>(std::floor(q.x() * inv));
      Slab& slab = slabs[vx >= 0 ? vx / kSlabVoxels : -((-vx + kSlabVoxels - 1) / kSlabVoxels)];
      slab.buffer.push_back(q);
      if (slab.buffer.size() >= kFlushPoints) {
        if (!scratch) scratch = std::make_unique<SpillFile>();
        slab.records.push_back(scratch->append(slab.buffer.data(), slab.buffer.size() * sizeof(Vec3)));
        slab.buffer.clear();
      }
    }
  if (!scratch) scratch = std::make_unique<SpillFile>();
  std::vector<SpillFile::Record> output;  // each slab's centroids as float, in slab order
  uint64_t vertices = 0;
  std::vector<uint8_t> bytes;
  for (auto& [index, slab] : slabs) {
    VoxelCentroids centroids(voxel_size);
    for (const SpillFile::Record& r : slab.records) {
      scratch->read(r, &bytes);
      for (size_t i = 0; i + sizeof(Vec3) <= bytes.size(); i += sizeof(Vec3)) {
        Vec3 q;
        std::memcpy(q.data(), bytes.data() + i, sizeof(Vec3));
        centroids.add(q);
      }
      scratch->release(r);
    }
    for (const Vec3& q : slab.buffer) centroids.add(q);
    Slab().buffer.swap(slab.buffer);
    std::vector<float> xyz;
    for (const Vec3& c : centroids.centroids())
      xyz.insert(xyz.end(), {static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())});
    vertices += xyz.size() / 3;
    output.push_back(scratch->append(xyz.data(), xyz.size() * sizeof(float)));
  }
  std::ofstream out(path, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write " + path);
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << vertices
      << "\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (const SpillFile::Record& r : output) {
    scratch->read(r, &bytes);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  }
  if (!out) throw std::runtime_error("cannot write " + path);
}

void writeLoopOutputs(const std::string& dir, const LoopCloser& closer, double map_voxel_size) {
  std::filesystem::create_directories(dir);
  writeKeyframeTrajectory(dir + "/keyframes.tum", closer);
  writeLoopsJson(dir + "/loops.json", closer);
  writeGlobalMapPly(dir + "/global_map.ply", closer, map_voxel_size);
}

}  // namespace livo::loop
