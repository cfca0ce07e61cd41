#include "livo/sim/wheel_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace livo::sim {

WheelReading idealWheelReading(const BodyState& s, const WheelRig& rig, int64_t utime) {
  const Mat3 R_WI = s.T_W_I.linear();
  const Mat3 R_IB = rig.T_I_B.linear();
  const Vec3 r_IB = rig.T_I_B.translation();
  // velocity of the base origin in the world, then in B; body rate in B
  const Vec3 v_W = s.velocity + R_WI * s.angular_velocity.cross(r_IB);
  const Vec3 v_B = R_IB.transpose() * (R_WI.transpose() * v_W);
  const Vec3 w_B = R_IB.transpose() * s.angular_velocity;
  WheelReading r;
  r.utime = utime;
  r.left_speed = v_B.x() - 0.5 * rig.track_width * w_B.z();
  r.right_speed = v_B.x() + 0.5 * rig.track_width * w_B.z();
  return r;
}

WheelSlip::WheelSlip(const WheelSlipOptions& options, Random rng) : options_(options), rng_(rng) {
  if (!options_.enabled()) throw std::invalid_argument("WheelSlip: rate_per_min must be > 0");
}

void WheelSlip::drawNext() {
  // always the same seven draws per episode
  const double u_gap = rng_.uniform();
  const double u_duration = rng_.uniform();
  const double u_wheels = rng_.uniform();
  const double u_lock = rng_.uniform();
  const double u_left = rng_.uniform();
  const double u_right = rng_.uniform();
  const double u_side = rng_.uniform();
  WheelSlipEpisode e;
  const double after = episodes_.empty() ? 0.0 : episodes_.back().end_s;
  e.start_s = after - std::log1p(-u_gap) * 60.0 / options_.rate_per_min;
  e.end_s = e.start_s + options_.min_duration_s + (options_.max_duration_s - options_.min_duration_s) * u_duration;
  if (u_wheels < options_.both_probability)
    e.left = e.right = true;
  else
    (u_side < 0.5 ? e.left : e.right) = true;
  e.lock = u_lock < options_.lock_probability;
  const double spin_l = options_.min_spin + (options_.max_spin - options_.min_spin) * u_left;
  const double spin_r = options_.min_spin + (options_.max_spin - options_.min_spin) * u_right;
  if (e.left) e.left_factor = e.lock ? 0.0 : 1.0 + spin_l;
  if (e.right) e.right_factor = e.lock ? 0.0 : 1.0 + spin_r;
  episodes_.push_back(e);
}

std::optional<WheelSlipEpisode> WheelSlip::episodeAt(double t) {
  while (episodes_.empty() || episodes_.back().start_s <= t) drawNext();
  // the last episode starting at or before t
  const auto it = std::upper_bound(episodes_.begin(), episodes_.end(), t,
                                   [](double x, const WheelSlipEpisode& e) { return x < e.start_s; });
  if (it == episodes_.begin() || !(t < (it - 1)->end_s)) return std::nullopt;
  return *(it - 1);
}

bool WheelSlip::apply(double t, WheelReading* r) {
  const std::optional<WheelSlipEpisode> e = episodeAt(t);
  if (!e) return false;
  r->left_speed *= e->left_factor;
  r->right_speed *= e->right_factor;
  return true;
}

}  // namespace livo::sim
