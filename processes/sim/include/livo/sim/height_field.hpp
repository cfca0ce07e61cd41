// Height-field ground: z = base + relief(x, y) (or any height function) over a rectangle, sampled on a
// regular grid and ray-cast cell by cell (2-D DDA with per-cell height bounds, two triangles per cell).
#pragma once

#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "livo/sim/geometry.hpp"

namespace livo::sim {

struct HeightFieldOptions {
  Vec3 center = Vec3::Zero();           // centre of the rectangle; z is the base height
  double size_x = 20.0, size_y = 20.0;  // m
  double resolution = 0.5;              // grid spacing, m
  /// Relief as octaves of gradient noise: (amplitude m, wavelength m) pairs.
  std::vector<std::pair<double, double>> relief = {{0.3, 10.0}, {0.05, 1.0}};
  uint64_t seed = 1;
};

class HeightField {
 public:
  explicit HeightField(const HeightFieldOptions& options);
  /// The grid of `grid` (center x, y, size, resolution; its relief and center z unused) sampled from
  /// z = height(x, y) at the vertices.
  HeightField(const HeightFieldOptions& grid, const std::function<double(double, double)>& height);

  /// Height of the triangulated surface at (x, y) (base height outside the rectangle).
  double heightAt(double x, double y) const;
  const Aabb& bounds() const { return bounds_; }

  bool intersect(const PreparedRay& ray, double t_min, double t_max, double* t, int* face) const;
  SurfacePoint surface(const Ray& ray, double t, int face) const;

 private:
  double vertex(int i, int j) const { return heights_[static_cast<size_t>(j) * (nx_ + 1) + i]; }
  Vec3 vertexPoint(int i, int j) const { return Vec3(x0_ + i * cell_, y0_ + j * cell_, vertex(i, j)); }
  bool intersectCell(int i, int j, const Ray& ray, double t_lo, double t_hi, double* t, int* tri) const;
  /// The cell walk (2-D DDA) from the ray's point at t_start until t_end, the nearest hit first.
  bool walkCells(const Ray& ray, double t_start, double t_end, double t_min, double t_max, double* t, int* face) const;

  int nx_ = 0, ny_ = 0;
  double x0_ = 0.0, y0_ = 0.0, cell_ = 1.0;
  std::vector<double> heights_;                      // (nx+1) x (ny+1), absolute z
  std::vector<std::pair<float, float>> cell_range_;  // min/max z per cell
  static constexpr int kBlock = 16;                  // cells per block side
  int nbx_ = 0, nby_ = 0;
  std::vector<std::pair<float, float>> block_range_;  // min/max z per block of kBlock x kBlock cells
  Aabb bounds_;
};

}  // namespace livo::sim
