#include "livo/sim/height_field.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "livo/sim/noise.hpp"

namespace livo::sim {

HeightField::HeightField(const HeightFieldOptions& o)
    : HeightField(o, [&o](double x, double y) {
        double h = o.center.z();
        int k = 0;
        for (const auto& [amplitude, wavelength] : o.relief)
          h += amplitude * gradientNoise(x / wavelength, y / wavelength, 1 << 20, o.seed + 31 * k++);
        return h;
      }) {}

HeightField::HeightField(const HeightFieldOptions& o, const std::function<double(double, double)>& height) {
  if (!(o.resolution > 0.0) || !(o.size_x > 0.0) || !(o.size_y > 0.0))
    throw std::invalid_argument("height field: size and resolution must be > 0");
  cell_ = o.resolution;
  nx_ = std::max(1, static_cast<int>(std::ceil(o.size_x / cell_)));
  ny_ = std::max(1, static_cast<int>(std::ceil(o.size_y / cell_)));
  x0_ = o.center.x() - 0.5 * nx_ * cell_;
  y0_ = o.center.y() - 0.5 * ny_ * cell_;
  heights_.resize(static_cast<size_t>(nx_ + 1) * (ny_ + 1));
  for (int j = 0; j <= ny_; ++j) {
    for (int i = 0; i <= nx_; ++i) {
      heights_[static_cast<size_t>(j) * (nx_ + 1) + i] = height(x0_ + i * cell_, y0_ + j * cell_);
    }
  }
  cell_range_.resize(static_cast<size_t>(nx_) * ny_);
  for (int j = 0; j < ny_; ++j) {
    for (int i = 0; i < nx_; ++i) {
      const double a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i, j + 1), d = vertex(i + 1, j + 1);
      cell_range_[static_cast<size_t>(j) * nx_ + i] = {static_cast<float>(std::min({a, b, c, d})),
                                                       static_cast<float>(std::max({a, b, c, d}))};
    }
  }
  // blocks of cells: a ray crosses a block whose heights it stays clear of without visiting its cells
  nbx_ = (nx_ + kBlock - 1) / kBlock;
  nby_ = (ny_ + kBlock - 1) / kBlock;
  block_range_.assign(static_cast<size_t>(nbx_) * nby_,
                      {std::numeric_limits<float>::max(), std::numeric_limits<float>::lowest()});
  for (int j = 0; j < ny_; ++j) {
    for (int i = 0; i < nx_; ++i) {
      auto& b = block_range_[static_cast<size_t>(j / kBlock) * nbx_ + i / kBlock];
      const auto& c = cell_range_[static_cast<size_t>(j) * nx_ + i];
      b.first = std::min(b.first, c.first);
      b.second = std::max(b.second, c.second);
    }
  }
  double lo = heights_[0], hi = heights_[0];
  for (double h : heights_) lo = std::min(lo, h), hi = std::max(hi, h);
  bounds_.extend(Vec3(x0_, y0_, lo));
  bounds_.extend(Vec3(x0_ + nx_ * cell_, y0_ + ny_ * cell_, hi));
}

double HeightField::heightAt(double x, double y) const {
  const double fx = (x - x0_) / cell_, fy = (y - y0_) / cell_;
  if (fx < 0.0 || fy < 0.0 || fx > nx_ || fy > ny_) return bounds_.min.z();
  const int i = std::min(nx_ - 1, static_cast<int>(fx)), j = std::min(ny_ - 1, static_cast<int>(fy));
  const double u = fx - i, v = fy - j;
  // triangles (00, 10, 11) where u >= v, and (00, 11, 01) where u < v
  const double h00 = vertex(i, j), h10 = vertex(i + 1, j), h01 = vertex(i, j + 1), h11 = vertex(i + 1, j + 1);
  if (u >= v) return h00 + u * (h10 - h00) + v * (h11 - h10);
  return h00 + v * (h01 - h00) + u * (h11 - h01);
}

namespace {
// Möller–Trumbore.
bool intersectTriangle(const Ray& r, const Vec3& a, const Vec3& b, const Vec3& c, double t_lo, double t_hi, double* t) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 p = r.direction.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-14) return false;
  const double inv = 1.0 / det;
  const Vec3 s = r.origin - a;
  const double u = s.dot(p) * inv;
  if (u < 0.0 || u > 1.0) return false;
  const Vec3 q = s.cross(e1);
  const double v = r.direction.dot(q) * inv;
  if (v < 0.0 || u + v > 1.0) return false;
  const double tt = e2.dot(q) * inv;
  if (!(tt > t_lo && tt < t_hi)) return false;
  *t = tt;
  return true;
}

