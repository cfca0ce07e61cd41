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
  for (size_t k = 0; k < options.profiles.size(); ++k) {
    const GradeProfile& g = options.profiles[k];
    const std::string name = "terrain profile " + std::to_string(k) + ": ";
    const size_t n = g.stations.size();
    if (n < 2) throw std::invalid_argument(name + "needs at least 2 stations");
    if (g.heights.size() != n) throw std::invalid_argument(name + "needs one height per station");
    if (!(g.curve_length > 0.0)) throw std::invalid_argument(name + "curve_length must be > 0");
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
    if (!(w.wavelength > 0.0))
      throw std::invalid_argument("terrain relief wave " + std::to_string(k) + ": wavelength must be > 0");
    const double kw = 2.0 * M_PI / w.wavelength;
    max_grade_ += std::abs(w.amplitude) * kw;
    max_curvature_ += std::abs(w.amplitude) * kw * kw;
  }
}

void Terrain::profileAt(const Profile& p, double s, double out[3]) {
  const std::vector<double>& st = p.stations;
  const double half = 0.5 * p.curve_length;
  const size_t k =
      static_cast<size_t>(std::upper_bound(st.begin(), st.end(), s) - st.begin());  // stations <= s
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
  for (const ReliefWave& w : options_.relief) {
    const Vec2 d = unitDirection(w.direction_deg);
    const double kw = 2.0 * M_PI / w.wavelength;
    const double arg = kw * d.dot(q) + w.phase_deg * M_PI / 180.0;
    const double sn = std::sin(arg), cs = std::cos(arg);
    g.height += w.amplitude * sn;
    g.gradient += w.amplitude * kw * cs * d;
    g.hessian -= w.amplitude * kw * kw * sn * d * d.transpose();
  }
  return g;
}

}  // namespace livo::sim
