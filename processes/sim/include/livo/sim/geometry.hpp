// Rays, axis-aligned boxes and ray hits: the vocabulary of the ray caster.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include "livo/so3.hpp"

namespace livo::sim {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

struct Ray {
  Vec3 origin = Vec3::Zero();
  Vec3 direction = Vec3::UnitX();  // unit length
};

/// Ray with the reciprocal direction precomputed for slab tests.
struct PreparedRay {
  explicit PreparedRay(const Ray& r) : ray(r) {
    for (int i = 0; i < 3; ++i) inv_direction[i] = 1.0 / r.direction[i];  // +-inf for 0 is fine
  }
  Ray ray;
  Vec3 inv_direction;
};

struct Aabb {
  Vec3 min = Vec3::Constant(kInfinity);
  Vec3 max = Vec3::Constant(-kInfinity);

  void extend(const Vec3& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  void extend(const Aabb& b) {
    min = min.cwiseMin(b.min);
    max = max.cwiseMax(b.max);
  }
  Vec3 center() const { return 0.5 * (min + max); }
  bool valid() const { return (min.array() <= max.array()).all(); }

  /// Overlap of the ray's parameter range with the box, clipped to [*t0, *t1].
  bool clip(const PreparedRay& r, double* t0, double* t1) const {
    double lo = *t0, hi = *t1;
    for (int i = 0; i < 3; ++i) {
      double a = (min[i] - r.ray.origin[i]) * r.inv_direction[i];
      double b = (max[i] - r.ray.origin[i]) * r.inv_direction[i];
      if (a > b) std::swap(a, b);
      if (std::isnan(a) || std::isnan(b)) {  // parallel ray exactly on a slab plane
        if (r.ray.origin[i] < min[i] || r.ray.origin[i] > max[i]) return false;
        continue;
      }
      lo = std::max(lo, a);
      hi = std::min(hi, b);
      if (lo > hi) return false;
    }
    *t0 = lo;
    *t1 = hi;
    return true;
  }
};

/// The nearest intersection found by a cast: which object, where along the ray, which face.
struct RayHit {
  double t = kInfinity;
  int object = -1;
  int face = 0;
  double time = 0.0;  // scene time of the cast (where a moving object was when it was hit)
  bool valid() const { return object >= 0; }
};

/// What a renderer or LiDAR needs to know about a hit point.
struct SurfacePoint {
  Vec3 position = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();  // unit, facing the ray origin
  double u = 0.0, v = 0.0;      // texture coordinates on the surface, metres
};

}  // namespace livo::sim
