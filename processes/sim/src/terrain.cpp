#include "livo/sim/terrain.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace livo::sim {

namespace {

Vec2 unitDirection(double deg) {
  const double a = deg * M_PI / 180.0;
  return Vec2(std::cos(a), std::sin(a));
}

}  // namespace

Terrain::Terrain(const TerrainOptions& options) : options_(options) {
  if (!std::isfinite(options.base)) throw std::invalid_argument("terrain: base must be finite");
  for (size_t k = 0; k < options.profiles.size(); ++k) {
    const GradeProfile& g = options.profiles[k];
    const std::string name = "terrain profile " + std::to_string(k) + ": ";
    const size_t n = g.stations.size();
    if (n < 2) throw std::invalid_argument(name + "needs at least 2 stations");
    if (g.heights.size() != n) throw std::invalid_argument(name + "needs one height per station");
    if (!(g.curve_length > 0.0)) throw std::invalid_argument(name + "curve_length must be > 0");
    if (!g.origin.allFinite() || !std::isfinite(g.direction_deg))
      throw std::invalid_argument(name + "origin and direction_deg must be finite");
    for (size_t i = 0; i < n; ++i)
      if (!std::isfinite(g.stations[i]) || !std::isfinite(g.heights[i]))
        throw std::invalid_argument(name + "station " + std::to_string(i) + " has a non-finite position or height");
    for (size_t i = 1; i < n; ++i)
      if (!(g.stations[i] > g.stations[i - 1]))
        throw std::invalid_argument(name + "stations must increase (station " + std::to_string(i) + " at " +
                                    std::to_string(g.stations[i]) + " m follows " + std::to_string(g.stations[i - 1]) +
                                    " m)");
    Profile p;
    p.direction = unitDirection(g.direction_deg);
    p.origin = g.origin;
    p.stations = g.stations;
    p.heights = g.heights;
    p.curve_length = g.curve_length;
    p.grades.assign(n + 1, 0.0);
    double steepest = 0.0, sharpest = 0.0;
    for (size_t i = 1; i < n; ++i) {
      const double run = g.stations[i] - g.stations[i - 1];
      if (!(run >= g.curve_length))
        throw std::invalid_argument(name + "stations " + std::to_string(i - 1) + " and " + std::to_string(i) +
                                    " are closer than curve_length: their vertical curves would overlap");
      p.grades[i] = (g.heights[i] - g.heights[i - 1]) / run;
      steepest = std::max(steepest, std::abs(p.grades[i]));
    }
    for (size_t i = 0; i < n; ++i)
      sharpest = std::max(sharpest, std::abs(p.grades[i + 1] - p.grades[i]) / g.curve_length);
    max_grade_ += steepest;
    max_curvature_ += sharpest;
    profiles_.push_back(std::move(p));
  }
  for (size_t k = 0; k < options.relief.size(); ++k) {
    const ReliefWave& w = options.relief[k];
    const std::string name = "terrain relief wave " + std::to_string(k) + ": ";
    if (!(w.wavelength > 0.0) || !std::isfinite(w.wavelength))
      throw std::invalid_argument(name + "wavelength must be finite and > 0");
    if (!std::isfinite(w.amplitude) || !std::isfinite(w.direction_deg) || !std::isfinite(w.phase_deg))
      throw std::invalid_argument(name + "amplitude, direction_deg and phase_deg must be finite");
    Wave v;
    v.direction = unitDirection(w.direction_deg);
    v.wavenumber = 2.0 * M_PI / w.wavelength;
    v.phase = w.phase_deg * M_PI / 180.0;
    v.amplitude = w.amplitude;
    max_grade_ += std::abs(w.amplitude) * v.wavenumber;
    max_curvature_ += std::abs(w.amplitude) * v.wavenumber * v.wavenumber;
    waves_.push_back(v);
  }
}

void Terrain::profileAt(const Profile& p, double s, double out[3]) {
  const std::vector<double>& st = p.stations;
  const double half = 0.5 * p.curve_length;
  const size_t k = static_cast<size_t>(std::upper_bound(st.begin(), st.end(), s) - st.begin());  // stations <= s
  for (size_t j : {k - 1, k}) {
    if (j >= st.size() || std::abs(s - st[j]) > half) continue;
    // the vertical curve at station j: from grade grades[j] to grades[j + 1], centred on the station
    const double x = s - st[j] + half, change = p.grades[j + 1] - p.grades[j];
    out[0] = p.heights[j] + p.grades[j] * (s - st[j]) + change * x * x / (2.0 * p.curve_length);
    out[1] = p.grades[j] + change * x / p.curve_length;
    out[2] = change / p.curve_length;
    return;
  }
  if (k == 0) {
    out[0] = p.heights[0], out[1] = out[2] = 0.0;
    return;
  }
  out[0] = p.heights[k - 1] + p.grades[k] * (s - st[k - 1]);
  out[1] = p.grades[k];
  out[2] = 0.0;
}

GroundJet Terrain::at(double x, double y) const {
  GroundJet g;
  g.height = options_.base;
  const Vec2 q(x, y);
  for (const Profile& p : profiles_) {
    double f[3];
    profileAt(p, p.direction.dot(q - p.origin), f);
    g.height += f[0];
    g.gradient += f[1] * p.direction;
    g.hessian += f[2] * p.direction * p.direction.transpose();
  }
  for (const Wave& w : waves_) {
    const Vec2& d = w.direction;
    const double kw = w.wavenumber;
    const double arg = kw * d.dot(q) + w.phase;
    const double sn = std::sin(arg), cs = std::cos(arg);
    g.height += w.amplitude * sn;
    g.gradient += w.amplitude * kw * cs * d;
    g.hessian -= w.amplitude * kw * kw * sn * d * d.transpose();
  }
  return g;
}

}  // namespace livo::sim
