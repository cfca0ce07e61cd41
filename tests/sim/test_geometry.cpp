// Ray casting against analytic primitives, height fields and the BVH, checked against closed-form
// distances and brute force.
#include <gtest/gtest.h>

#include "livo/sim/height_field.hpp"
#include "livo/sim/random.hpp"
#include "livo/sim/scene.hpp"
#include "livo/sim/shapes.hpp"
#include "livo/sim/texture.hpp"

using namespace livo;
using namespace livo::sim;

namespace {
Ray rayFrom(const Vec3& o, const Vec3& d) {
  Ray r;
  r.origin = o;
  r.direction = d.normalized();
  return r;
}
}  // namespace

TEST(Shapes, BoxFromOutsideAndInside) {
  Shape box;
  box.type = ShapeType::kBox;
  box.center = Vec3(1, 2, 3);
  box.half_size = Vec3(1, 2, 3);
  box.finalize();
  double t;
  int face;
  ASSERT_TRUE(intersectShape(box, rayFrom(Vec3(10, 2, 3), Vec3(-1, 0, 0)), 0, kInfinity, &t, &face));
  EXPECT_NEAR(t, 8.0, 1e-12);
  EXPECT_EQ(face, 1);  // +x face
  // from the centre: exits through the nearest face along the direction
  const Vec3 d = Vec3(0.3, -0.5, 0.8).normalized();
  ASSERT_TRUE(intersectShape(box, rayFrom(box.center, d), 0, kInfinity, &t, &face));
  const double expected = std::min({1.0 / std::abs(d.x()), 2.0 / std::abs(d.y()), 3.0 / std::abs(d.z())});
  EXPECT_NEAR(t, expected, 1e-12);
  const SurfacePoint sp = shapeSurface(box, rayFrom(box.center, d), t, face);
  EXPECT_LT(sp.normal.dot(d), 0.0);  // faces the ray origin
}

TEST(Shapes, RotatedBoxMatchesAxisAlignedInItsFrame) {
  Shape box;
  box.type = ShapeType::kBox;
  box.center = Vec3(5, -1, 2);
  box.half_size = Vec3(0.5, 1.5, 1.0);
  box.rotation = so3::Exp(Vec3(0.2, -0.4, 0.9));
  box.finalize();
  ASSERT_FALSE(box.axis_aligned);
  // a ray along the box's local -x axis from outside hits the +x face at distance 4.5
  const Vec3 ex = box.rotation.col(0);
  double t;
  int face;
  ASSERT_TRUE(intersectShape(box, rayFrom(box.center + 5.0 * ex, -ex), 0, kInfinity, &t, &face));
  EXPECT_NEAR(t, 4.5, 1e-12);
  const Aabb b = box.bounds();
  for (int sx : {-1, 1})
    for (int sy : {-1, 1})
      for (int sz : {-1, 1}) {
        const Vec3 corner = box.center + box.rotation * Vec3(sx * 0.5, sy * 1.5, sz * 1.0);
        EXPECT_TRUE((corner.array() >= b.min.array() - 1e-12).all() && (corner.array() <= b.max.array() + 1e-12).all());
      }
}

TEST(Shapes, CylinderSphereAndPlaneDistances) {
  Shape cyl;
  cyl.type = ShapeType::kCylinder;
  cyl.center = Vec3(0, 0, 1);
  cyl.half_size = Vec3(0.5, 0.5, 1.0);
  cyl.finalize();
  double t;
  int face;
  // horizontal ray offset by 0.3 from the axis: hits at x = -sqrt(0.25 - 0.09) = -0.4
  ASSERT_TRUE(intersectShape(cyl, rayFrom(Vec3(-5, 0.3, 1.2), Vec3(1, 0, 0)), 0, kInfinity, &t, &face));
  EXPECT_NEAR(t, 5.0 - 0.4, 1e-12);
  EXPECT_EQ(face, 0);
  // straight down onto the top cap
  ASSERT_TRUE(intersectShape(cyl, rayFrom(Vec3(0.1, 0.1, 5), Vec3(0, 0, -1)), 0, kInfinity, &t, &face));
  EXPECT_NEAR(t, 3.0, 1e-12);
  EXPECT_EQ(face, 1);
  // above the top: misses
  EXPECT_FALSE(intersectShape(cyl, rayFrom(Vec3(-5, 0, 2.5), Vec3(1, 0, 0)), 0, kInfinity, &t, &face));

  Shape sphere;
  sphere.type = ShapeType::kSphere;
  sphere.center = Vec3(3, 4, 0);
  sphere.half_size = Vec3::Constant(1.0);
  sphere.finalize();
  ASSERT_TRUE(intersectShape(sphere, rayFrom(Vec3::Zero(), Vec3(3, 4, 0)), 0, kInfinity, &t, &face));
  EXPECT_NEAR(t, 4.0, 1e-12);
  ASSERT_TRUE(intersectShape(sphere, rayFrom(sphere.center, Vec3(0, 0, 1)), 0, kInfinity, &t, &face));
  EXPECT_NEAR(t, 1.0, 1e-12);  // from inside

  Shape plane;
  plane.type = ShapeType::kPlane;
  plane.half_size = Vec3(kInfinity, kInfinity, 0);
  plane.finalize();
  const Vec3 d = Vec3(1, 2, -2).normalized();
  ASSERT_TRUE(intersectShape(plane, rayFrom(Vec3(0, 0, 3), d), 0, kInfinity, &t, &face));
  EXPECT_NEAR(t, 3.0 / (2.0 / 3.0), 1e-12);
  EXPECT_FALSE(plane.bounded());
}

