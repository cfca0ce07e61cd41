// Online wheel scale calibration on synthetic data from a known motion: the wheel base B drives a
// curvy path at a varying speed; the encoders read scale * the true contact-point speeds plus
// white noise at 50 Hz; the "LiDAR" poses at 10 Hz carry position and yaw noise. Checks the
// travel geometry against the exact arc, convergence to the true scales within the estimator's
// own 3 sigma, no learning while standing still or turning on the spot, the slip gate, and the
// wheel update's chi-square with the learned scales against its 3 degrees of freedom.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "livo/lio/wheel_scale.hpp"

using namespace livo;
using namespace livo::lio;

namespace {
const Pose3 kTIB = se3::fromRotationTranslation(so3::Exp(Vec3(0.0, 0.0, 0.05)), Vec3(-1.2, 0.1, -1.5));
constexpr double kTrack = 1.6;
constexpr double kSpeedNoise = 0.02;      // m/s per reading
constexpr double kPositionNoise = 0.003;  // m per axis, per pose
constexpr double kYawNoise = 1e-4;        // rad per pose

// Planar motion of B: forward speed v(t), yaw rate w(t); the exact state by fine integration.
struct Motion {
  double (*speed)(double);
  double (*yaw_rate)(double);
};
double curvySpeed(double t) { return 5.0 + 1.5 * std::sin(0.3 * t); }
double curvyYawRate(double t) { return 0.3 * std::sin(0.5 * t); }
double zero(double) { return 0.0; }
double spinRate(double) { return 0.5; }

struct SyntheticRun {
  std::vector<int64_t> sweep_utime;
  std::vector<Pose3> poses;        // noisy W_T_I at each sweep end
  std::deque<WheelSample> wheels;  // 50 Hz readings with scale and noise
};

SyntheticRun simulate(const Motion& m, double duration_s, Vec2 scale, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  SyntheticRun run;
  const int64_t dt_us = 500;  // integration step
  double x = 0.0, y = 0.0, yaw = 0.0;
  const Pose3 T_B_I = kTIB.inverse();
  for (int64_t u = 0; u <= static_cast<int64_t>(duration_s * 1e6); u += dt_us) {
    const double t = static_cast<double>(u) * 1e-6;
    if (u % 20'000 == 0) {  // encoder reading
      const double v = m.speed(t), w = m.yaw_rate(t);
      run.wheels.push_back({u, scale.x() * (v - 0.5 * kTrack * w) + kSpeedNoise * n01(rng),
                            scale.y() * (v + 0.5 * kTrack * w) + kSpeedNoise * n01(rng)});
    }
    if (u % 100'000 == 0) {  // registered sweep
      const Pose3 T_W_B =
          se3::fromRotationTranslation(so3::Exp(Vec3(0, 0, yaw + kYawNoise * n01(rng))),
                                       Vec3(x, y, 0.0) + kPositionNoise * Vec3(n01(rng), n01(rng), n01(rng)));
      run.sweep_utime.push_back(u);
      run.poses.push_back(T_W_B * T_B_I);
    }
    const double h = static_cast<double>(dt_us) * 1e-6;
    const double mid_yaw = yaw + 0.5 * h * m.yaw_rate(t + 0.5 * h);
    x += h * m.speed(t + 0.5 * h) * std::cos(mid_yaw);
    y += h * m.speed(t + 0.5 * h) * std::sin(mid_yaw);
    yaw += h * m.yaw_rate(t + 0.5 * h);
  }
  return run;
}

WheelScaleOptions testOptions() {
  WheelScaleOptions o;
  o.displacement_noise_std = std::sqrt(2.0) * kPositionNoise;  // the difference of two noisy poses
  return o;
}

WheelTravel travelOf(const SyntheticRun& run, size_t k) {
  WheelTravel t;
  t.duration_s = static_cast<double>(run.sweep_utime[k] - run.sweep_utime[k - 1]) * 1e-6;
  t.predicted = predictedWheelTravel(run.poses[k - 1], run.poses[k], kTIB, kTrack, &t.forward_distance);
  EXPECT_TRUE(integrateWheelSpeeds(run.wheels, run.sweep_utime[k - 1], run.sweep_utime[k], 0.1, &t.measured,
                                   &t.measured_noise_gain));
  return t;
}

void learnAll(const SyntheticRun& run, WheelScaleEstimator* est) {
  for (size_t k = 1; k < run.poses.size(); ++k) est->update(travelOf(run, k), run.sweep_utime[k]);
}
}  // namespace

