#include "livo/evaluate/four_dof_alignment.hpp"

#include <cmath>
#include <limits>
#include <string>

namespace livo::evaluate {

// Minimise sum_k |R_z(psi) x_k + t - y_k|^2 over the yaw psi and the translation t.
// For a fixed psi the optimal t is mean(y) - R_z(psi) mean(x); with the centred points x', y' the
// cost becomes sum_k |R_z(psi) x'_k - y'_k|^2 = const - 2 sum_k y'_k . R_z(psi) x'_k. R_z leaves z
// alone, so only the horizontal components depend on psi:
//   sum_k y'_k . R_z(psi) x'_k = cos(psi) a + sin(psi) b + sum_k x'_kz y'_kz,
//   a = sum_k (x'_kx y'_kx + x'_ky y'_ky),  b = sum_k (x'_kx y'_ky - x'_ky y'_kx),
// i.e. a and b are the trace and the antisymmetric part of the 2-D cross-covariance
// H = sum_k x'_k,xy y'_k,xy^T: a = H_xx + H_yy, b = H_xy - H_yx. cos(psi) a + sin(psi) b is
// largest, equal to hypot(a, b), at psi = atan2(b, a); undefined when a = b = 0.
// The z offset is the difference of the mean heights (the z row of t).
Similarity3 fourDofAlignment(const std::vector<Vec3>& source, const std::vector<Vec3>& target) {
  const PairedCentroids centroids = pairedCentroids(source, target);
  const Vec3 &mean_x = centroids.source, &mean_y = centroids.target;

  double a = 0.0, b = 0.0, spread_x = 0.0, spread_y = 0.0;
  for (size_t i = 0; i < source.size(); ++i) {
    const Vec3 dx = source[i] - mean_x, dy = target[i] - mean_y;
    a += dx.x() * dy.x() + dx.y() * dy.y();
    b += dx.x() * dy.y() - dx.y() * dy.x();
    spread_x += dx.head<2>().squaredNorm();
    spread_y += dy.head<2>().squaredNorm();
  }
  // |(a, b)| <= sqrt(spread_x spread_y) (Cauchy-Schwarz); at rounding level of it the yaw is noise.
  if (!(std::hypot(a, b) > 1e3 * std::numeric_limits<double>::epsilon() * std::sqrt(spread_x * spread_y)) ||
      !(spread_x > 0.0 && spread_y > 0.0))
    throw AlignmentError("cannot align yaw: the " + std::to_string(source.size()) +
                         " associated positions have no horizontal spread (one point, or a vertical line)");

  const double yaw = std::atan2(b, a);
  Similarity3 sim;
  sim.rotation = Eigen::AngleAxisd(yaw, Vec3::UnitZ()).toRotationMatrix();
  sim.translation = mean_y - sim.rotation * mean_x;
  return sim;
}

double yawOf(const Mat3& rotation_about_z) { return std::atan2(rotation_about_z(1, 0), rotation_about_z(0, 0)); }

}  // namespace livo::evaluate
