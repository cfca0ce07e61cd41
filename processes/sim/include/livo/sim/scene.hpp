// A scene: textured primitives and height fields with LiDAR reflectivity, a sky and a light, and a
// ray caster over them (BVH for bounded objects, unbounded planes tested directly). A few moving
// objects (pedestrians, cars) are tested separately at the cast's time, the nearer hit winning.
// Materials: opaque, glass (a LiDAR beam mostly passes through) and vegetation (a volume of
// leaves a ray enters to an exponentially distributed depth).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "livo/sim/bvh.hpp"
#include "livo/sim/geometry.hpp"
#include "livo/sim/height_field.hpp"
#include "livo/sim/moving_object.hpp"
#include "livo/sim/shapes.hpp"
#include "livo/sim/terrain.hpp"
#include "livo/sim/texture.hpp"

namespace livo::sim {

enum class MaterialKind {
  kOpaque,
  kGlass,       // a surface the camera sees through and a LiDAR beam mostly passes
  kVegetation,  // a volume (box, cylinder or sphere) of leaves: hit at an exponentially distributed depth
};

struct Material {
  int texture = 0;            // index into the scene's textures
  double reflectivity = 0.5;  // LiDAR reflectivity in [0, 1]
  double u_offset = 0.0;      // texture shift (m) so equal textures on different objects differ
  double v_offset = 0.0;
  MaterialKind kind = MaterialKind::kOpaque;
  double glass_return_probability = 0.05;  // glass: chance a LiDAR beam returns from this object
  double glass_transmission = 0.95;        // glass: share of the light from behind, per surface
  double leaf_density = 1.0;               // vegetation: extinction coefficient (1/m), free path 1/this
};

/// What a cast needs beyond the ray: the scene time (where moving objects are), a key that makes
/// the random interactions reproducible per ray (vegetation depth, LiDAR glass returns: each is a
/// function of (key, object) only), and whether glass is sampled the LiDAR way (returns with its
/// probability, else is transparent) or is a plain surface (the camera's way).
struct CastContext {
  double time = 0.0;
  uint64_t key = 0;
  bool sample_glass = false;
  static CastContext lidar(double time, uint64_t key) { return {time, key, true}; }
  static CastContext camera(double time, uint64_t key) { return {time, key, false}; }
};

struct Lighting {
  Vec3 direction = Vec3(0.3, 0.2, -1.0).normalized();  // direction the light travels
  double ambient = 0.45;
  double diffuse = 0.55;
};

struct Sky {
  Eigen::Vector3d horizon{0.85, 0.88, 0.92};
  Eigen::Vector3d zenith{0.40, 0.55, 0.85};
};

class Scene {
 public:
  int addTexture(const TextureOptions& options);
  int addShape(const std::string& name, const Shape& shape, const Material& material);
  int addHeightField(const std::string& name, const HeightFieldOptions& options, const Material& material);
  int addHeightField(const std::string& name, std::unique_ptr<HeightField> field, const Material& material);
  /// A moving object (opaque or glass); it is not in the BVH but tested at each cast's time.
  int addMover(const std::string& name, const MovingObject& mover, const Material& material);
  /// Builds the acceleration structure; call after the last add*() and before casting.
  void build();

  /// Nearest hit with t in (t_min, t_max); invalid if the ray escapes (sky). Moving objects at
  /// time 0, glass as a plain surface, vegetation depths from key 0.
  RayHit cast(const Ray& ray, double t_min = 1e-6, double t_max = kInfinity) const;
  /// The same at the context's time, with its random key and glass handling.
  RayHit cast(const Ray& ray, const CastContext& context, double t_min = 1e-6, double t_max = kInfinity) const;
  /// Position, normal and texture coordinates at a hit (moving objects where they were at hit.time).
  SurfacePoint surface(const Ray& ray, const RayHit& hit) const;

  /// Objects a bundle of rays from one origin may hit, nearest first (by the distance from the
  /// origin to their bounds, a lower bound of any hit distance).
  struct Candidates {
    std::vector<int> objects;
    std::vector<double> distance;
  };
  /// Culls to the pyramid of planes through `origin` with inward unit normals `normals`.
  void cullPyramid(const Vec3& origin, const Vec3 (&normals)[4], Candidates* out) const;
  /// Nearest hit among `candidates` (trying `hint` first, e.g. the neighbouring pixel's object).
  RayHit castAmong(const Ray& ray, const Candidates& candidates, int hint, double t_min = 1e-6,
                   double t_max = kInfinity) const;
  /// The same, plus the moving objects at the context's time.
  RayHit castAmong(const Ray& ray, const Candidates& candidates, int hint, const CastContext& context,
                   double t_min = 1e-6, double t_max = kInfinity) const;

  const Material& material(int object) const { return objects_[object].material; }
  const Texture& texture(int index) const { return *textures_[index]; }
  const std::string& objectName(int object) const { return objects_[object].name; }
  size_t objectCount() const { return objects_.size(); }
  size_t moverCount() const { return movers_.size(); }
  size_t textureCount() const { return textures_.size(); }
  /// Bounds of the bounded objects.
  Aabb bounds() const;

  Lighting lighting;
  Sky sky;
  /// The graded ground a car drives on (null: none; the scene's `terrain:`); its surface is one of
  /// the objects, a height field sampled from it.
  std::shared_ptr<const Terrain> terrain;

 private:
  struct Object {
    std::string name;
    int shape = -1;         // index into shapes_, or
    int height_field = -1;  // index into height_fields_, or
    int mover = -1;         // index into movers_
    Material material;
  };
  Aabb objectBounds(int object) const;
  bool intersectObject(int object, const PreparedRay& ray, const CastContext& context, double t_min, double t_max,
                       double* t, int* face) const;
  bool intersectVegetation(int object, const Ray& ray, const CastContext& context, double t_min, double t_max,
                           double* t) const;
  /// Lowers `hit` to the nearest moving object hit before it, if any.
  void castMovers(const Ray& ray, const CastContext& context, double t_min, double t_max, RayHit* hit) const;

  std::vector<Object> objects_;
  std::vector<Shape> shapes_;
  std::vector<std::unique_ptr<HeightField>> height_fields_;
  std::vector<MovingObject> movers_;
  std::vector<int> mover_objects_;  // object index of each mover
  std::vector<std::unique_ptr<Texture>> textures_;
  std::vector<int> bounded_, unbounded_;  // object indices
  Bvh bvh_;
  bool built_ = false;
};

}  // namespace livo::sim
