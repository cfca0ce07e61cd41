#include "synthetic_scenes.hpp"

#include <cmath>
#include <random>

namespace livo::loop::testing {

namespace {
// Samples the rectangle origin + u*a + v*b (u, v in [0, 1]) on a grid of `spacing`.
void sampleRect(const Vec3& origin, const Vec3& a, const Vec3& b, double spacing, Points& out) {
  const int na = std::max(1, static_cast<int>(a.norm() / spacing));
  const int nb = std::max(1, static_cast<int>(b.norm() / spacing));
  for (int i = 0; i <= na; ++i)
    for (int j = 0; j <= nb; ++j) out.push_back(origin + a * (double(i) / na) + b * (double(j) / nb));
}
void sampleBox(const Vec3& c, const Vec3& size, double yaw, double spacing, Points& out) {
  const Mat3 R = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
  const Vec3 ex = R * Vec3(size.x(), 0, 0), ey = R * Vec3(0, size.y(), 0), ez(0, 0, size.z());
  const Vec3 o = c - 0.5 * ex - 0.5 * ey;
  sampleRect(o, ex, ez, spacing, out);
  sampleRect(o, ey, ez, spacing, out);
  sampleRect(o + ex, ey, ez, spacing, out);
  sampleRect(o + ey, ex, ez, spacing, out);
  sampleRect(o + ez, ex, ey, spacing, out);
}
void samplePole(const Vec3& base, double radius, double height, double spacing, Points& out) {
  const int nr = std::max(6, static_cast<int>(2 * M_PI * radius / spacing));
  const int nh = static_cast<int>(height / spacing);
  for (int i = 0; i < nr; ++i)
    for (int j = 0; j <= nh; ++j) {
      const double a = 2 * M_PI * i / nr;
      out.push_back(base + Vec3(radius * std::cos(a), radius * std::sin(a), j * spacing));
    }
}
}  // namespace

Points makeScene(uint32_t seed, double spacing) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Points pts;
  // Ground with a gentle slope in one corner.
  const double g = spacing * 3;
  for (double x = -30; x <= 30; x += g)
    for (double y = -30; y <= 30; y += g) pts.push_back(Vec3(x, y, x > 10 && y > 10 ? 0.1 * (x - 10) : 0.0));
  for (int i = 0; i < 14; ++i) {  // boxes (buildings, cars, containers) of varied sizes and yaws
    const Vec3 c(-26 + 52 * u(rng), -26 + 52 * u(rng), 0.0);
    sampleBox(c, Vec3(1.5 + 6 * u(rng), 1.5 + 5 * u(rng), 1.0 + 4 * u(rng)), M_PI * u(rng), spacing * 2, pts);
  }
  for (int i = 0; i < 20; ++i)
    samplePole(Vec3(-28 + 56 * u(rng), -28 + 56 * u(rng), 0), 0.15 + 0.2 * u(rng), 2 + 4 * u(rng), spacing * 2, pts);
  for (int i = 0; i < 5; ++i) {  // free-standing walls at odd angles
    const double a = M_PI * u(rng);
    const Vec3 o(-25 + 50 * u(rng), -25 + 50 * u(rng), 0);
    sampleRect(o, Vec3(std::cos(a), std::sin(a), 0) * (4 + 8 * u(rng)), Vec3(0, 0, 2 + 2 * u(rng)), spacing * 2, pts);
  }
  return pts;
}

Points viewFrom(const Points& scene, const Vec3& viewpoint, double yaw, double range, double noise, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, noise);
  const Pose3 T_frame = yawPose(yaw, viewpoint);
  const Pose3 inv = T_frame.inverse();
  Points out;
  for (const Vec3& p : scene) {
    if ((p - viewpoint).head<2>().norm() > range) continue;
    Vec3 q = inv * p;
    if (noise > 0) q += Vec3(n(rng), n(rng), n(rng));
    out.push_back(q);
  }
  return out;
}

Points corridorView(double x0, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 0.01);
  Points out;
  for (double x = -15.0; x <= 15.0; x += 0.1)
    for (double u = -1.5; u <= 1.5; u += 0.1) {
      out.push_back(Vec3(x, u, -1.5 + n(rng)));
      out.push_back(Vec3(x, u, 1.5 + n(rng)));
      out.push_back(Vec3(x, -1.5 + n(rng), u));
      out.push_back(Vec3(x, 1.5 + n(rng), u));
    }
  for (Vec3& p : out) p.x() -= x0;
  return out;
}

Pose3 yawPose(double yaw, const Vec3& t) {
  Pose3 T = Pose3::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
  T.translation() = t;
  return T;
}

double rotationErrorDeg(const Pose3& a, const Pose3& b) {
  return so3::Log(Mat3(a.linear().transpose() * b.linear())).norm() * 180.0 / M_PI;
}
double translationError(const Pose3& a, const Pose3& b) { return (a.translation() - b.translation()).norm(); }

}  // namespace livo::loop::testing
