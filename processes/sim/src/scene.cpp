#include "livo/sim/scene.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "livo/sim/random.hpp"

namespace livo::sim {

int Scene::addTexture(const TextureOptions& options) {
  textures_.push_back(std::make_unique<Texture>(options));
  return static_cast<int>(textures_.size()) - 1;
}

int Scene::addShape(const std::string& name, const Shape& shape, const Material& material) {
  shapes_.push_back(shape);
  shapes_.back().finalize();
  objects_.push_back({name, static_cast<int>(shapes_.size()) - 1, -1, -1, material});
  built_ = false;
  return static_cast<int>(objects_.size()) - 1;
}

int Scene::addHeightField(const std::string& name, const HeightFieldOptions& options, const Material& material) {
  return addHeightField(name, std::make_unique<HeightField>(options), material);
}

int Scene::addHeightField(const std::string& name, std::unique_ptr<HeightField> field, const Material& material) {
  height_fields_.push_back(std::move(field));
  objects_.push_back({name, -1, static_cast<int>(height_fields_.size()) - 1, -1, material});
  built_ = false;
  return static_cast<int>(objects_.size()) - 1;
}

int Scene::addMover(const std::string& name, const MovingObject& mover, const Material& material) {
  if (material.kind == MaterialKind::kVegetation) throw std::logic_error("mover " + name + " cannot be vegetation");
  movers_.push_back(mover);
  objects_.push_back({name, -1, -1, static_cast<int>(movers_.size()) - 1, material});
  mover_objects_.push_back(static_cast<int>(objects_.size()) - 1);
  built_ = false;
  return static_cast<int>(objects_.size()) - 1;
}

void Scene::build() {
  bounded_.clear();
  unbounded_.clear();
  std::vector<Aabb> boxes;
  for (size_t i = 0; i < objects_.size(); ++i) {
    const Object& o = objects_[i];
    if (o.material.texture < 0 || o.material.texture >= static_cast<int>(textures_.size()))
      throw std::logic_error("scene object " + o.name + " has no valid texture");
    if (o.mover >= 0) continue;  // tested at each cast's time, outside the BVH
    if (o.material.kind == MaterialKind::kVegetation && (o.shape < 0 || !shapes_[o.shape].bounded()))
      throw std::logic_error("vegetation " + o.name + " must be a bounded shape");
    if (o.height_field >= 0) {
      bounded_.push_back(static_cast<int>(i));
      boxes.push_back(height_fields_[o.height_field]->bounds());
    } else if (shapes_[o.shape].bounded()) {
      bounded_.push_back(static_cast<int>(i));
      boxes.push_back(shapes_[o.shape].bounds());
    } else {
      unbounded_.push_back(static_cast<int>(i));
    }
  }
  bvh_.build(boxes);
  built_ = true;
}

Aabb Scene::objectBounds(int i) const {
  const Object& o = objects_[i];
  return o.height_field >= 0 ? height_fields_[o.height_field]->bounds() : shapes_[o.shape].bounds();
}

Aabb Scene::bounds() const {
  Aabb b;
  for (int i : bounded_) b.extend(objectBounds(i));
  return b;
}

namespace {
/// False if the box lies entirely on the outer side of a plane through `o` with inward normal n.
bool insideAll(const Aabb& box, const Vec3& o, const Vec3 (&normals)[4]) {
  for (const Vec3& n : normals) {
    // the corner farthest along n
    const Vec3 p(n.x() >= 0.0 ? box.max.x() : box.min.x(), n.y() >= 0.0 ? box.max.y() : box.min.y(),
                 n.z() >= 0.0 ? box.max.z() : box.min.z());
    if (n.dot(p - o) < 0.0) return false;
  }
  return true;
}
double distanceToBox(const Aabb& box, const Vec3& p) {
  const Vec3 d = (box.min - p).cwiseMax(p - box.max).cwiseMax(Vec3::Zero());
  return d.norm();
}
}  // namespace

void Scene::cullPyramid(const Vec3& origin, const Vec3 (&normals)[4], Candidates* out) const {
  if (!built_) throw std::logic_error("Scene::cullPyramid before Scene::build");
  std::vector<std::pair<double, int>> found;
  for (int i : unbounded_) {
    const Shape& s = shapes_[objects_[i].shape];
    found.emplace_back(std::abs((s.rotation.transpose() * (origin - s.center)).z()), i);
  }
  bvh_.visit([&](const Aabb& box) { return insideAll(box, origin, normals); },
             [&](int item) {
               const int object = bounded_[item];
               const Aabb box = objectBounds(object);
               if (insideAll(box, origin, normals)) found.emplace_back(distanceToBox(box, origin), object);
             });
  std::sort(found.begin(), found.end());
  out->objects.clear();
  out->distance.clear();
  for (const auto& [d, i] : found) {
    out->objects.push_back(i);
    out->distance.push_back(d);
  }
}

RayHit Scene::castAmong(const Ray& ray, const Candidates& c, int hint, double t_min, double t_max) const {
  return castAmong(ray, c, hint, CastContext{}, t_min, t_max);
}

RayHit Scene::castAmong(const Ray& ray, const Candidates& c, int hint, const CastContext& context, double t_min,
                        double t_max) const {
  const PreparedRay pr(ray);
  RayHit hit;
  double t;
  int face;
  if (hint >= 0 && objects_[hint].mover < 0 && intersectObject(hint, pr, context, t_min, t_max, &t, &face)) {
    t_max = t;
    hit = {t, hint, face};
  }
  for (size_t k = 0; k < c.objects.size(); ++k) {
    if (c.distance[k] >= t_max) break;
    const int object = c.objects[k];
    if (object == hint) continue;
    if (intersectObject(object, pr, context, t_min, t_max, &t, &face)) {
      t_max = t;
      hit = {t, object, face};
    }
  }
  castMovers(ray, context, t_min, t_max, &hit);
  return hit;
}

namespace {
// Random stream ids of the per-ray interactions.
enum InteractionStream : uint64_t { kGlassStream = 0x61a55ULL, kFoliageStream = 0xf011a6eULL };

/// Whether a LiDAR beam with this key returns from this glass object (else it passes through).
bool glassReturns(uint64_t key, int object, double probability) {
  return Random(key, kGlassStream, static_cast<uint64_t>(object)).uniform() < probability;
}
}  // namespace

bool Scene::intersectObject(int object, const PreparedRay& ray, const CastContext& context, double t_min, double t_max,
                            double* t, int* face) const {
  const Object& o = objects_[object];
  if (o.material.kind == MaterialKind::kVegetation) {
    *face = 0;
    return intersectVegetation(object, ray.ray, context, t_min, t_max, t);
  }
  if (o.material.kind == MaterialKind::kGlass && context.sample_glass &&
      !glassReturns(context.key, object, o.material.glass_return_probability))
    return false;
  if (o.height_field >= 0) return height_fields_[o.height_field]->intersect(ray, t_min, t_max, t, face);
  if (o.mover >= 0) return intersectShape(movers_[o.mover].shapeAt(context.time), ray.ray, t_min, t_max, t, face);
  return intersectShape(shapes_[o.shape], ray.ray, t_min, t_max, t, face);
}

bool Scene::intersectVegetation(int object, const Ray& ray, const CastContext& context, double t_min, double t_max,
                                double* t) const {
  const Object& o = objects_[object];
  double t_in, t_out;
  if (!shapeInterval(shapes_[o.shape], ray, &t_in, &t_out)) return false;
  const double entry = std::max(t_in, t_min);
  if (entry >= t_out) return false;
  // free flight through the leaves: exponential with mean 1 / leaf_density, one draw per (ray, crown)
  const double u = Random(context.key, kFoliageStream, static_cast<uint64_t>(object)).uniform();
  const double depth = entry - std::log1p(-u) / o.material.leaf_density;
  if (!(depth < t_out && depth < t_max && depth > t_min)) return false;
  *t = depth;
  return true;
}

void Scene::castMovers(const Ray& ray, const CastContext& context, double t_min, double t_max, RayHit* hit) const {
  double t;
  int face;
  for (int object : mover_objects_) {
    const Object& o = objects_[object];
    if (o.material.kind == MaterialKind::kGlass && context.sample_glass &&
        !glassReturns(context.key, object, o.material.glass_return_probability))
      continue;
    if (intersectShape(movers_[o.mover].shapeAt(context.time), ray, t_min, std::min(t_max, hit->t), &t, &face))
      *hit = {t, object, face};
  }
  hit->time = context.time;
}

RayHit Scene::cast(const Ray& ray, double t_min, double t_max) const { return cast(ray, CastContext{}, t_min, t_max); }

RayHit Scene::cast(const Ray& ray, const CastContext& context, double t_min, double t_max) const {
  if (!built_) throw std::logic_error("Scene::cast before Scene::build");
  const PreparedRay pr(ray);
  RayHit hit;
  double t;
  int face;
  for (int i : unbounded_) {
    if (intersectObject(i, pr, context, t_min, t_max, &t, &face)) {
      t_max = t;
      hit = {t, i, face};
    }
  }
  bvh_.traverse(pr, t_min, t_max, [&](int item, double t_best) {
    const int object = bounded_[item];
    if (intersectObject(object, pr, context, t_min, t_best, &t, &face)) {
      hit = {t, object, face};
      return t;
    }
    return t_best;
  });
  castMovers(ray, context, t_min, t_max, &hit);
  return hit;
}

namespace {
/// A leaf met inside a vegetation volume: a random orientation (facing the ray) drawn from the hit
/// itself, and texture coordinates along the world axes.
SurfacePoint leafSurface(const Ray& ray, double t, int object) {
  SurfacePoint sp;
  sp.position = ray.origin + t * ray.direction;
  uint64_t bits;
  std::memcpy(&bits, &t, sizeof bits);
  Random r(bits, kFoliageStream, static_cast<uint64_t>(object) + 1);
  sp.normal = r.normal3().normalized();
  if (sp.normal.dot(ray.direction) > 0.0) sp.normal = -sp.normal;
  sp.u = sp.position.x() + 0.5 * sp.position.y();
  sp.v = sp.position.z() + 0.5 * sp.position.y();
  return sp;
}
}  // namespace

SurfacePoint Scene::surface(const Ray& ray, const RayHit& hit) const {
  const Object& o = objects_[hit.object];
  SurfacePoint sp;
  if (o.material.kind == MaterialKind::kVegetation)
    sp = leafSurface(ray, hit.t, hit.object);
  else if (o.height_field >= 0)
    sp = height_fields_[o.height_field]->surface(ray, hit.t, hit.face);
  else if (o.mover >= 0)
    sp = shapeSurface(movers_[o.mover].shapeAt(hit.time), ray, hit.t, hit.face);
  else
    sp = shapeSurface(shapes_[o.shape], ray, hit.t, hit.face);
  sp.u += o.material.u_offset;
  sp.v += o.material.v_offset;
  return sp;
}

}  // namespace livo::sim
