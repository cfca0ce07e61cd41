#include "livo/sim/lidar_scanner.hpp"

#include <algorithm>
#include <cmath>

namespace livo::sim {

LidarScanner::LidarScanner(const LidarRig& rig, const LidarPatternOptions& pattern_options, const LidarEffects& effects)
    : rig_(rig), pattern_(rig.model, rig.rate_hz, pattern_options), effects_(effects) {
  if (effects_.footprint()) sub_rays_ = footprintSubRays(effects_);
}

Echo LidarScanner::axisEcho(const Scene& scene, const Ray& ray, const CastContext& context) const {
  const RayHit hit = scene.cast(ray, context, 1e-6, rig_.max_range);
  Echo echo;
  if (!hit.valid()) return echo;
  echo.range = hit.t;
  echo.reflectivity = scene.material(hit.object).reflectivity;
  echo.cos_incidence = std::abs(scene.surface(ray, hit).normal.dot(ray.direction));
  return echo;
}

Echo LidarScanner::footprintEcho(const Scene& scene, const Ray& ray, const Vec3& up, const CastContext& context,
                                 std::vector<SubRayHit>* hits) const {
  Vec3 horizontal = up.cross(ray.direction);
  if (horizontal.norm() < 1e-9) horizontal = ray.direction.unitOrthogonal();
  horizontal.normalize();
  const Vec3 vertical = ray.direction.cross(horizontal);
  hits->clear();
  for (size_t i = 0; i < sub_rays_.size(); ++i) {
    const SubRay& s = sub_rays_[i];
    // each part of the beam draws its own glass and vegetation depths (its own key)
    CastContext sub_context = context;
    sub_context.key = context.key ^ (0x9E3779B97F4A7C15ull * (i + 1));
    Ray sub = ray;
    sub.direction =
        (ray.direction + std::tan(s.horizontal) * horizontal + std::tan(s.vertical) * vertical).normalized();
    const RayHit hit = scene.cast(sub, sub_context, 1e-6, rig_.max_range);
    if (!hit.valid()) continue;  // this part of the beam goes to the sky: the return weakens
    const double cos_incidence = std::abs(scene.surface(sub, hit).normal.dot(sub.direction));
    hits->push_back({hit.t, s.weight, scene.material(hit.object).reflectivity, cos_incidence});
  }
  return strongestEcho(hits, effects_.echo_separation_m);
}

LidarSweep LidarScanner::scan(const Scene& scene, const BodyTrajectory& trajectory, double t0, int64_t utime,
                              double sensor_time0, Random rng) const {
  LidarSweep sweep;
  sweep.utime = utime;
  sweep.duration = pattern_.sweepDuration();
  sweep.solid_state = pattern_.solidState();
  sweep.num_rings = pattern_.beams();
  const size_t expected = static_cast<size_t>(pattern_.columns()) * pattern_.beams();
  for (auto* v : {&sweep.x, &sweep.y, &sweep.z, &sweep.intensity, &sweep.time_offset}) v->reserve(expected);
  sweep.ring.reserve(expected);

  std::vector<SubRayHit> hits;
  hits.reserve(sub_rays_.size());
  const Mat3 R_IL = rig_.T_I_L.linear();
  const Vec3 t_IL = rig_.T_I_L.translation();
  for (int c = 0; c < pattern_.columns(); ++c) {
    const double column_time = c * pattern_.columnPeriod();
    const BodyState s = trajectory.at(t0 + column_time);
    const Mat3 R_WI = s.T_W_I.linear();
    const Vec3 p_WI = s.T_W_I.translation();
    for (int b = 0; b < pattern_.beams(); ++b) {
      const double dt = pattern_.firingTime(c, b) - column_time;  // microseconds at most
      // sensor pose at the beam's firing time (constant-rate step over dt, exact for dt = 0)
      const Mat3 R = dt == 0.0 ? R_WI : Mat3(R_WI * so3::Exp(s.angular_velocity * dt));
      const Vec3 p = p_WI + s.velocity * dt + 0.5 * s.acceleration * dt * dt;
      const Mat3 R_WL = R * R_IL;
      const double time_offset = column_time + dt;
      const Vec3 d_L = pattern_.direction(b, time_offset, sensor_time0 + time_offset);
      Ray ray;
      ray.origin = p + R * t_IL;
      ray.direction = R_WL * d_L;
      // draw the noise for every beam so each beam's noise does not depend on other beams' hits
      const double noise = rng.normal();
      const double drop = rng.uniform();
      const double detect = effects_.detection() ? rng.uniform() : 0.0;
      const CastContext context = CastContext::lidar(t0 + time_offset, rng.key());
      const Echo echo =
          sub_rays_.empty() ? axisEcho(scene, ray, context) : footprintEcho(scene, ray, R_WL.col(2), context, &hits);
      if (!echo.valid() || echo.range < rig_.min_range) continue;
      if (drop < rig_.dropout_probability) continue;
      const double apparent = echo.apparentReflectivity();
      if (detect >= detectionProbability(effects_, echo.range, apparent)) continue;
      const double range = echo.range + rangeNoiseStd(effects_, rig_.range_noise_std, echo.range, apparent) * noise;
      if (range < rig_.min_range || range > rig_.max_range) continue;
      const double intensity = 255.0 * echo.reflectivity * echo.cos_incidence * echo.share;
      const Vec3 q = d_L * range;
      sweep.x.push_back(static_cast<float>(q.x()));
      sweep.y.push_back(static_cast<float>(q.y()));
      sweep.z.push_back(static_cast<float>(q.z()));
      sweep.intensity.push_back(static_cast<float>(std::min(255.0, intensity)));
      sweep.time_offset.push_back(static_cast<float>(time_offset));
      sweep.ring.push_back(static_cast<int16_t>(pattern_.ring(b)));
    }
  }
  return sweep;
}

}  // namespace livo::sim
