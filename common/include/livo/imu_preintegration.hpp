// On-manifold IMU preintegration (Forster, Carlone, Dellaert, Scaramuzza, TRO 2017): the
// rotation, velocity and position increments between two states in the frame of the first,
// their 9x9 covariance, and first-order corrections for a change of the biases, for a factor
// between states i and j of a factor graph (Ceres AutoDiff through the templated residual).
//
//   ImuPreintegration pre(bg, ba, ImuPreintegrationNoise::fromRig(rig.imu));
//   for (each interval k between i and j) pre.integrate(0.5 * (w_k + w_k1), 0.5 * (a_k + a_k1), dt);
//   Eigen::Matrix<double, 9, 1> r = pre.residual(R_i, p_i, v_i, R_j, p_j, v_j, bg, ba, g_W);
//
// Discretisation. With w = gyro - bg, a = accel - ba and the increment ΔR_k so far,
//   ΔR_{k+1} = ΔR_k Exp(w dt),
//   Δv_{k+1} = Δv_k + ΔR_m a dt,  Δp_{k+1} = Δp_k + Δv_k dt + ½ ΔR_m a dt²,  ΔR_m = ΔR_k Exp(½ w dt):
// Forster's scheme with the specific force rotated by the interval's middle rotation instead of
// its start. Given the mean of the interval's two samples (or the mid value) this is second order:
// the error over a fixed time falls with dt². Forster's ΔR_k there makes velocity and position
// first order, an error of about ½ dt |w x a| per second (0.012 m/s per second at 200 Hz turning
// at 0.5 rad/s against gravity), several times the accelerometer noise (2e-3 m/s over a second at
// the rig's default density). The bias Jacobians and the covariance below are the exact
// linearisation of this discrete recursion.
//
// Error conventions (Forster): the preintegrated values are the true ones perturbed as
// ΔR̃ = ΔR Exp(δφ), Δṽ = Δv + δv, Δp̃ = Δp + δp, covariance() = Cov([δφ, δv, δp]); a bias change
// δb corrects as ΔR(b + δb) ≈ ΔR(b) Exp(dR_dbg δbg), Δv(b + δb) ≈ Δv(b) + dV_dbg δbg + dV_dba δba,
// and the same for Δp. Rotation vectors follow so3.hpp (right perturbations).
#pragma once

#include <cmath>

#include "livo/sensor_rig.hpp"
#include "livo/so3.hpp"

namespace livo {

using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;

// ---- Templated SO(3) maps on quaternions, for residuals differentiated by Ceres' Jets (T is a
// double or a ceres::Jet; nothing here depends on Ceres). Quaternions in Eigen's storage order
// [x, y, z, w]. The wheel preintegration uses them too.

/// Below this squared angle (and squared half-angle sine) the maps use their Taylor series: the
/// first omitted term is below 1e-24 relative, and the series stay differentiable at zero, where
/// sqrt(|v|²) is not.
constexpr double kQuaternionSeriesThreshold2 = 1e-12;

/// Exp(r) as a unit quaternion, exact to rounding and differentiable at r = 0.
template <class T>
Eigen::Quaternion<T> quaternionExp(const Eigen::Matrix<T, 3, 1>& r) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T theta2 = r.squaredNorm();
  T w, k;  // q = [k r, w]
  if (theta2 < T(kQuaternionSeriesThreshold2)) {
    w = T(1.0) - theta2 / T(8.0);   // cos(θ/2)
    k = T(0.5) - theta2 / T(48.0);  // sin(θ/2) / θ
  } else {
    const T theta = sqrt(theta2);
    w = cos(T(0.5) * theta);
    k = sin(T(0.5) * theta) / theta;
  }
  return Eigen::Quaternion<T>(w, k * r.x(), k * r.y(), k * r.z());
}

/// Log(q), the rotation vector with angle in [0, pi] (q and -q give the same), exact to rounding
/// and differentiable at the identity. q need not be normalised: the angle is 2 atan2(|v|, w).
template <class T>
Eigen::Matrix<T, 3, 1> quaternionLog(const Eigen::Quaternion<T>& q) {
  using std::atan2;
  using std::sqrt;
  const T sign = q.w() < T(0.0) ? T(-1.0) : T(1.0);
  const T w = sign * q.w();
  const Eigen::Matrix<T, 3, 1> v = sign * q.vec();
  const T n2 = v.squaredNorm();
  T k;  // θ / sin(θ/2) for a unit q
  if (n2 < T(kQuaternionSeriesThreshold2) * w * w) {
    // 2 atan2(n, w) / n = (2 / w) (1 - n²/(3 w²) + n⁴/(5 w⁴) - ...)
    k = T(2.0) / w * (T(1.0) - n2 / (T(3.0) * w * w));
  } else {
    const T n = sqrt(n2);
    k = T(2.0) * atan2(n, w) / n;
  }
  return k * v;
}

