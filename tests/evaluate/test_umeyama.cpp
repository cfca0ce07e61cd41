// Umeyama alignment: exact recovery of known similarities, noise, reflections and degenerate sets.
#include <gtest/gtest.h>

#include <random>

#include "livo/evaluate/umeyama.hpp"

using namespace livo;
using namespace livo::evaluate;

namespace {
std::vector<Vec3> randomPoints(size_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  std::vector<Vec3> pts(n);
  for (auto& p : pts) p = Vec3(u(rng), u(rng), 0.3 * u(rng));
  return pts;
}
}  // namespace

TEST(Umeyama, RecoversAKnownSimilarityExactly) {
  const auto x = randomPoints(50, 1);
  const Mat3 R = so3::Exp(Vec3(0.4, -0.2, 2.5));
  const Vec3 t(3.0, -4.0, 1.5);
  const double s = 2.75;
  std::vector<Vec3> y;
  for (const auto& p : x) y.push_back(s * R * p + t);

  const Similarity3 sim = umeyamaAlignment(x, y, true);
  EXPECT_NEAR(sim.scale, s, 1e-12);
  EXPECT_LT((sim.rotation - R).norm(), 1e-12);
  EXPECT_LT((sim.translation - t).norm(), 1e-11);
  EXPECT_LT((sim.apply(x[7]) - y[7]).norm(), 1e-11);

  std::vector<Vec3> y_rigid;
  for (const auto& p : x) y_rigid.push_back(R * p + t);
  const Similarity3 rigid = umeyamaAlignment(x, y_rigid, false);
  EXPECT_DOUBLE_EQ(rigid.scale, 1.0);
  EXPECT_LT((rigid.rotation - R).norm(), 1e-12);
  EXPECT_LT((rigid.translation - t).norm(), 1e-11);
  EXPECT_NEAR(rigid.rotation.determinant(), 1.0, 1e-12);
}

TEST(Umeyama, NoisyPointsGiveAnEstimateWithinTheNoise) {
  const auto x = randomPoints(2000, 2);
  const Mat3 R = so3::Exp(Vec3(-0.1, 0.05, -1.0));
  const Vec3 t(-20.0, 5.0, 0.5);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.05);
  std::vector<Vec3> y;
  for (const auto& p : x) y.push_back(R * p + t + Vec3(noise(rng), noise(rng), noise(rng)));
  const Similarity3 sim = umeyamaAlignment(x, y, true);
  // Standard errors: rotation ~ sigma / (sqrt(n) * spread) ~ 2e-4 rad, scale ~ 2e-4, translation
  // ~ sigma / sqrt(n) ~ 1e-3 m; the bounds are about five of them.
  EXPECT_LT(so3::Log(Mat3(R.transpose() * sim.rotation)).norm(), 1e-3);
  EXPECT_NEAR(sim.scale, 1.0, 1e-3);
  EXPECT_LT((sim.translation - t).norm(), 5e-3);
}

TEST(Umeyama, NeverReturnsAReflection) {
  const auto x = randomPoints(30, 4);
  std::vector<Vec3> mirrored;
  for (const auto& p : x) mirrored.push_back(Vec3(p.x(), p.y(), -p.z()));
  const Similarity3 sim = umeyamaAlignment(x, mirrored, true);
  EXPECT_NEAR(sim.rotation.determinant(), 1.0, 1e-12);
  EXPECT_LT((sim.rotation.transpose() * sim.rotation - Mat3::Identity()).norm(), 1e-12);
}

TEST(Umeyama, RefusesCollinearOrEmptySets) {
  std::vector<Vec3> line, shifted;
  for (int i = 0; i < 10; ++i) {
    line.push_back(Vec3(i, 2.0 * i, -i));
    shifted.push_back(line.back() + Vec3(1, 1, 1));
  }
  EXPECT_THROW(umeyamaAlignment(line, shifted, false), AlignmentError);
  EXPECT_THROW(umeyamaAlignment({}, {}, false), AlignmentError);
  EXPECT_THROW(umeyamaAlignment(line, {Vec3::Zero()}, false), AlignmentError);
  // Three points that span a plane are enough.
  const std::vector<Vec3> tri = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};
  const std::vector<Vec3> tri_moved = {Vec3(5, 0, 0), Vec3(5, 1, 0), Vec3(4, 0, 0)};
  const Similarity3 sim = umeyamaAlignment(tri, tri_moved, false);
  for (int i = 0; i < 3; ++i) EXPECT_LT((sim.apply(tri[i]) - tri_moved[i]).norm(), 1e-12);
}