TEST(HeightField, VerticalRaysHitTheSurfaceHeight) {
  HeightFieldOptions o;
  o.center = Vec3(5, -3, 0.5);
  o.size_x = 20;
  o.size_y = 12;
  o.resolution = 0.5;
  o.relief = {{0.8, 6.0}, {0.1, 1.0}};
  HeightField hf(o);
  Random rng(7, 1);
  int face;
  double t;
  for (int i = 0; i < 500; ++i) {
    const double x = rng.uniform(-4.9, 14.9), y = rng.uniform(-8.9, 2.9);
    ASSERT_TRUE(hf.intersect(PreparedRay(rayFrom(Vec3(x, y, 10), Vec3(0, 0, -1))), 0, kInfinity, &t, &face));
    EXPECT_NEAR(10.0 - t, hf.heightAt(x, y), 1e-9);
  }
  // slanted rays: the hit point lies on the surface and nothing lies above the segment before it
  for (int i = 0; i < 200; ++i) {
    const Vec3 o2(rng.uniform(-4, 14), rng.uniform(-8, 2), 3.0);
    const Vec3 d = Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), -rng.uniform(0.05, 1.0)).normalized();
    if (!hf.intersect(PreparedRay(rayFrom(o2, d)), 0, kInfinity, &t, &face)) continue;
    const Vec3 p = o2 + t * d;
    EXPECT_NEAR(p.z(), hf.heightAt(p.x(), p.y()), 1e-7);
    for (double a = 0.0; a < t - 1e-3; a += 0.05) {
      const Vec3 q = o2 + a * d;
      ASSERT_GT(q.z(), hf.heightAt(q.x(), q.y()) - 1e-9) << "passed through the surface at " << a;
    }
  }
}

TEST(Scene, BvhAndCulledCastsAgreeWithBruteForce) {
  Scene scene;
  TextureOptions to;
  scene.addTexture(to);
  Random rng(3, 3);
  std::vector<Shape> shapes;
  for (int i = 0; i < 150; ++i) {
    Shape s;
    s.type = static_cast<ShapeType>(1 + i % 3);  // box, cylinder, sphere
    s.center = Vec3(rng.uniform(-20, 20), rng.uniform(-20, 20), rng.uniform(-3, 3));
    s.half_size = Vec3(rng.uniform(0.2, 2), rng.uniform(0.2, 2), rng.uniform(0.2, 2));
    if (s.type != ShapeType::kBox) s.half_size.y() = s.half_size.x();
    if (i % 4 == 0) s.rotation = so3::Exp(Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)));
    s.finalize();
    shapes.push_back(s);
    scene.addShape("s" + std::to_string(i), s, Material{});
  }
  Shape ground;
  ground.type = ShapeType::kPlane;
  ground.center = Vec3(0, 0, -4);
  ground.half_size = Vec3(kInfinity, kInfinity, 0);
  ground.finalize();
  shapes.push_back(ground);
  scene.addShape("ground", ground, Material{});
  scene.build();
  for (int i = 0; i < 3000; ++i) {
    const Ray r = rayFrom(Vec3(rng.uniform(-25, 25), rng.uniform(-25, 25), rng.uniform(-2, 5)),
                          Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)));
    double best = kInfinity, t;
    int face, best_i = -1;
    for (size_t k = 0; k < shapes.size(); ++k)
      if (intersectShape(shapes[k], r, 1e-6, best, &t, &face)) best = t, best_i = static_cast<int>(k);
    const RayHit hit = scene.cast(r);
    ASSERT_EQ(hit.object, best_i);
    if (best_i >= 0) {
      EXPECT_DOUBLE_EQ(hit.t, best);
    }
    // a pyramid around this ray must keep the object it hits
    const Vec3 axis = r.direction, u = axis.unitOrthogonal(), v = axis.cross(u);
    const double a = 0.05;
    const Vec3 normals[4] = {std::sin(a) * axis + std::cos(a) * u, std::sin(a) * axis - std::cos(a) * u,
                             std::sin(a) * axis + std::cos(a) * v, std::sin(a) * axis - std::cos(a) * v};
    Scene::Candidates c;
    scene.cullPyramid(r.origin, normals, &c);
    const RayHit culled = scene.castAmong(r, c, static_cast<int>(i % 7) - 1);
    ASSERT_EQ(culled.object, best_i);
    if (best_i >= 0) {
      EXPECT_DOUBLE_EQ(culled.t, best);
    }
  }
}

TEST(Texture, CheckerSquaresAndFiltering) {
  TextureOptions o;
  o.pattern = TexturePattern::kChecker;
  o.scale = 0.25;
  o.color_a = Eigen::Vector3d(0.9, 0.9, 0.9);
  o.color_b = Eigen::Vector3d(0.1, 0.1, 0.1);
  o.grain = 0.0;
  o.variation = 0.0;
  Texture tex(o);
  EXPECT_NEAR(tex.sample(0.125, 0.125, 1e-4)[0], 0.9f, 1e-4);        // square (0, 0)
  EXPECT_NEAR(tex.sample(0.375, 0.125, 1e-4)[0], 0.1f, 1e-4);        // square (1, 0)
  EXPECT_NEAR(tex.sample(-0.125, 0.125, 1e-4)[0], 0.1f, 1e-4);       // square (-1, 0)
  EXPECT_NEAR(tex.sample(2.0 + 0.125, 0.125, 1e-4)[0], 0.9f, 1e-4);  // tiles
  // a footprint much larger than a square averages the two colours
  EXPECT_NEAR(tex.sample(0.3, 0.7, 10.0)[0], 0.5f, 1e-3);
}