/// The upper-triangular U with U^T U = covariance^-1, so that |U r|² is r's squared Mahalanobis
/// norm (a factor whitens its residual with it). The covariance is symmetrised and its
/// eigenvalues are raised to at least 1e-12 times the largest (and to 1e-18), so a covariance
/// that is singular (e.g. after a single IMU interval, where δp = ½ dt δv) or zero gives a
/// finite, very stiff weight in the directions that have no noise instead of failing.
Eigen::MatrixXd upperSqrtInformation(const Eigen::MatrixXd& covariance);

/// The gyro's scale-factor and axis-misalignment errors as a rate noise (density², per axis) at the
/// bias-corrected rate w: M w with M's diagonal of scale_std (relative) and its off-diagonal of
/// misalignment_std (rad) has var((M w)_i) = s² w_i² + m² (|w|² - w_i²); unlike white noise it keeps
/// its sign through a turn, so over the `window_s` between two corrections of the attitude it adds up
/// to M w T, which a white rate noise of density² = var(M w) T matches at T = window_s. livo-lio's
/// propagation and the shared preintegration budget it the same way (0 std: nothing).
inline Vec3 gyroSystematicDensity2(const Vec3& w, double scale_std, double misalignment_std, double window_s) {
  const Vec3 w2 = w.cwiseAbs2();
  const double s2 = scale_std * scale_std, m2 = misalignment_std * misalignment_std;
  return (s2 * w2 + m2 * (Vec3::Constant(w2.sum()) - w2)) * window_s;
}

/// Continuous-time noise of the IMU as the preintegration uses it.
struct ImuPreintegrationNoise {
  double gyro_noise_density = 1.7e-4;   // rad/s/sqrt(Hz)
  double accel_noise_density = 2.0e-3;  // m/s^2/sqrt(Hz)
  double gyro_random_walk = 1.9e-5;     // rad/s^2/sqrt(Hz)
  double accel_random_walk = 3.0e-3;    // m/s^3/sqrt(Hz)
  // The gyro's scale and misalignment (rig.imu.gyro_scale_std, gyro_misalignment_std) in the noise
  // budget (gyroSystematicDensity2): a turn's increments are trusted less than a straight drive's,
  // by the turn. systematic_error_window_s is the spacing of the states the factors join (the
  // LiDAR sweep period for livo-lio-graph, the keyframe spacing for livo-vio-feature). The
  // accelerometer's scale and misalignment are not budgeted: against gravity they act as a bias
  // (estimated), and the motion's own specific force is small beside it on a ground vehicle.
  double gyro_scale_std = 0.0;             // relative
  double gyro_misalignment_std = 0.0;      // rad
  double systematic_error_window_s = 0.1;  // s

  /// The rig's densities and gyro errors; systematic_error_window_s is left to the caller.
  static ImuPreintegrationNoise fromRig(const ImuRig& rig);
};

class ImuPreintegration {
 public:
  /// Preintegration linearised at the biases (gyro_bias, accel_bias).
  ImuPreintegration(const Vec3& gyro_bias, const Vec3& accel_bias, const ImuPreintegrationNoise& noise);

  /// Adds one interval of dt seconds over which the body rate is `gyro` (rad/s) and the specific
  /// force `accel` (m/s²), as measured (biases included). Its discrete noise has the covariance
  /// density² / dt per axis, the gyro's density² raised by gyroSystematicDensity2 at the rate.
  /// dt == 0 adds nothing; a negative or non-finite dt throws std::invalid_argument.
  void integrate(const Vec3& gyro, const Vec3& accel, double dt);

  /// Starts over (no interval) linearised at new biases.
  void reset(const Vec3& gyro_bias, const Vec3& accel_bias);

  double duration() const { return duration_; }
  const Mat3& deltaR() const { return delta_R_; }
  const Vec3& deltaV() const { return delta_v_; }
  const Vec3& deltaP() const { return delta_p_; }
  /// Cov([δφ, δv, δp]) of the measurement noise (biases held at their linearisation point).
  const Mat9& covariance() const { return covariance_; }
  /// Covariance of the bias change over duration() from the random walks, [gyro, accel]: the
  /// weight of a between-bias factor for the same interval.
  Mat6 biasRandomWalkCovariance() const;

  const Mat3& dR_dbg() const { return dR_dbg_; }
  const Mat3& dV_dbg() const { return dV_dbg_; }
  const Mat3& dV_dba() const { return dV_dba_; }
  const Mat3& dP_dbg() const { return dP_dbg_; }
  const Mat3& dP_dba() const { return dP_dba_; }
  const Vec3& gyroBias() const { return bg_; }
  const Vec3& accelBias() const { return ba_; }

