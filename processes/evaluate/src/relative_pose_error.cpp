#include "livo/evaluate/relative_pose_error.hpp"

#include <cmath>
#include <stdexcept>

namespace livo::evaluate {

double rotationAngle(const Mat3& R) {
  const double trace = R(0, 0) + R(1, 1) + R(2, 2);
  const double decision[4] = {R(0, 0), R(1, 1), R(2, 2), trace};
  int choice = 0;
  for (int c = 1; c < 4; ++c)
    if (decision[c] > decision[choice]) choice = c;
  double q[4];  // x, y, z, w
  if (choice == 3) {
    q[0] = R(2, 1) - R(1, 2);
    q[1] = R(0, 2) - R(2, 0);
    q[2] = R(1, 0) - R(0, 1);
    q[3] = 1.0 + trace;
  } else {
    const int i = choice, j = (i + 1) % 3, k = (j + 1) % 3;
    q[i] = 1.0 - trace + 2.0 * R(i, i);
    q[j] = R(j, i) + R(i, j);
    q[k] = R(k, i) + R(i, k);
    q[3] = R(k, j) - R(j, k);
  }
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const double vec = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2]) / norm;
  const double w = std::abs(q[3]) / norm;
  return 2.0 * std::atan2(vec, w);
}

RelativePoseError relativePoseError(const std::vector<Pose3>& gt, const std::vector<Pose3>& est,
                                    const RelativePoseErrorOptions& options) {
  if (gt.size() != est.size()) throw std::invalid_argument("relativePoseError: pose lists differ in length");
  if (options.delta < 1) throw std::invalid_argument("relativePoseError: delta must be at least 1 frame");
  RelativePoseError rpe;
  const size_t delta = static_cast<size_t>(options.delta);
  const size_t stride = options.all_pairs ? 1 : delta;
  for (size_t i = 0; i + delta < gt.size(); i += stride) {
    const size_t j = i + delta;
    const Pose3 gt_rel = gt[i].inverse() * gt[j];
    const Pose3 est_rel = est[i].inverse() * est[j];
    const Pose3 E = gt_rel.inverse() * est_rel;
    rpe.from.push_back(i);
    rpe.to.push_back(j);
    rpe.translation_m.push_back(E.translation().norm());
    rpe.rotation_deg.push_back(rotationAngle(E.linear()) * 180.0 / M_PI);
  }
  return rpe;
}

}  // namespace livo::evaluate
