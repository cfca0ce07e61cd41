// Plane fitting, the point-to-plane residual's Jacobian, and the matching options for a noisier LiDAR.
#include <gtest/gtest.h>

#include <random>

#include "livo/lio/point_to_plane.hpp"
#include "livo/lio/scan_to_map.hpp"

using namespace livo;
using namespace livo::lio;

// min_planarity for these tests: refuses only (nearly) collinear points
constexpr double kCollinearOnly = 1e-4;

TEST(PointToPlane, FitRecoversAPlane) {
  const Vec3 n = Vec3(0.3, -0.2, 0.9).normalized();
  const double d = -1.7;
  // points on n.x + d = 0
  const Vec3 c = -d * n;
  const Vec3 u = n.unitOrthogonal(), v = n.cross(u);
  std::vector<Vec3> pts;
  const double uv[5][2] = {{0, 0}, {0.4, 0.1}, {-0.3, 0.5}, {0.2, -0.6}, {-0.5, -0.2}};
  for (const auto& q : uv) pts.push_back(c + q[0] * u + q[1] * v);
  Plane p;
  ASSERT_TRUE(fitPlane(pts.data(), 5, 0.01, &p, kCollinearOnly));
  EXPECT_NEAR(std::abs(p.normal.dot(n)), 1.0, 1e-12);
  for (const auto& x : pts) EXPECT_NEAR(p.distance(x), 0.0, 1e-12);
  // a point 0.5 m off the plane on the normal's side
  EXPECT_NEAR(std::abs(p.distance(c + 0.5 * n)), 0.5, 1e-12);

  // thickness check: one point 20 cm off; the fit leans towards it, but it stays > 5 cm away
  pts[2] += 0.2 * n;
  EXPECT_FALSE(fitPlane(pts.data(), 5, 0.05, &p, kCollinearOnly));
  ASSERT_TRUE(fitPlane(pts.data(), 5, 0.2, &p, kCollinearOnly));
  double worst = 0.0;
  for (const auto& x : pts) worst = std::max(worst, std::abs(p.distance(x)));
  EXPECT_GT(worst, 0.05);
  EXPECT_LT(worst, 0.2);
}

TEST(PointToPlane, RejectsCollinearAndTooFewPoints) {
  std::vector<Vec3> line;
  for (int i = 0; i < 5; ++i) line.emplace_back(0.1 * i, 0.2 * i, 0.0);
  Plane p;
  EXPECT_FALSE(fitPlane(line.data(), 5, 0.1, &p, kCollinearOnly));
  EXPECT_FALSE(fitPlane(line.data(), 2, 0.1, &p, kCollinearOnly));
}

TEST(PointToPlane, JacobianMatchesNumericDifferentiation) {
  PointToPlaneResidual r;
  r.p_body = Vec3(3.0, -1.0, 0.5);
  r.plane.normal = Vec3(0.2, 0.9, -0.3).normalized();
  r.plane.offset = 0.7;
  const Mat3 R = so3::Exp(Vec3(0.4, -0.2, 1.1));
  const Vec3 t(1.0, 2.0, -0.5);
  const Row6 J = r.jacobian(R);
  const double h = 1e-6;
  for (int i = 0; i < 6; ++i) {
    Vec6 d = Vec6::Zero();
    d[i] = h;
    const Pose3 Tp = se3::boxplus(se3::fromRotationTranslation(R, t), d);
    const Pose3 Tm = se3::boxplus(se3::fromRotationTranslation(R, t), -d);
    const double num = (r.value(Tp.linear(), Tp.translation()) - r.value(Tm.linear(), Tm.translation())) / (2 * h);
    EXPECT_NEAR(J[i], num, 1e-8) << i;
  }
}

// Matching options scaled to the LiDAR's range noise: unchanged at the 1 cm they were tuned at; at
// 3 cm the options tuned for 1 cm refuse 4 in 10 true planes through noisy neighbours (each of 5
// points within 1 sigma of the fit), the scaled ones 1 in 10 (8 points within 2 sigma), and the
// residual sigma is the 1 cm floor combined with the noise of the point and of the fitted plane.
TEST(PointToPlane, MatchingOptionsScaleWithTheRangeNoise) {
  const ScanToMapOptions tuned;
  const ScanToMapOptions at1cm = matchingForRangeNoise(0.01, tuned);
  EXPECT_EQ(at1cm.plane.num_neighbors, tuned.plane.num_neighbors);
  EXPECT_EQ(at1cm.plane.max_plane_thickness, tuned.plane.max_plane_thickness);
  EXPECT_EQ(at1cm.point_noise_std, tuned.point_noise_std);

  constexpr double kSigma = 0.03;
  const ScanToMapOptions at3cm = matchingForRangeNoise(kSigma, tuned);
  EXPECT_EQ(at3cm.plane.num_neighbors, tuned.plane.num_neighbors + 3);
  EXPECT_DOUBLE_EQ(at3cm.plane.max_plane_thickness, 2.0 * kSigma);
  const double floor2 = 0.03 * 0.03 - 1.2 * 0.01 * 0.01;
  EXPECT_NEAR(at3cm.point_noise_std, std::sqrt(floor2 + (1.0 + 1.0 / 8.0) * kSigma * kSigma), 1e-12);

  // planes through k neighbours spread over 1.5 m with 3 cm noise along the normal
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> spread(-0.75, 0.75);
  std::normal_distribution<double> noise(0.0, kSigma);
  auto acceptance = [&](const ScanToMapOptions& o) {
    constexpr int kTrials = 4000;
    int accepted = 0;
    for (int t = 0; t < kTrials; ++t) {
      Vec3 nb[32];
      for (int i = 0; i < o.plane.num_neighbors; ++i) nb[i] = Vec3(spread(rng), spread(rng), noise(rng));
      Plane plane;
      accepted += fitPlane(nb, o.plane.num_neighbors, o.plane.max_plane_thickness, &plane, o.plane.min_planarity);
    }
    return static_cast<double>(accepted) / kTrials;
  };
  const double a_tuned = acceptance(tuned), a_scaled = acceptance(at3cm);
  EXPECT_LT(a_tuned, 0.70);  // measured 0.615: 4 of 10 true planes lost
  EXPECT_GT(a_scaled, 0.85);  // measured 0.898
}