  /// The increments for biases (bg, ba), corrected to first order (Forster eq. 44).
  Mat3 correctedDeltaR(const Vec3& bg) const;
  Vec3 correctedDeltaV(const Vec3& bg, const Vec3& ba) const;
  Vec3 correctedDeltaP(const Vec3& bg, const Vec3& ba) const;

  /// The state at j from the state at i (world frame, gravity_W e.g. (0, 0, -9.81)) with the
  /// increments corrected to the biases (bg, ba).
  void predict(const Mat3& R_i, const Vec3& p_i, const Vec3& v_i, const Vec3& bg, const Vec3& ba, const Vec3& gravity_W,
               Mat3* R_j, Vec3* p_j, Vec3* v_j) const;

  /// [r_R, r_v, r_p] of Forster eq. 45 with the corrected increments:
  ///   r_R = Log(ΔR̂^T R_i^T R_j),
  ///   r_v = R_i^T (v_j - v_i - g Δt) - Δv̂,
  ///   r_p = R_i^T (p_j - p_i - v_i Δt - ½ g Δt²) - Δp̂.
  /// Its covariance is covariance() (r_R = -δφ to first order).
  Vec9 residual(const Mat3& R_i, const Vec3& p_i, const Vec3& v_i, const Mat3& R_j, const Vec3& p_j, const Vec3& v_j,
                const Vec3& bg, const Vec3& ba, const Vec3& gravity_W) const;

  /// The same residual on raw parameter blocks for Ceres AutoDiff: unit quaternions q = W_R_I in
  /// Eigen's order [x, y, z, w], 3-vectors otherwise; r has 9 entries.
  template <class T>
  void residual(const T* q_i, const T* p_i, const T* v_i, const T* bg, const T* ba, const T* q_j, const T* p_j,
                const T* v_j, const Vec3& gravity_W, T* r) const;

  /// upperSqrtInformation(covariance()): whitens residual().
  Mat9 sqrtInformation() const;

 private:
  ImuPreintegrationNoise noise_;
  Vec3 bg_, ba_;
  double duration_ = 0.0;
  Quat delta_q_ = Quat::Identity();  // ΔR kept as a unit quaternion; delta_R_ is its matrix
  Mat3 delta_R_ = Mat3::Identity();
  Vec3 delta_v_ = Vec3::Zero();
  Vec3 delta_p_ = Vec3::Zero();
  Mat9 covariance_ = Mat9::Zero();
  Mat3 dR_dbg_ = Mat3::Zero();
  Mat3 dV_dbg_ = Mat3::Zero();
  Mat3 dV_dba_ = Mat3::Zero();
  Mat3 dP_dbg_ = Mat3::Zero();
  Mat3 dP_dba_ = Mat3::Zero();
};

template <class T>
void ImuPreintegration::residual(const T* q_i, const T* p_i, const T* v_i, const T* bg, const T* ba, const T* q_j,
                                 const T* p_j, const T* v_j, const Vec3& gravity_W, T* r) const {
  using Vec3T = Eigen::Matrix<T, 3, 1>;
  using QuatT = Eigen::Quaternion<T>;
  const Eigen::Map<const QuatT> Q_i(q_i), Q_j(q_j);
  const Eigen::Map<const Vec3T> P_i(p_i), V_i(v_i), Bg(bg), Ba(ba), P_j(p_j), V_j(v_j);
  const Vec3T dbg = Bg - bg_.cast<T>();
  const Vec3T dba = Ba - ba_.cast<T>();
  const QuatT dR = delta_q_.cast<T>() * quaternionExp<T>(dR_dbg_.cast<T>() * dbg);
  const Vec3T dV = delta_v_.cast<T>() + dV_dbg_.cast<T>() * dbg + dV_dba_.cast<T>() * dba;
  const Vec3T dP = delta_p_.cast<T>() + dP_dbg_.cast<T>() * dbg + dP_dba_.cast<T>() * dba;
  const T dt(duration_);
  const Vec3T g = gravity_W.cast<T>();
  const QuatT Q_i_inv = Q_i.conjugate();
  Eigen::Map<Eigen::Matrix<T, 9, 1>> res(r);
  res.template head<3>() = quaternionLog<T>(dR.conjugate() * (Q_i_inv * Q_j));
  res.template segment<3>(3) = Q_i_inv * Vec3T(V_j - V_i - g * dt) - dV;
  res.template tail<3>() = Q_i_inv * Vec3T(P_j - P_i - V_i * dt - T(0.5) * g * dt * dt) - dP;
}

}  // namespace livo
