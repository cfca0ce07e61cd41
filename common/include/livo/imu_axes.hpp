// The axes a MEMS IMU senses along, as the simulator draws them (livo-lio models a full K,
// lio/imu_intrinsics.hpp): a reading is K u + bias with
//   K = (I + diag(scale)) L,  L = [[1, 0, 0], [m0, 1, 0], [m1, m2, 1]]
// (lower triangular: the sensing x axis defines the body x, sensing y lies in the body x-y plane
// leaning by m0 towards x, sensing z leans by m1 towards x and m2 towards y: six parameters per
// triad, the part of a 3x3 error that is not a rotation of the whole triad, as in Kalibr's and
// OpenVINS's IMU models). A real gyro triad is also turned against the accelerometer's by up to a
// few mrad; neither the simulator nor the filter models that.
#pragma once

#include "livo/so3.hpp"

namespace livo {

/// K = (I + diag(scale)) L(misalignment): relative scale errors, misalignment in rad.
Mat3 imuSensingAxes(const Vec3& scale, const Vec3& misalignment);

}  // namespace livo