TEST(WheelScale, TravelFollowsTheArc) {
  // B on a circle of radius 10 m, turning 0.2 rad between the poses: each contact point travels
  // its own radius times the angle
  const double r = 10.0, angle = 0.2;
  const Pose3 T_W_Ba = Pose3::Identity();
  const Pose3 T_W_Bb = se3::fromRotationTranslation(so3::Exp(Vec3(0, 0, angle)),
                                                    Vec3(r * std::sin(angle), r * (1 - std::cos(angle)), 0));
  const Pose3 T_B_I = kTIB.inverse();
  double forward = 0.0;
  const Vec2 d = predictedWheelTravel(T_W_Ba * T_B_I, T_W_Bb * T_B_I, kTIB, kTrack, &forward);
  EXPECT_NEAR(forward, r * angle, 1e-9);
  EXPECT_NEAR(d.x(), (r - 0.5 * kTrack) * angle, 1e-9);
  EXPECT_NEAR(d.y(), (r + 0.5 * kTrack) * angle, 1e-9);
}

TEST(WheelScale, IntegralOfLinearSpeedsIsExactAndItsNoiseGainMatchesTheWeights) {
  std::deque<WheelSample> w;
  for (int i = 0; i <= 10; ++i) w.push_back({i * 20'000, 1.0 + 0.1 * i, -2.0});  // 1 + 5 t m/s
  Vec2 d;
  double gain = 0.0;
  ASSERT_TRUE(integrateWheelSpeeds(w, 10'000, 110'000, 0.05, &d, &gain));
  // integral of 1 + 5 t over [0.01, 0.11]
  EXPECT_NEAR(d.x(), 0.1 + 2.5 * (0.11 * 0.11 - 0.01 * 0.01), 1e-12);
  EXPECT_NEAR(d.y(), -0.2, 1e-12);
  // weights of the readings at 0, 20, ..., 120 ms: the half segments at the ends give 3/4 and 1/4
  // of their 10 ms to their nearer and farther reading, full segments 10 ms to each end:
  // 2.5, 7.5 + 10, 20, 20, 20, 10 + 7.5, 2.5 ms (summing to the 100 ms)
  EXPECT_NEAR(gain, 2 * 0.0025 * 0.0025 + 2 * 0.0175 * 0.0175 + 3 * 0.02 * 0.02, 1e-12);
  EXPECT_FALSE(integrateWheelSpeeds(w, 10'000, 250'000, 0.05, &d, &gain));  // not covered
  w.erase(w.begin() + 3);
  EXPECT_FALSE(integrateWheelSpeeds(w, 10'000, 110'000, 0.03, &d, &gain));  // a 40 ms gap
}

TEST(WheelScale, ConvergesToTheTrueScalesWithinItsThreeSigma) {
  const Vec2 truth(0.97, 1.02);
  for (uint32_t seed = 1; seed <= 10; ++seed) {
    const SyntheticRun run = simulate({curvySpeed, curvyYawRate}, 60.0, truth, seed);
    WheelScaleEstimator est(testOptions(), kSpeedNoise);
    learnAll(run, &est);
    EXPECT_GE(est.counts().learned, 590) << "seed " << seed;
    EXPECT_LE(est.counts().outliers, 2) << "seed " << seed;
    for (int side = 0; side < 2; ++side) {
      EXPECT_LT(est.stds()[side], 0.001) << "seed " << seed;  // learned, not just the prior
      EXPECT_LT(std::abs(est.scales()[side] - truth[side]), 3.0 * est.stds()[side])
          << "seed " << seed << " side " << side;
    }
  }
}

TEST(WheelScale, StandingStillOrTurningOnTheSpotTeachesNothing) {
  for (const Motion m : {Motion{zero, zero}, Motion{zero, spinRate}}) {
    const SyntheticRun run = simulate(m, 30.0, Vec2(0.97, 1.02), 3);
    const WheelScaleOptions o = testOptions();
    WheelScaleEstimator est(o, kSpeedNoise);
    learnAll(run, &est);
    EXPECT_EQ(est.counts().learned, 0);
    EXPECT_EQ(est.counts().unobservable, static_cast<int64_t>(run.poses.size()) - 1);
    EXPECT_EQ(est.scales(), Vec2::Ones());
    // the std grew only by the random walk
    const double expected = std::sqrt(o.prior_std * o.prior_std + o.random_walk * o.random_walk * 29.9);
    EXPECT_NEAR(est.stds().x(), expected, 1e-12);
    EXPECT_NEAR(est.stds().y(), expected, 1e-12);
  }
}

TEST(WheelScale, SlipIsNotLearned) {
  const SyntheticRun run = simulate({curvySpeed, curvyYawRate}, 20.0, Vec2(0.97, 1.02), 4);
  WheelScaleEstimator est(testOptions(), kSpeedNoise);
  learnAll(run, &est);
  const Vec2 before = est.scales();
  WheelTravel slip = travelOf(run, run.poses.size() - 1);
  slip.measured.x() *= 1.3;  // the left wheel spins 30 % faster than the ground goes by
  EXPECT_EQ(est.update(slip, run.sweep_utime.back() + 100'000), WheelScaleEstimator::Outcome::kOutlier);
  EXPECT_GT(est.lastChi2(), testOptions().gate_chi2);
  EXPECT_EQ(est.scales(), before);
}

TEST(WheelScale, CorrectedWheelUpdateIsChiSquareConsistent) {
  const Vec2 truth(0.97, 1.02);
  WheelScaleEstimator learned(testOptions(), kSpeedNoise);
  learnAll(simulate({curvySpeed, curvyYawRate}, 60.0, truth, 5), &learned);
  WheelScaleOptions fixed = testOptions();
  fixed.prior_std = 0.0;  // main's behaviour before the calibration: the speeds taken as they are
  const WheelScaleEstimator unlearned(fixed, kSpeedNoise);

  WheelOptions o;
  o.enabled = true;
  o.T_I_B = kTIB;
  o.track_width = kTrack;
  o.speed_noise_std = kSpeedNoise;
  StateCovariance P = StateCovariance::Zero();  // the calibration held fixed
  P.diagonal().segment<3>(FilterState::kRot).setConstant(1e-6);
  P.diagonal().segment<3>(FilterState::kPos).setConstant(1e-4);
  P.diagonal().segment<3>(FilterState::kVel).setConstant(1e-4);  // 1 cm/s: a LiDAR-tracked filter
  P.diagonal().segment<3>(FilterState::kGyroBias).setConstant(1e-8);
  P.diagonal().segment<3>(FilterState::kAccelBias).setConstant(1e-4);
  P.diagonal().segment<3>(FilterState::kGravity).setConstant(1e-6);
  const Mat18 L = P.topLeftCorner<FilterState::kNavDim, FilterState::kNavDim>().llt().matrixL();

  std::mt19937 rng(7);
  std::normal_distribution<double> n01(0.0, 1.0);
  const int trials = 2000;
  double sum_learned = 0.0, sum_unlearned = 0.0;
  for (int i = 0; i < trials; ++i) {
    // a state that moves as the constraints allow (lateral and vertical velocity of B at their
    // configured noise), turning; the encoders read the true contact-point speeds scaled
    const double v = 4.0 + 2.0 * (i % 5) / 4.0, w = 0.3 * std::sin(0.1 * i);
    const Vec3 v_B(v, o.lateral_noise_std * n01(rng), o.vertical_noise_std * n01(rng));
    FilterState truth_state;
    truth_state.rot = so3::Exp(Vec3(0.01, -0.02, 0.1 * i));
    const Vec3 omega = kTIB.linear() * Vec3(0, 0, w);
    truth_state.gyro_bias = Vec3(0.001, -0.002, 0.003);
    truth_state.vel = truth_state.rot * (kTIB.linear() * v_B - omega.cross(kTIB.translation()));
    const Vec3 gyro = omega + truth_state.gyro_bias;
    const WheelSample raw{0, truth.x() * (v - 0.5 * kTrack * w) + kSpeedNoise * n01(rng),
                          truth.y() * (v + 0.5 * kTrack * w) + kSpeedNoise * n01(rng)};
    Vec18 e;
    for (int k = 0; k < 18; ++k) e[k] = n01(rng);
    StateVector d = StateVector::Zero();
    d.head<FilterState::kNavDim>() = L * e;
    const FilterState estimate = truth_state.boxplus(d);
    for (const WheelScaleEstimator* est : std::array<const WheelScaleEstimator*, 2>{&learned, &unlearned}) {
      FilterState x = estimate;
      StateCovariance Pi = P;
      const WheelSample c = est->correct(raw);
      const WheelUpdateResult r =
          wheelVelocityUpdate(&x, &Pi, gyro, 0.5 * (c.left_speed + c.right_speed), o, est->meanSpeedVariance(raw));
      (est == &learned ? sum_learned : sum_unlearned) += r.chi2;
    }
  }
  // chi-square with 3 dof: mean 3, std of the mean sqrt(6 / 2000) = 0.055
  EXPECT_NEAR(sum_learned / trials, 3.0, 0.25);
  // the same data taken as it is: the mean speed reads 0.5 % slow (-3 % and +2 %), 2 to 3 cm/s,
  // as large as the innovation's forward std (1.7 cm/s): the mean chi-square grows by ~2
  EXPECT_GT(sum_unlearned / trials, 4.5);
}
