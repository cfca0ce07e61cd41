// Objects that move through the scene on their own (pedestrians, cars): a shape that walks a closed
// polyline of ground points at a constant speed, looping, turned to face along its path.
#pragma once

#include <vector>

#include "livo/sim/shapes.hpp"

namespace livo::sim {

struct MoverPath {
  std::vector<Vec3> waypoints;  // closed polyline of ground points (the last joins the first)
  double speed = 1.4;           // m/s along the path
  double phase = 0.0;           // fraction of the loop already walked at scene time 0, [0, 1)
};

class MovingObject {
 public:
  /// `shape` is given in the mover's own frame: x forward, z up, standing on z = 0 (its centre
  /// is lifted by half_size.z). Throws std::invalid_argument for a degenerate path.
  MovingObject(const Shape& shape, const MoverPath& path);

  /// The shape placed in the world at scene time t.
  Shape shapeAt(double t) const;
  /// Ground point and heading (rad, about z) at scene time t.
  Vec3 groundPointAt(double t, double* heading = nullptr) const;
  double loopLength() const { return cumulative_.back(); }

 private:
  Shape shape_;
  MoverPath path_;
  std::vector<double> cumulative_;  // arc length at each waypoint; the last entry closes the loop
};

}  // namespace livo::sim
