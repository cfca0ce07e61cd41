#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "livo/loop/voxel_grid.hpp"

namespace livo::loop {
namespace {

TEST(VoxelGrid, CentroidPerVoxelAndNonFiniteDropped) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Points in{
      {0.1, 0.1, 0.1}, {0.3, 0.3, 0.3}, {1.2, 0.0, 0.0}, {nan, 0, 0}, {0, std::numeric_limits<double>::infinity(), 0}};
  const Points out = centroidPerVoxel(in, 1.0);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_TRUE(out[0].isApprox(Vec3(0.2, 0.2, 0.2)));
  EXPECT_TRUE(out[1].isApprox(Vec3(1.2, 0.0, 0.0)));
}

TEST(VoxelGrid, OutputIndependentOfInputOrder) {
  Points a;
  for (int i = 0; i < 500; ++i) a.push_back(Vec3(std::sin(i * 1.3) * 5, std::cos(i * 0.7) * 5, i * 0.01));
  Points b(a.rbegin(), a.rend());
  const Points oa = centroidPerVoxel(a, 0.5), ob = centroidPerVoxel(b, 0.5);
  ASSERT_EQ(oa.size(), ob.size());
  for (size_t i = 0; i < oa.size(); ++i) EXPECT_LT((oa[i] - ob[i]).norm(), 1e-12);
  EXPECT_LT(oa.size(), a.size());
}

TEST(VoxelGrid, EmptyInput) { EXPECT_TRUE(centroidPerVoxel({}, 0.5).empty()); }

// global_map.ply is streamed keyframe by keyframe into VoxelCentroids: the same centroids, in the
// same order, bit for bit, as centroidPerVoxel of every point at once (negative coordinates too).
TEST(VoxelGrid, StreamedCentroidsEqualTheDownsamplingOfAllPoints) {
  Points a;
  for (int i = 0; i < 5000; ++i)
    a.push_back(Vec3(std::sin(i * 1.3) * 7, std::cos(i * 0.7) * 7, std::sin(i * 0.11) * 2));
  a.push_back(Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0));
  for (double voxel : {0.2, 0.5, 0.0}) {
    VoxelCentroids streamed(voxel);
    for (const Vec3& p : a) streamed.add(p);
    const Points expected = centroidPerVoxel(a, voxel), got = streamed.centroids();
    ASSERT_EQ(got.size(), expected.size()) << voxel;
    EXPECT_EQ(streamed.voxels(), expected.size());
    for (size_t i = 0; i < got.size(); ++i) ASSERT_TRUE(got[i] == expected[i]) << voxel << " " << i;
  }
}

}  // namespace
}  // namespace livo::loop
