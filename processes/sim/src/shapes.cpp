#include "livo/sim/shapes.hpp"

namespace livo::sim {

namespace {

struct LocalRay {
  Vec3 o, d;
};
LocalRay toLocal(const Shape& s, const Ray& r) {
  if (s.axis_aligned) return {r.origin - s.center, r.direction};
  return {s.rotation.transpose() * (r.origin - s.center), s.rotation.transpose() * r.direction};
}

bool intersectPlane(const Shape& s, const LocalRay& r, double t_min, double t_max, double* t) {
  if (r.d.z() == 0.0) return false;
  const double tt = -r.o.z() / r.d.z();
  if (!(tt > t_min && tt < t_max)) return false;
  const double x = r.o.x() + tt * r.d.x(), y = r.o.y() + tt * r.d.y();
  if (std::abs(x) > s.half_size.x() || std::abs(y) > s.half_size.y()) return false;
  *t = tt;
  return true;
}

bool intersectBox(const Shape& s, const LocalRay& r, double t_min, double t_max, double* t, int* face) {
  double near = -kInfinity, far = kInfinity;
  int near_axis = 0, far_axis = 0;
  for (int i = 0; i < 3; ++i) {
    const double h = s.half_size[i];
    if (r.d[i] == 0.0) {
      if (std::abs(r.o[i]) > h) return false;
      continue;
    }
    double a = (-h - r.o[i]) / r.d[i], b = (h - r.o[i]) / r.d[i];
    if (a > b) std::swap(a, b);
    if (a > near) near = a, near_axis = i;
    if (b < far) far = b, far_axis = i;
    if (near > far) return false;
  }
  double tt;
  int axis;
  if (near > t_min) {
    tt = near, axis = near_axis;  // from outside
  } else if (far > t_min) {
    tt = far, axis = far_axis;  // from inside (a room seen from within)
  } else {
    return false;
  }
  if (tt >= t_max) return false;
  const double coord = r.o[axis] + tt * r.d[axis];
  *t = tt;
  *face = axis * 2 + (coord > 0.0 ? 1 : 0);
  return true;
}

bool intersectCylinder(const Shape& s, const LocalRay& r, double t_min, double t_max, double* t, int* face) {
  const double radius = s.half_size.x(), hz = s.half_size.z();
  double best = t_max;
  int best_face = -1;
  // side: (ox + t dx)^2 + (oy + t dy)^2 = r^2
  const double a = r.d.x() * r.d.x() + r.d.y() * r.d.y();
  if (a > 0.0) {
    const double b = r.o.x() * r.d.x() + r.o.y() * r.d.y();
    const double c = r.o.x() * r.o.x() + r.o.y() * r.o.y() - radius * radius;
    const double disc = b * b - a * c;
    if (disc >= 0.0) {
      const double sq = std::sqrt(disc);
      // numerically stable pair of roots
      const double q = b >= 0.0 ? -(b + sq) : -(b - sq);
      double t0 = q / a, t1 = q != 0.0 ? c / q : t0;
      if (t0 > t1) std::swap(t0, t1);
      for (double tt : {t0, t1}) {
        if (tt > t_min && tt < best && std::abs(r.o.z() + tt * r.d.z()) <= hz) {
          best = tt;
          best_face = 0;
          break;
        }
      }
    }
  }
  if (r.d.z() != 0.0) {
    for (int cap = 0; cap < 2; ++cap) {
      const double z = cap == 0 ? hz : -hz;
      const double tt = (z - r.o.z()) / r.d.z();
      if (tt > t_min && tt < best) {
        const double x = r.o.x() + tt * r.d.x(), y = r.o.y() + tt * r.d.y();
        if (x * x + y * y <= radius * radius) best = tt, best_face = 1 + cap;
      }
    }
  }
  if (best_face < 0) return false;
  *t = best;
  *face = best_face;
  return true;
}

bool intersectSphere(const Shape& s, const LocalRay& r, double t_min, double t_max, double* t) {
  const double radius = s.half_size.x();
  const double b = r.o.dot(r.d);
  const double c = r.o.squaredNorm() - radius * radius;
  const double disc = b * b - c;  // |d| = 1
  if (disc < 0.0) return false;
  const double sq = std::sqrt(disc);
  const double q = b >= 0.0 ? -(b + sq) : -(b - sq);
  double t0 = q, t1 = q != 0.0 ? c / q : q;
  if (t0 > t1) std::swap(t0, t1);
  for (double tt : {t0, t1}) {
    if (tt > t_min && tt < t_max) {
      *t = tt;
      return true;
    }
  }
  return false;
}

/// Overlap of the ray with the slab |o_i + t d_i| <= h on axis i, clipped into [*lo, *hi].
bool clipSlab(double o, double d, double h, double* lo, double* hi) {
  if (d == 0.0) return std::abs(o) <= h;
  double a = (-h - o) / d, b = (h - o) / d;
  if (a > b) std::swap(a, b);
  *lo = std::max(*lo, a);
  *hi = std::min(*hi, b);
  return *lo <= *hi;
}

/// Overlap of the ray with the infinite cylinder x^2 + y^2 <= r^2, clipped into [*lo, *hi].
bool clipDisc(const LocalRay& r, double radius, double* lo, double* hi) {
  const double a = r.d.x() * r.d.x() + r.d.y() * r.d.y();
  const double c = r.o.x() * r.o.x() + r.o.y() * r.o.y() - radius * radius;
  if (a == 0.0) return c <= 0.0;
  const double b = r.o.x() * r.d.x() + r.o.y() * r.d.y();
  const double disc = b * b - a * c;
  if (disc < 0.0) return false;
  const double sq = std::sqrt(disc);
  *lo = std::max(*lo, (-b - sq) / a);
  *hi = std::min(*hi, (-b + sq) / a);
  return *lo <= *hi;
}

}  // namespace

bool Shape::bounded() const {
  return type != ShapeType::kPlane || (std::isfinite(half_size.x()) && std::isfinite(half_size.y()));
}

Aabb Shape::bounds() const {
  Vec3 h = half_size;
  if (type == ShapeType::kPlane) h.z() = 0.0;
  if (type == ShapeType::kCylinder) h = Vec3(half_size.x(), half_size.x(), half_size.z());
  if (type == ShapeType::kSphere) h = Vec3::Constant(half_size.x());
  // extent of a rotated box: |R| h
  const Vec3 e = rotation.cwiseAbs() * h;
  Aabb b;
  b.extend(center - e);
  b.extend(center + e);
  return b;
}

bool intersectShape(const Shape& s, const Ray& ray, double t_min, double t_max, double* t, int* face) {
  const LocalRay r = toLocal(s, ray);
  *face = 0;
  switch (s.type) {
    case ShapeType::kPlane: return intersectPlane(s, r, t_min, t_max, t);
    case ShapeType::kBox: return intersectBox(s, r, t_min, t_max, t, face);
    case ShapeType::kCylinder: return intersectCylinder(s, r, t_min, t_max, t, face);
    case ShapeType::kSphere: return intersectSphere(s, r, t_min, t_max, t);
  }
  return false;
}

bool shapeInterval(const Shape& s, const Ray& ray, double* t_in, double* t_out) {
  const LocalRay r = toLocal(s, ray);
  double lo = -kInfinity, hi = kInfinity;
  bool inside = false;
  switch (s.type) {
    case ShapeType::kPlane: return false;
    case ShapeType::kBox:
      inside = clipSlab(r.o.x(), r.d.x(), s.half_size.x(), &lo, &hi) &&
               clipSlab(r.o.y(), r.d.y(), s.half_size.y(), &lo, &hi) &&
               clipSlab(r.o.z(), r.d.z(), s.half_size.z(), &lo, &hi);
      break;
    case ShapeType::kCylinder:
      inside = clipDisc(r, s.half_size.x(), &lo, &hi) && clipSlab(r.o.z(), r.d.z(), s.half_size.z(), &lo, &hi);
      break;
    case ShapeType::kSphere: {
      const double b = r.o.dot(r.d), c = r.o.squaredNorm() - s.half_size.x() * s.half_size.x();
      const double disc = b * b - c;
      inside = disc >= 0.0;
      if (inside) lo = -b - std::sqrt(disc), hi = -b + std::sqrt(disc);
      break;
    }
  }
  if (!inside) return false;
  *t_in = lo;
  *t_out = hi;
  return true;
}

SurfacePoint shapeSurface(const Shape& s, const Ray& ray, double t, int face) {
  SurfacePoint sp;
  sp.position = ray.origin + t * ray.direction;
  const Vec3 p =
      s.axis_aligned ? Vec3(sp.position - s.center) : Vec3(s.rotation.transpose() * (sp.position - s.center));
  Vec3 n_local = Vec3::UnitZ();
  switch (s.type) {
    case ShapeType::kPlane: sp.u = p.x(), sp.v = p.y(); break;
    case ShapeType::kBox: {
      const int axis = face / 2;
      n_local = Vec3::Zero();
      n_local[axis] = (face % 2) ? 1.0 : -1.0;
      // the two in-face axes; vertical faces map their height to v
      const int ua = axis == 0 ? 1 : 0, va = axis == 2 ? 1 : 2;
      sp.u = p[ua] + s.half_size[ua];
      sp.v = p[va] + s.half_size[va];
      break;
    }
    case ShapeType::kCylinder:
      if (face == 0) {
        n_local = Vec3(p.x(), p.y(), 0.0).normalized();
        sp.u = s.half_size.x() * std::atan2(p.y(), p.x());
        sp.v = p.z() + s.half_size.z();
      } else {
        n_local = face == 1 ? Vec3::UnitZ() : Vec3(-Vec3::UnitZ());
        sp.u = p.x(), sp.v = p.y();
      }
      break;
    case ShapeType::kSphere: {
      const double r = s.half_size.x();
      n_local = p / r;
      sp.u = r * std::atan2(p.y(), p.x());
      sp.v = r * std::asin(std::clamp(p.z() / r, -1.0, 1.0));
      break;
    }
  }
  sp.normal = s.rotation * n_local;
  if (sp.normal.dot(ray.direction) > 0.0) sp.normal = -sp.normal;
  return sp;
}

}  // namespace livo::sim
