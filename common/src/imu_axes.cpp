#include "livo/imu_axes.hpp"

namespace livo {

namespace {
Mat3 lowerAxes(const Vec3& m) {
  Mat3 L = Mat3::Identity();
  L(1, 0) = m[0];
  L(2, 0) = m[1];
  L(2, 1) = m[2];
  return L;
}
}  // namespace

Mat3 imuSensingAxes(const Vec3& scale, const Vec3& misalignment) {
  return (Vec3::Ones() + scale).asDiagonal() * lowerAxes(misalignment);
}

}  // namespace livo
