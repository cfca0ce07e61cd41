// A static scene: textured primitives and height fields with LiDAR reflectivity, a sky and a
// light, and a ray caster over them (BVH for bounded objects, unbounded planes tested directly).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "bvh.hpp"
#include "geometry.hpp"
#include "height_field.hpp"
#include "shapes.hpp"
#include "texture.hpp"

namespace livo {
namespace sim {

struct Material {
  int texture = 0;             // index into the scene's textures
  double reflectivity = 0.5;   // LiDAR reflectivity in [0, 1]
  double u_offset = 0.0;       // texture shift (m) so equal textures on different objects differ
  double v_offset = 0.0;
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
  /// Builds the acceleration structure; call after the last add*() and before casting.
  void build();

  /// Nearest hit with t in (t_min, t_max); invalid if the ray escapes (sky).
  RayHit cast(const Ray& ray, double t_min = 1e-6, double t_max = kInfinity) const;
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

  const Material& material(int object) const { return objects_[object].material; }
  const Texture& texture(int index) const { return *textures_[index]; }
  const std::string& objectName(int object) const { return objects_[object].name; }
  size_t objectCount() const { return objects_.size(); }
  size_t textureCount() const { return textures_.size(); }
  /// Bounds of the bounded objects.
  Aabb bounds() const;

  Lighting lighting;
  Sky sky;

 private:
  struct Object {
    std::string name;
    int shape = -1;         // index into shapes_, or
    int height_field = -1;  // index into height_fields_
    Material material;
  };
  Aabb objectBounds(int object) const;
  bool intersectObject(int object, const PreparedRay& ray, double t_min, double t_max, double* t, int* face) const;

  std::vector<Object> objects_;
  std::vector<Shape> shapes_;
  std::vector<std::unique_ptr<HeightField>> height_fields_;
  std::vector<std::unique_ptr<Texture>> textures_;
  std::vector<int> bounded_, unbounded_;  // object indices
  Bvh bvh_;
  bool built_ = false;
};

}  // namespace sim
}  // namespace livo
