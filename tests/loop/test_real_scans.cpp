// Coarse-to-fine registration of real scans against their reference transforms: the KITTI 07
// keyframes (graph.txt poses), the KITTI 00 frame pair (ground truth via the sequence's
// velodyne-to-camera calibration) and small_gicp's scan pair (T_target_source.txt).
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "livo/loop/loop_closer.hpp"
#include "livo/loop/loop_registration.hpp"
#include "livo/loop/voxel_grid.hpp"
#include "real_scans.hpp"
#include "synthetic_scenes.hpp"

namespace livo::loop {
namespace {
using namespace livo::loop::testing;

const std::string kLidar = std::string(LIVO_SHARED_DATA) + "/lidar/";

struct Prepared {
  CoarseFeatures coarse;
  GicpCloud fine;
};
// With the options livo-loop runs with (the fine voxel size unless given).
Prepared prepare(const Points& raw, double fine_voxel = LoopCloserOptions{}.fine_voxel_size) {
  const LoopCloserOptions o;
  return {computeCoarseFeatures(raw, o.coarse),
          GicpCloud::build(centroidPerVoxel(raw, fine_voxel), o.covariance_neighbors)};
}

LoopRegistrationResult registerPair(const Prepared& source, const Prepared& target) {
  return registerLoop(source.coarse, target.coarse, source.fine, target.fine, LoopCloserOptions{}.registration);
}

void report(const std::string& what, const LoopRegistrationResult& r, const Pose3& truth) {
  std::printf(
      "[real-scan] %-22s coarse %.3f deg %.3f m | fine %.3f deg %.3f m | inliers %d fitness %.4f overlap %.2f ratio "
      "%.3f %s\n",
      what.c_str(), rotationErrorDeg(r.coarse.T_target_source, truth),
      translationError(r.coarse.T_target_source, truth), rotationErrorDeg(r.T_target_source, truth),
      translationError(r.T_target_source, truth), r.coarse.num_inliers, r.fine.fitness, r.fine.overlap,
      r.fine.translation_eigenvalue_ratio, r.accepted ? "accepted" : r.reason.c_str());
}

TEST(RealScans, KittiSevenKeyframesRegisterToGraphPoses) {
  const std::vector<Pose3> poses = readGraphPoses(kLidar + "kitti_07_dump/graph.txt");
  ASSERT_EQ(poses.size(), 5u);
  std::vector<Prepared> kf;
  for (int i = 0; i < 5; ++i) {
    char name[64];
    std::snprintf(name, sizeof(name), "kitti_07_dump/%06d/points.bin", i);
    kf.push_back(prepare(readXyzBin(kLidar + name)));
  }
  int accepted = 0;
  for (int i = 0; i + 1 < 5; ++i) {
    const int j = i + 1;
    const Pose3 truth = poses[i].inverse() * poses[j];  // T_i_j: source j onto target i
    const LoopRegistrationResult r = registerPair(kf[j], kf[i]);
    report("kitti07 " + std::to_string(j) + "->" + std::to_string(i), r, truth);
    // A wrong loop is worse than none: a pair may be refused (too few coarse inliers), but what is
    // accepted must be right. The well-overlapping pairs must be accepted. graph.txt is an
    // estimated trajectory, not ground truth; the fine results agree with it to 0.1 deg and 3 cm.
    if (i < 3) {
      EXPECT_TRUE(r.accepted) << r.reason;
    }
    if (r.accepted) {
      ++accepted;
      EXPECT_LT(rotationErrorDeg(r.T_target_source, truth), 0.25);
      EXPECT_LT(translationError(r.T_target_source, truth), 0.05);
    }
  }
  EXPECT_GE(accepted, 3);
}

TEST(RealScans, KittiZeroFramePairMatchesGroundTruth) {
  // KITTI odometry sequence 00 calib.txt, Tr (velodyne -> camera 0), 3x4 row-major.
  Eigen::Matrix4d tr;
  tr << 4.276802385584e-04, -9.999672484946e-01, -8.084491683471e-03, -1.198459927713e-02, -7.210626507497e-03,
      8.081198471645e-03, -9.999413164504e-01, -5.403984729748e-02, 9.999738645903e-01, 4.859485810390e-04,
      -7.206933692422e-03, -2.921968648686e-01, 0, 0, 0, 1;
  Eigen::Matrix4d c1;
  c1 << 9.999978e-01, 5.272628e-04, -2.066935e-03, -4.690294e-02, -5.296506e-04, 9.999992e-01, -1.154865e-03,
      -2.839928e-02, 2.066324e-03, 1.155958e-03, 9.999971e-01, 8.586941e-01, 0, 0, 0, 1;
  Pose3 Tr(tr), C1(c1);
  Tr.linear() = so3::normalize(Tr.linear());
  C1.linear() = so3::normalize(C1.linear());
  const Pose3 truth = Tr.inverse() * C1 * Tr;  // velodyne 1 onto velodyne 0 (pose 0 is identity)
  const Prepared f0 = prepare(readXyzBin(kLidar + "kitti_00/000000.bin"));
  const Prepared f1 = prepare(readXyzBin(kLidar + "kitti_00/000001.bin"));
  const LoopRegistrationResult r = registerPair(f1, f0);
  report("kitti00 1->0", r, truth);
  EXPECT_TRUE(r.accepted) << r.reason;
  // KITTI sweeps are not motion-compensated: the car moves 0.86 m during this sweep, so a rigid
  // registration cannot agree with the ground truth much better than a quarter of that.
  EXPECT_LT(rotationErrorDeg(r.T_target_source, truth), 0.3);
  EXPECT_LT(translationError(r.T_target_source, truth), 0.25);
}

TEST(RealScans, SmallGicpPairMatchesReference) {
  const Pose3 truth = readMatrix4(kLidar + "scan_pair/T_target_source.txt");
  // Fine clouds at small_gicp's test resolution (0.3 m), like for like with its reference. At
  // livo-loop's 0.4 m the result moves 0.8 deg from it, nearly all in roll; which of the two is
  // nearer the truth this pair cannot tell (on simulated keyframes with ground truth, these
  // settings leave 0.1 deg of roll and pitch error).
  const Prepared source = prepare(readFloatPly(kLidar + "scan_pair/source.ply"), 0.3);
  const Prepared target = prepare(readFloatPly(kLidar + "scan_pair/target.ply"), 0.3);
  const LoopRegistrationResult r = registerPair(source, target);
  report("scan_pair", r, truth);
  EXPECT_TRUE(r.accepted) << r.reason;
  // The reference is small_gicp's own registration result, not independent ground truth (its own
  // tests accept 2.5 deg and 0.2 m around it); GICP here lands 0.46 deg and 1 cm from it.
  EXPECT_LT(rotationErrorDeg(r.T_target_source, truth), 0.5);
  EXPECT_LT(translationError(r.T_target_source, truth), 0.03);
}

}  // namespace
}  // namespace livo::loop
