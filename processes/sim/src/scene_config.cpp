#include "livo/sim/scene_config.hpp"

#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>
#include <variant>

#include "livo/sim/random.hpp"

namespace livo::sim {

namespace {

Mat3 rotationFromRpyDeg(const Vec3& rpy_deg) {
  const Vec3 r = rpy_deg * M_PI / 180.0;
  return (Eigen::AngleAxisd(r.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(r.y(), Vec3::UnitY()) *
          Eigen::AngleAxisd(r.x(), Vec3::UnitX()))
      .toRotationMatrix();
}

/// A rotation whose z axis is `normal`.
Mat3 rotationFromNormal(const Vec3& normal) {
  const Vec3 z = normal.normalized();
  const Vec3 helper = std::abs(z.z()) < 0.9 ? Vec3::UnitZ() : Vec3::UnitX();
  const Vec3 x = helper.cross(z).normalized();
  Mat3 R;
  R.col(0) = x;
  R.col(1) = z.cross(x);
  R.col(2) = z;
  return R;
}

double positive(const Config& c, const std::string& key) {
  const double v = c.get<double>(key);
  if (!(v > 0.0)) throw ConfigError(c.where(key) + ": must be > 0");
  return v;
}

Eigen::Vector3d colour(const Config& c, const std::string& key) {
  const Eigen::Vector3d v = c.get<Eigen::Vector3d>(key);
  if ((v.array() < 0.0).any() || (v.array() > 1.0).any())
    throw ConfigError(c.where(key) + ": colour components must be in [0, 1]");
  return v;
}

TextureOptions readTexture(const Config& c, uint64_t seed) {
  TextureOptions t;
  t.seed = seed;
  const std::string pattern = c.get<std::string>("pattern");
  if (!parseTexturePattern(pattern, &t.pattern))
    throw ConfigError(c.where("pattern") + ": unknown pattern '" + pattern +
                      "' (known: uniform, noise, bricks, checker, stripes)");
  t.color_a = colour(c, "color");
  if (c.has("color2"))
    t.color_b = colour(c, "color2");
  else
    t.color_b = 0.5 * t.color_a;
  if (t.pattern != TexturePattern::kUniform) t.scale = positive(c, "scale");
  if (t.pattern == TexturePattern::kBricks) {
    t.brick_height = positive(c, "brick_height");
    c.readOptional("mortar", t.mortar);
  }
  if (t.pattern == TexturePattern::kNoise) {
    c.readOptional("octaves", t.octaves);
    if (t.octaves < 1 || t.octaves > 6) throw ConfigError(c.where("octaves") + ": must be in 1..6");
  }
  c.readOptional("grain", t.grain);
  c.readOptional("variation", t.variation);
  if (t.grain < 0.0 || t.grain > 1.0) throw ConfigError(c.where("grain") + ": must be in [0, 1]");
  if (t.variation < 0.0 || t.variation > 1.0) throw ConfigError(c.where("variation") + ": must be in [0, 1]");
  c.checkAllUsed();
  return t;
}

struct Placement {
  int count = 1, rows = 1;
  Vec3 step = Vec3::Zero(), row_step = Vec3::Zero(), jitter = Vec3::Zero();
  int seed = 0;
};

Placement readRepeat(const Config& c) {
  Placement p;
  if (!c.has("repeat")) return p;
  const Config r = c.section("repeat");
  r.read("count", p.count);
  r.read("step", p.step);
  r.readOptional("rows", p.rows);
  if (p.rows > 1) r.read("row_step", p.row_step);
  r.readOptional("jitter", p.jitter);
  r.readOptional("seed", p.seed);
  if (p.count < 1 || p.count > 100000) throw ConfigError(r.where("count") + ": must be in 1..100000");
  if (p.rows < 1 || p.rows > 100000) throw ConfigError(r.where("rows") + ": must be in 1..100000");
  r.checkAllUsed();
  return p;
}

double unitInterval(const Config& c, const std::string& key, double value) {
  c.readOptional(key, value);
  if (!(value >= 0.0 && value <= 1.0)) throw ConfigError(c.where(key) + ": must be in [0, 1]");
  return value;
}

/// texture, reflectivity, and `material: opaque | glass` with glass's return_probability, transmission.
Material readMaterial(const Config& c, const std::map<std::string, int>& textures) {
  const std::string tex = c.get<std::string>("texture");
  const auto it = textures.find(tex);
  if (it == textures.end()) throw ConfigError(c.where("texture") + ": unknown texture '" + tex + "'");
  Material m;
  m.texture = it->second;
  m.reflectivity = unitInterval(c, "reflectivity", m.reflectivity);
  std::string kind = "opaque";
  c.readOptional("material", kind);
  if (kind == "glass") {
    m.kind = MaterialKind::kGlass;
    m.glass_return_probability = unitInterval(c, "return_probability", m.glass_return_probability);
    m.glass_transmission = unitInterval(c, "transmission", m.glass_transmission);
  } else if (kind != "opaque") {
    throw ConfigError(c.where("material") + ": unknown material '" + kind + "' (known: opaque, glass)");
  }
  return m;
}

/// A box (`size`), cylinder (`radius`, `height`) or sphere (`radius`) named by `form` into *shape;
/// false for another form.
bool readSolid(const Config& c, const std::string& form, Shape* shape) {
  if (form == "box") {
    shape->type = ShapeType::kBox;
    const Vec3 size = c.get<Vec3>("size");
    if ((size.array() <= 0.0).any()) throw ConfigError(c.where("size") + ": must be > 0");
    shape->half_size = 0.5 * size;
  } else if (form == "cylinder") {
    shape->type = ShapeType::kCylinder;
    const double radius = positive(c, "radius"), height = positive(c, "height");
    shape->half_size = Vec3(radius, radius, 0.5 * height);
  } else if (form == "sphere") {
    shape->type = ShapeType::kSphere;
    shape->half_size = Vec3::Constant(positive(c, "radius"));
  } else {
    return false;
  }
  return true;
}

/// A box, cylinder or sphere crown of leaves (`shape`, its size keys, `leaf_density` in 1/m).
Shape readVegetation(const Config& c, Material* m) {
  if (m->kind != MaterialKind::kOpaque) throw ConfigError(c.where("material") + ": vegetation has no material key");
  m->kind = MaterialKind::kVegetation;
  m->leaf_density = positive(c, "leaf_density");
  std::string form = "cylinder";
  c.readOptional("shape", form);
  Shape shape;
  if (!readSolid(c, form, &shape))
    throw ConfigError(c.where("shape") + ": unknown vegetation shape '" + form + "' (known: box, cylinder, sphere)");
  return shape;
}

/// A plane turned by `rotation` (from rpy_deg) or by its `normal` (not both), infinite unless `size`
/// [size_x, size_y] bounds it.
Shape readPlane(const Config& c, bool has_rpy, const Mat3& rotation) {
  Shape shape;
  shape.type = ShapeType::kPlane;
  shape.rotation = rotation;
  if (c.has("normal")) {
    if (has_rpy) throw ConfigError(c.where("normal") + ": give normal or rpy_deg, not both");
    shape.rotation = rotationFromNormal(c.get<Vec3>("normal"));
  }
  shape.half_size = Vec3(kInfinity, kInfinity, 0.0);
  std::vector<double> size;
  if (c.readOptional("size", size)) {
    if (size.size() != 2 || !(size[0] > 0.0) || !(size[1] > 0.0))
      throw ConfigError(c.where("size") + ": expected [size_x, size_y] > 0 (omit for an infinite plane)");
    shape.half_size = Vec3(0.5 * size[0], 0.5 * size[1], 0.0);
  }
  return shape;
}

/// A height field (`size`, `resolution`, `relief` waves, `seed`): opaque and axis-aligned.
HeightFieldOptions readHeightField(const Config& c, const Material& m, bool has_rpy) {
  if (m.kind != MaterialKind::kOpaque) throw ConfigError(c.where("material") + ": a height field is opaque");
  if (has_rpy) throw ConfigError(c.where("rpy_deg") + ": a height field is axis-aligned");
  HeightFieldOptions hf;
  const std::vector<double> size = c.get<std::vector<double>>("size");
  if (size.size() != 2 || !(size[0] > 0.0) || !(size[1] > 0.0))
    throw ConfigError(c.where("size") + ": expected [size_x, size_y] > 0");
  hf.size_x = size[0];
  hf.size_y = size[1];
  hf.resolution = positive(c, "resolution");
  if (hf.size_x / hf.resolution * hf.size_y / hf.resolution > 2e7)
    throw ConfigError(c.where("resolution") + ": too fine for this size (more than 2e7 cells)");
  const Config relief = c.section("relief");
  const auto amplitude = relief.get<std::vector<double>>("amplitude");
  const auto wavelength = relief.get<std::vector<double>>("wavelength");
  if (amplitude.size() != wavelength.size())
    throw ConfigError(relief.where("wavelength") + ": needs as many entries as amplitude");
  hf.relief.clear();
  for (size_t i = 0; i < amplitude.size(); ++i) {
    if (!(wavelength[i] > 0.0)) throw ConfigError(relief.where("wavelength") + ": must be > 0");
    hf.relief.emplace_back(amplitude[i], wavelength[i]);
  }
  relief.checkAllUsed();
  int seed = 1;
  c.readOptional("seed", seed);
  hf.seed = static_cast<uint64_t>(seed);
  return hf;
}

/// What an object entry describes: a shape, or a height field.
using ObjectGeometry = std::variant<Shape, HeightFieldOptions>;

/// The object's copies (`repeat`) added to the scene at `center` + their offsets, each named
/// name[i] (name alone for one copy), jittered by the placement's seed and with its own texture
/// offset.
void addCopies(Scene& scene, const std::string& name, const Vec3& center, const Placement& placement, const Material& m,
               const ObjectGeometry& geometry) {
  const Texture& texture = scene.texture(m.texture);
  int index = 0;
  for (int row = 0; row < placement.rows; ++row) {
    for (int k = 0; k < placement.count; ++k, ++index) {
      const std::string full = placement.count * placement.rows > 1 ? name + "[" + std::to_string(index) + "]" : name;
      Random jitter(static_cast<uint64_t>(placement.seed), 0x6a177e5ULL, static_cast<uint64_t>(index));
      Vec3 offset = placement.step * k + placement.row_step * row;
      for (int i = 0; i < 3; ++i) offset[i] += placement.jitter[i] * (2.0 * jitter.uniform() - 1.0);
      Random shift(hashString(full.c_str()), 0x7e47ULL);
      Material mi = m;
      mi.u_offset = shift.uniform() * texture.periodU();
      mi.v_offset = shift.uniform() * texture.periodV();
      if (const auto* hf = std::get_if<HeightFieldOptions>(&geometry)) {
        HeightFieldOptions h = *hf;
        h.center = center + offset;
        scene.addHeightField(full, h, mi);
      } else {
        Shape s = std::get<Shape>(geometry);
        s.center = center + offset;
        scene.addShape(full, s, mi);
      }
    }
  }
}

void readObject(Scene& scene, const Config& c, const std::string& name, const std::map<std::string, int>& textures) {
  const std::string type = c.get<std::string>("type");
  Material m = readMaterial(c, textures);
  const Vec3 center = c.get<Vec3>("center");
  const Placement placement = readRepeat(c);

  Vec3 rpy = Vec3::Zero();
  const bool has_rpy = c.readOptional("rpy_deg", rpy);
  const Mat3 rotation = rotationFromRpyDeg(rpy);
  ObjectGeometry geometry;
  Shape solid;
  solid.rotation = rotation;
  if (type == "vegetation") {
    Shape shape = readVegetation(c, &m);
    shape.rotation = rotation;
    geometry = shape;
  } else if (type == "plane") {
    geometry = readPlane(c, has_rpy, rotation);
  } else if (readSolid(c, type, &solid)) {
    geometry = solid;
  } else if (type == "heightfield") {
    geometry = readHeightField(c, m, has_rpy);
  } else {
    throw ConfigError(c.where("type") + ": unknown object type '" + type +
                      "' (known: plane, box, cylinder, sphere, heightfield, vegetation)");
  }
  c.checkAllUsed();
  addCopies(scene, name, center, placement, m, geometry);
}

std::vector<Vec3> readPath(const Config& c) {
  const auto flat = c.get<std::vector<double>>("path");
  if (flat.size() % 3 != 0 || flat.size() < 6)
    throw ConfigError(c.where("path") + ": expected x, y, z triples of at least 2 ground points");
  std::vector<Vec3> points;
  for (size_t i = 0; i < flat.size(); i += 3) points.emplace_back(flat[i], flat[i + 1], flat[i + 2]);
  return points;
}

/// A pedestrian (upright cylinder, 0.5 m across, 1.75 m tall) or a car (box 4.5 x 1.8 x 1.5 m)
/// walking a closed path; `size` overrides the body.
void readMover(Scene& scene, const Config& c, const std::string& name, const std::map<std::string, int>& textures) {
  const std::string type = c.get<std::string>("type");
  const Material m = readMaterial(c, textures);
  Shape body;
  std::vector<double> size;
  const bool has_size = c.readOptional("size", size);
  if (type == "pedestrian") {
    body.type = ShapeType::kCylinder;
    if (!has_size) size = {0.5, 1.75};
    if (size.size() != 2 || !(size[0] > 0.0) || !(size[1] > 0.0))
      throw ConfigError(c.where("size") + ": a pedestrian's size is [diameter, height] > 0");
    body.half_size = Vec3(0.5 * size[0], 0.5 * size[0], 0.5 * size[1]);
  } else if (type == "car") {
    body.type = ShapeType::kBox;
    if (!has_size) size = {4.5, 1.8, 1.5};
    if (size.size() != 3 || !(size[0] > 0.0) || !(size[1] > 0.0) || !(size[2] > 0.0))
      throw ConfigError(c.where("size") + ": a car's size is [length, width, height] > 0");
    body.half_size = 0.5 * Vec3(size[0], size[1], size[2]);
  } else {
    throw ConfigError(c.where("type") + ": unknown mover type '" + type + "' (known: pedestrian, car)");
  }
  MoverPath path;
  path.waypoints = readPath(c);
  c.read("speed", path.speed);
  if (!(path.speed >= 0.0 && path.speed <= 100.0)) throw ConfigError(c.where("speed") + ": must be in [0, 100] m/s");
  c.readOptional("phase", path.phase);
  if (!(path.phase >= 0.0 && path.phase < 1.0)) throw ConfigError(c.where("phase") + ": must be in [0, 1)");
  c.checkAllUsed();
  try {
    scene.addMover(name, MovingObject(body, path), m);
  } catch (const std::invalid_argument& e) {
    throw ConfigError(c.where("path") + ": " + e.what());
  }
}

Vec2 pair(const Config& c, const std::string& key, const std::string& what) {
  const auto v = c.get<std::vector<double>>(key);
  if (v.size() != 2) throw ConfigError(c.where(key) + ": expected " + what);
  return Vec2(v[0], v[1]);
}

GradeProfile readGradeProfile(const Config& c) {
  GradeProfile g;
  c.readOptional("direction_deg", g.direction_deg);
  if (c.has("origin")) g.origin = pair(c, "origin", "[x, y]");
  c.read("stations", g.stations);
  c.read("heights", g.heights);
  c.readOptional("curve_length", g.curve_length);
  c.checkAllUsed();
  if (g.stations.size() < 2) throw ConfigError(c.where("stations") + ": needs at least 2 stations");
  if (g.heights.size() != g.stations.size()) throw ConfigError(c.where("heights") + ": needs one height per station");
  if (!(g.curve_length > 0.0)) throw ConfigError(c.where("curve_length") + ": must be > 0");
  for (size_t i = 1; i < g.stations.size(); ++i)
    if (!(g.stations[i] - g.stations[i - 1] >= g.curve_length))
      throw ConfigError(c.where("stations") + ": stations " + std::to_string(g.stations[i - 1]) + " and " +
                        std::to_string(g.stations[i]) + " are closer than curve_length (" +
                        std::to_string(g.curve_length) + " m): their vertical curves would overlap");
  return g;
}

ReliefWave readReliefWave(const Config& c) {
  ReliefWave w;
  c.read("amplitude", w.amplitude);
  w.wavelength = positive(c, "wavelength");
  c.readOptional("direction_deg", w.direction_deg);
  c.readOptional("phase_deg", w.phase_deg);
  c.checkAllUsed();
  return w;
}

/// `terrain:` the graded ground a car drives on (base, profiles, relief) and its surface: a height
/// field sampled from it on `resolution`, which must keep its triangles within 1 mm of h.
void readTerrain(Scene& scene, const Config& c, const std::map<std::string, int>& textures) {
  TerrainOptions o;
  c.readOptional("base", o.base);
  const Config profiles = c.optionalSection("profiles");
  if (!profiles.isNull())
    for (const std::string& name : profiles.keys()) o.profiles.push_back(readGradeProfile(profiles.section(name)));
  const Config relief = c.optionalSection("relief");
  if (!relief.isNull())
    for (const std::string& name : relief.keys()) o.relief.push_back(readReliefWave(relief.section(name)));
  const Config surface = c.section("surface");
  const Material m = readMaterial(surface, textures);
  if (m.kind != MaterialKind::kOpaque) throw ConfigError(surface.where("material") + ": the terrain is opaque");
  HeightFieldOptions grid;
  grid.center.head<2>() = pair(surface, "center", "[x, y]");
  const Vec2 size = pair(surface, "size", "[size_x, size_y] > 0");
  if (!(size.x() > 0.0) || !(size.y() > 0.0))
    throw ConfigError(surface.where("size") + ": expected [size_x, size_y] > 0");
  grid.size_x = size.x(), grid.size_y = size.y();
  grid.resolution = 0.25;
  surface.readOptional("resolution", grid.resolution);
  if (!(grid.resolution > 0.0)) throw ConfigError(surface.where("resolution") + ": must be > 0");
  if (grid.size_x / grid.resolution * grid.size_y / grid.resolution > 2e7)
    throw ConfigError(surface.where("resolution") + ": too fine for this size (more than 2e7 cells)");
  surface.checkAllUsed();
  c.checkAllUsed();
  auto terrain = std::make_shared<const Terrain>(o);
  // linear interpolation on a right triangle with legs r departs from h by at most M r^2 / 4
  // (M: the largest curvature; the triangle's smallest enclosing circle has radius r / sqrt 2)
  const double departure = terrain->maxCurvature() * grid.resolution * grid.resolution / 4.0;
  if (departure > 1e-3)
    throw ConfigError(surface.where("resolution") + ": the triangles would depart from the terrain by up to " +
                      std::to_string(departure * 1e3) + " mm (curvature up to " +
                      std::to_string(terrain->maxCurvature()) + " /m); take at most " +
                      std::to_string(std::sqrt(4e-3 / terrain->maxCurvature())) + " m");
  Material mi = m;
  Random shift(hashString("terrain"), 0x7e47ULL);
  mi.u_offset = shift.uniform() * scene.texture(m.texture).periodU();
  mi.v_offset = shift.uniform() * scene.texture(m.texture).periodV();
  const auto height = [t = terrain.get()](double x, double y) { return t->height(x, y); };
  scene.addHeightField("terrain", std::make_unique<HeightField>(grid, height), mi);
  scene.terrain = std::move(terrain);
}

}  // namespace

std::unique_ptr<Scene> readScene(const Config& c) {
  auto scene = std::make_unique<Scene>();
  if (c.has("sky")) {
    const Config sky = c.section("sky");
    scene->sky.horizon = colour(sky, "horizon");
    scene->sky.zenith = colour(sky, "zenith");
    sky.checkAllUsed();
  }
  if (c.has("light")) {
    const Config light = c.section("light");
    const Vec3 d = light.get<Vec3>("direction");
    if (d.norm() < 1e-9) throw ConfigError(light.where("direction") + ": must not be zero");
    scene->lighting.direction = d.normalized();
    light.read("ambient", scene->lighting.ambient);
    light.read("diffuse", scene->lighting.diffuse);
    light.checkAllUsed();
  }
  std::map<std::string, int> textures;
  const Config tex = c.section("textures");
  for (const std::string& name : tex.keys()) {
    textures[name] = scene->addTexture(readTexture(tex.section(name), hashString(name.c_str())));
  }
  const Config objects = c.section("objects");
  if (objects.keys().empty()) throw ConfigError(c.where("objects") + ": the scene has no objects");
  for (const std::string& name : objects.keys()) readObject(*scene, objects.section(name), name, textures);
  if (c.has("terrain")) readTerrain(*scene, c.section("terrain"), textures);
  if (c.has("movers")) {
    const Config movers = c.section("movers");
    for (const std::string& name : movers.keys()) readMover(*scene, movers.section(name), name, textures);
  }
  c.checkAllUsed();
  scene->build();
  return scene;
}

}  // namespace livo::sim
