// Differential-drive wheel encoder: left/right contact-point speeds of the wheel base frame B
// from the body motion, with per-wheel scale error and white noise, and optional episodes of
// wheel slip (a wheel spinning faster than the ground passes under it, or locked and skidding).
#pragma once

#include <optional>
#include <vector>

#include "livo/sensor_rig.hpp"
#include "livo/sim/random.hpp"
#include "livo/sim/sensor_data.hpp"
#include "livo/sim/trajectory.hpp"

namespace livo::sim {

/// Exact wheel speeds: v_B (forward, in B) -/+ yaw rate of B * track / 2.
WheelReading idealWheelReading(const BodyState& state, const WheelRig& rig, int64_t utime);

class WheelNoise {
 public:
  WheelNoise(const WheelRig& rig, double left_scale, double right_scale, Random rng)
      : rig_(rig), left_scale_(left_scale), right_scale_(right_scale), rng_(rng) {}
  void apply(WheelReading* r) {
    r->left_speed = r->left_speed * left_scale_ + rig_.speed_noise_std * rng_.normal();
    r->right_speed = r->right_speed * right_scale_ + rig_.speed_noise_std * rng_.normal();
  }

 private:
  WheelRig rig_;
  double left_scale_, right_scale_;
  Random rng_;
};

/// sim.wheel.slip: occasional slip episodes. Off (rate 0) by default.
struct WheelSlipOptions {
  double rate_per_min = 0.0;    // episodes per minute of time without slip; 0 = off
  double min_duration_s = 0.2;  // each episode lasts uniform [min, max] seconds
  double max_duration_s = 1.5;
  double min_spin = 0.10;  // a spinning wheel reads (1 + uniform [min, max]) x its true speed
  double max_spin = 0.40;
  double lock_probability = 0.25;  // share of episodes whose wheel(s) lock instead: they read 0
  double both_probability = 0.3;   // share of episodes on both wheels (else the left or the right alike)
  bool enabled() const { return rate_per_min > 0.0; }
};

/// One slip episode, in seconds of sensor time since the run's start.
struct WheelSlipEpisode {
  double start_s = 0.0, end_s = 0.0;             // [start, end)
  bool left = false, right = false;              // the wheels it affects
  bool lock = false;                             // locked (factor 0) rather than spinning
  double left_factor = 1.0, right_factor = 1.0;  // measured / true speed while it lasts (1: unaffected)
};

/// The slip episodes of a run, drawn lazily from one random stream in time order: the gap from one
/// episode's end to the next one's start is exponential with mean 60 / rate_per_min s (a Poisson
/// process in the time the wheels grip), so the episodes never overlap. Every episode makes the
/// same draws, so the schedule depends only on the options and the stream, not on the queries.
class WheelSlip {
 public:
  WheelSlip(const WheelSlipOptions& options, Random rng);
  /// The episode covering t (s since the start), if any. Queries may come in any order.
  std::optional<WheelSlipEpisode> episodeAt(double t);
  /// Multiplies the true speeds of the affected wheels by their factors if an episode covers t
  /// (before the scale errors and the noise); returns whether one does.
  bool apply(double t, WheelReading* r);
  /// The episodes drawn so far: every one starting up to the latest time asked for, and the next.
  const std::vector<WheelSlipEpisode>& episodes() const { return episodes_; }
  const WheelSlipOptions& options() const { return options_; }

 private:
  void drawNext();

  WheelSlipOptions options_;
  Random rng_;
  std::vector<WheelSlipEpisode> episodes_;
};

}  // namespace livo::sim
