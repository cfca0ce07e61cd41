// Analytic primitives (plane or rectangle, box, cylinder, sphere) in a local frame:
// exact ray intersection, surface normal and texture coordinates in metres.
#pragma once

#include "livo/sim/geometry.hpp"

namespace livo::sim {

enum class ShapeType { kPlane, kBox, kCylinder, kSphere };

/// A primitive placed in the world: p_world = rotation * p_local + center.
///  - plane:    local z is the normal; |x| <= half_size.x, |y| <= half_size.y (infinite if inf)
///  - box:      |p_i| <= half_size_i
///  - cylinder: axis local z, radius half_size.x, |z| <= half_size.z, capped
///  - sphere:   radius half_size.x
struct Shape {
  ShapeType type = ShapeType::kBox;
  Vec3 center = Vec3::Zero();
  Mat3 rotation = Mat3::Identity();
  Vec3 half_size = Vec3::Constant(0.5);
  bool axis_aligned = true;  // rotation is the identity (set by finalize())

  /// Call after setting `rotation`.
  void finalize() { axis_aligned = rotation == Mat3::Identity(); }
  bool bounded() const;
  /// World-frame bounding box (only for bounded shapes).
  Aabb bounds() const;
};

/// Nearest intersection with t in (t_min, t_max); `face` identifies the surface patch hit.
bool intersectShape(const Shape& shape, const Ray& ray, double t_min, double t_max, double* t, int* face);

/// The parameter range [*t_in, *t_out] over which the ray is inside a box, cylinder or sphere (t_in
/// may be negative if the origin is inside); false if the ray misses it or it is a plane.
bool shapeInterval(const Shape& shape, const Ray& ray, double* t_in, double* t_out);

/// Position, normal (facing the ray origin) and texture coordinates at a hit.
SurfacePoint shapeSurface(const Shape& shape, const Ray& ray, double t, int face);

}  // namespace livo::sim
