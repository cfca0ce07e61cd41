#include "livo/sim/moving_object.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace livo::sim {

MovingObject::MovingObject(const Shape& shape, const MoverPath& path) : shape_(shape), path_(path) {
  const auto& w = path_.waypoints;
  if (w.size() < 2) throw std::invalid_argument("a mover's path needs at least 2 waypoints");
  if (!(path_.speed >= 0.0)) throw std::invalid_argument("a mover's speed must be >= 0");
  cumulative_.push_back(0.0);
  for (size_t i = 0; i < w.size(); ++i) {
    const double step = (w[(i + 1) % w.size()] - w[i]).head<2>().norm();
    if (!(step > 1e-6)) throw std::invalid_argument("a mover's path has two consecutive waypoints at the same place");
    cumulative_.push_back(cumulative_.back() + step);
  }
}

Vec3 MovingObject::groundPointAt(double t, double* heading) const {
  const double length = loopLength();
  double s = std::fmod(path_.phase * length + path_.speed * t, length);
  if (s < 0.0) s += length;
  // segment i runs from cumulative_[i] to cumulative_[i + 1]
  const size_t i =
      std::min<size_t>(std::upper_bound(cumulative_.begin(), cumulative_.end(), s) - cumulative_.begin() - 1,
                       path_.waypoints.size() - 1);
  const Vec3& a = path_.waypoints[i];
  const Vec3& b = path_.waypoints[(i + 1) % path_.waypoints.size()];
  const double f = (s - cumulative_[i]) / (cumulative_[i + 1] - cumulative_[i]);
  if (heading) *heading = std::atan2(b.y() - a.y(), b.x() - a.x());
  return a + f * (b - a);
}

Shape MovingObject::shapeAt(double t) const {
  double heading = 0.0;
  const Vec3 ground = groundPointAt(t, &heading);
  Shape s = shape_;
  s.center = ground + Vec3(0.0, 0.0, shape_.half_size.z());
  s.rotation = Eigen::AngleAxisd(heading, Vec3::UnitZ()).toRotationMatrix();
  s.finalize();
  return s;
}

}  // namespace livo::sim
