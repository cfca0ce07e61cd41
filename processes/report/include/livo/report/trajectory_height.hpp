// The height of the trajectory near a place: the pictures cut the map relative to it (the ceiling
// above the path left out, the OctoMap slice a band around it), so a path up a ramp or across
// floors still gets a sensible cut everywhere.
#pragma once

#include <vector>

#include "livo/trajectory_io.hpp"

namespace livo::report {

/// The height (z) of the trajectory's nearest pose in the horizontal plane, on a grid: the poses
/// seed the cells they fall in (the mean z of a cell's poses), and every other cell takes the
/// height of the seed a breadth-first wave (8 neighbours) reaches it from first, seeds in cell
/// order; so "nearest" is in grid steps (the chessboard distance), not exact, and deterministic.
/// Outside the grid, the nearest border cell. Without poses every height is 0.
class TrajectoryHeight {
 public:
  TrajectoryHeight() = default;
  /// A grid over the poses' horizontal extent widened by `reach_m` on every side, of cells
  /// `cell_m` wide, coarsened until it has at most `max_cells`.
  explicit TrajectoryHeight(const Trajectory& trajectory, double reach_m = 100.0, double cell_m = 0.5,
                            size_t max_cells = 1u << 20);

  double at(double x, double y) const;
  bool empty() const { return heights_.empty(); }
  /// The median z of the poses (0 without poses).
  double median() const { return median_; }
  double minimum() const { return min_; }  // of the grid's heights
  double maximum() const { return max_; }
  double cellSize() const { return cell_; }

 private:
  double x0_ = 0.0, y0_ = 0.0, cell_ = 1.0;
  int nx_ = 0, ny_ = 0;
  std::vector<float> heights_;  // row-major, ny_ rows of nx_
  double median_ = 0.0, min_ = 0.0, max_ = 0.0;
};

}  // namespace livo::report
