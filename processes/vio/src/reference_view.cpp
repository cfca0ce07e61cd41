#include "livo/vio/reference_view.hpp"

namespace livo::vio {

Eigen::Matrix<double, 2, 6> pixelExtrinsicJacobian(const Eigen::Matrix<double, 2, 3>& J_proj, const Vec3& p_C,
                                                   const Mat3& R_I_C) {
  // p_C = Exp(-δφ) R_I_C^T (p_I - t_I_C - δρ): d p_C / d δφ = [p_C]x, d p_C / d δρ = -R_I_C^T
  Eigen::Matrix<double, 2, 6> J;
  J.leftCols<3>() = J_proj * so3::hat(p_C);
  J.rightCols<3>() = -J_proj * R_I_C.transpose();
  return J;
}

bool projectIntoReference(const CameraProjection& camera, const ReferenceView& v, const SensorCalibration& c,
                          const Vec3& p_W, Eigen::Vector2d* pixel, Mat27* J, Eigen::Matrix<double, 2, 3>* J_point) {
  // the body when the image was really taken, by the time shift known now
  const double dt = c.dt - v.time_shift;
  const Mat3 R = dt != 0.0 ? Mat3(v.T_W_I.linear() * so3::Exp(v.omega_I * dt)) : v.T_W_I.linear();
  const Vec3 p = v.T_W_I.translation() + v.vel_W * dt;
  const Vec3 p_I = R.transpose() * (p_W - p);
  const Vec3 p_C = c.rot.transpose() * (p_I - c.pos);
  if (!J && !J_point) return camera.project(p_C, pixel);
  Eigen::Matrix<double, 2, 3> J_proj;
  if (!camera.projectWithJacobian(p_C, pixel, &J_proj)) return false;
  if (J) {
    J->leftCols<6>() = pixelExtrinsicJacobian(J_proj, p_C, c.rot);
    // p_I = Exp(-ω dt) R^T (p_W - p - v dt): d p_I / d dt = p_I x ω - R^T v
    J->col(6) = J_proj * c.rot.transpose() * (p_I.cross(v.omega_I) - R.transpose() * v.vel_W);
  }
  if (J_point) *J_point = J_proj * c.rot.transpose() * R.transpose();
  return true;
}

}  // namespace livo::vio