/// The 2-D DDA: the cells of a grid of square cells of side `size` from (x0, y0), nx x ny of them,
/// that the ray crosses from the cell of its point at t0 until t1, in order. visit(i, j, t_enter,
/// t_exit) returns true to stop the walk (a hit), which then returns true.
template <class Visit>
bool walkGrid(const Ray& r, double t0, double t1, double x0, double y0, double size, int nx, int ny, Visit&& visit) {
  const Vec3 entry = r.origin + t0 * r.direction;
  int i = std::clamp(static_cast<int>(std::floor((entry.x() - x0) / size)), 0, nx - 1);
  int j = std::clamp(static_cast<int>(std::floor((entry.y() - y0) / size)), 0, ny - 1);
  const int step_i = r.direction.x() > 0.0 ? 1 : -1, step_j = r.direction.y() > 0.0 ? 1 : -1;
  const double dx = std::abs(r.direction.x()) > 1e-15 ? size / std::abs(r.direction.x()) : kInfinity;
  const double dy = std::abs(r.direction.y()) > 1e-15 ? size / std::abs(r.direction.y()) : kInfinity;
  const double bx = x0 + (i + (step_i > 0 ? 1 : 0)) * size, by = y0 + (j + (step_j > 0 ? 1 : 0)) * size;
  double next_x = dx < kInfinity ? (bx - r.origin.x()) / r.direction.x() : kInfinity;
  double next_y = dy < kInfinity ? (by - r.origin.y()) / r.direction.y() : kInfinity;
  double t_enter = t0;
  while (true) {
    const double t_exit = std::min({next_x, next_y, t1});
    if (visit(i, j, t_enter, t_exit)) return true;
    if (t_exit >= t1) return false;
    if (next_x < next_y) {
      i += step_i;
      t_enter = next_x;
      next_x += dx;
    } else {
      j += step_j;
      t_enter = next_y;
      next_y += dy;
    }
    if (i < 0 || j < 0 || i >= nx || j >= ny) return false;
  }
}
}  // namespace

bool HeightField::intersectCell(int i, int j, const Ray& ray, double t_lo, double t_hi, double* t, int* tri) const {
  const Vec3 v00 = vertexPoint(i, j), v10 = vertexPoint(i + 1, j), v01 = vertexPoint(i, j + 1),
             v11 = vertexPoint(i + 1, j + 1);
  double best = t_hi, tt;
  int which = -1;
  if (intersectTriangle(ray, v00, v10, v11, t_lo, best, &tt)) best = tt, which = 0;
  if (intersectTriangle(ray, v00, v11, v01, t_lo, best, &tt)) best = tt, which = 1;
  if (which < 0) return false;
  *t = best;
  *tri = which;
  return true;
}

bool HeightField::intersect(const PreparedRay& pr, double t_min, double t_max, double* t, int* face) const {
  double t0 = t_min, t1 = t_max;
  if (!bounds_.clip(pr, &t0, &t1)) return false;
  const Ray& r = pr.ray;
  // the DDA over blocks; the cells of a block whose heights the ray reaches are walked
  return walkGrid(r, t0, t1, x0_, y0_, kBlock * cell_, nbx_, nby_, [&](int i, int j, double t_enter, double t_exit) {
    const double za = r.origin.z() + t_enter * r.direction.z(), zb = r.origin.z() + t_exit * r.direction.z();
    const auto& range = block_range_[static_cast<size_t>(j) * nbx_ + i];
    return std::max(za, zb) >= range.first - 1e-6 && std::min(za, zb) <= range.second + 1e-6 &&
           walkCells(r, t_enter, t_exit, t_min, t_max, t, face);
  });
}

bool HeightField::walkCells(const Ray& r, double t_start, double t_end, double t_min, double t_max, double* t,
                            int* face) const {
  const double slack = 1e-9 * (1.0 + std::abs(t_end));
  return walkGrid(r, t_start, t_end, x0_, y0_, cell_, nx_, ny_, [&](int i, int j, double t_enter, double t_exit) {
    const double za = r.origin.z() + t_enter * r.direction.z(), zb = r.origin.z() + t_exit * r.direction.z();
    const auto& range = cell_range_[static_cast<size_t>(j) * nx_ + i];
    if (std::max(za, zb) < range.first - 1e-9 || std::min(za, zb) > range.second + 1e-9) return false;
    int tri;
    if (!intersectCell(i, j, r, std::max(t_min, t_enter - slack), std::min(t_max, t_exit + slack), t, &tri))
      return false;
    *face = (j * nx_ + i) * 2 + tri;
    return true;
  });
}

SurfacePoint HeightField::surface(const Ray& ray, double t, int face) const {
  SurfacePoint sp;
  sp.position = ray.origin + t * ray.direction;
  const int cell = face / 2, i = cell % nx_, j = cell / nx_;
  const Vec3 v00 = vertexPoint(i, j), v11 = vertexPoint(i + 1, j + 1);
  const Vec3 other = (face % 2 == 0) ? vertexPoint(i + 1, j) : vertexPoint(i, j + 1);
  Vec3 n = (face % 2 == 0) ? (other - v00).cross(v11 - v00) : (v11 - v00).cross(other - v00);
  n.normalize();
  if (n.dot(ray.direction) > 0.0) n = -n;
  sp.normal = n;
  sp.u = sp.position.x();
  sp.v = sp.position.y();
  return sp;
}

}  // namespace livo::sim
