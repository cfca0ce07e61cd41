#include "livo/sim/camera_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace livo::sim {

CameraRenderer::CameraRenderer(const CameraRig& rig, const CameraEffects& effects)
    : rig_(rig), effects_(effects), camera_(rig) {
  const size_t n = static_cast<size_t>(rig.width) * rig.height;
  rays_.resize(n);
  vignette_.resize(n);
  const double half_diag2 =
      0.25 * (static_cast<double>(rig.width) * rig.width + static_cast<double>(rig.height) * rig.height);
  for (int j = 0; j < rig.height; ++j) {
    for (int i = 0; i < rig.width; ++i) {
      const size_t k = static_cast<size_t>(j) * rig.width + i;
      rays_[k] = camera_.pixelRay(Eigen::Vector2d(i, j)).cast<float>();
      const double dx = i - rig.cx, dy = j - rig.cy;
      vignette_[k] = static_cast<float>(1.0 - effects.vignetting * std::min(1.0, (dx * dx + dy * dy) / half_diag2));
    }
  }
  buildTiles();
}

void CameraRenderer::buildTiles() {
  // a rolling shutter sees each row from its own pose: one-row tiles
  const bool rolling = effects_.rolling_shutter_s > 0.0;
  const int tile_w = rolling ? 32 : 16, tile_h = rolling ? 1 : 16;
  const int w = rig_.width, h = rig_.height;
  for (int y0 = 0; y0 < h; y0 += tile_h) {
    for (int x0 = 0; x0 < w; x0 += tile_w) {
      Tile t{x0, y0, std::min(w, x0 + tile_w), std::min(h, y0 + tile_h), {}, true};
      // bounding cone of the tile's rays: axis = mean ray, half-angle = largest deviation
      Vec3 axis = Vec3::Zero();
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x) axis += rays_[static_cast<size_t>(y) * w + x].cast<double>();
      axis.normalize();
      double cos_min = 1.0;
      for (int y = t.y0; y < t.y1; ++y)
        for (int x = t.x0; x < t.x1; ++x)
          cos_min = std::min(cos_min, axis.dot(rays_[static_cast<size_t>(y) * w + x].cast<double>().normalized()));
      const double half_angle = std::acos(std::clamp(cos_min, -1.0, 1.0)) + 1e-4;
      if (half_angle > 1.4) {
        t.culled = false;
      } else {
        // square pyramid tangent to the cone: n = sin(a) axis + cos(a) (+-u, +-v)
        const Vec3 u = axis.unitOrthogonal(), v = axis.cross(u);
        const double sa = std::sin(half_angle), ca = std::cos(half_angle);
        t.normals[0] = sa * axis + ca * u;
        t.normals[1] = sa * axis - ca * u;
        t.normals[2] = sa * axis + ca * v;
        t.normals[3] = sa * axis - ca * v;
      }
      tiles_.push_back(t);
    }
  }
}

double CameraRenderer::exposureAt(double t) const {
  const double w = 2.0 * M_PI / effects_.exposure_period_s;
  const double drift = 0.6 * std::sin(w * t) + 0.4 * std::sin(2.71 * w * t + 1.3);
  return effects_.exposure_time * (1.0 + effects_.exposure_variation * drift);
}

double CameraRenderer::illuminationAt(double t) const {
  const double w = 2.0 * M_PI / effects_.exposure_period_s;
  const double drift = 0.6 * std::sin(w * t) + 0.4 * std::sin(2.71 * w * t + 1.3);
  return 1.0 + effects_.exposure_variation * drift;
}

double CameraRenderer::rowTimeOffset(int y) const {
  if (effects_.rolling_shutter_s == 0.0) return 0.0;
  const double line_delay = effects_.rolling_shutter_s / rig_.height;
  return line_delay * (y - 0.5 * (rig_.height - 1));
}

Eigen::Vector3f CameraRenderer::shade(const Scene& scene, const Ray& ray, const RayHit& hit) const {
  if (!hit.valid()) {
    const float up = static_cast<float>(std::max(0.0, ray.direction.z()));
    return scene.sky.horizon.cast<float>() + up * (scene.sky.zenith - scene.sky.horizon).cast<float>();
  }
  const SurfacePoint sp = scene.surface(ray, hit);
  const double cos_view = std::max(std::abs(sp.normal.dot(ray.direction)), 0.15);
  const double footprint = hit.t / rig_.fx / cos_view;  // pixel size on the surface
  const Material& m = scene.material(hit.object);
  const double light =
      scene.lighting.ambient + scene.lighting.diffuse * std::max(0.0, -sp.normal.dot(scene.lighting.direction));
  const Texture& texture = scene.texture(m.texture);
  if (!rig_.color)
    return Eigen::Vector3f::Constant(texture.sampleLuminance(sp.u, sp.v, footprint) * static_cast<float>(light));
  return texture.sample(sp.u, sp.v, footprint) * static_cast<float>(light);
}

Eigen::Vector3f CameraRenderer::shadeThroughGlass(const Scene& scene, const Ray& ray, RayHit hit,
                                                  const CastContext& context) const {
  constexpr int kMaxGlassLayers = 4;
  if (!hit.valid() || scene.material(hit.object).kind != MaterialKind::kGlass) return shade(scene, ray, hit);
  Eigen::Vector3f colour = Eigen::Vector3f::Zero();
  float share = 1.0f;
  for (int layer = 0; layer < kMaxGlassLayers && hit.valid(); ++layer) {
    const Material& m = scene.material(hit.object);
    if (m.kind != MaterialKind::kGlass) break;
    const float transmission = static_cast<float>(m.glass_transmission);
    colour += share * (1.0f - transmission) * shade(scene, ray, hit);
    share *= transmission;
    hit = scene.cast(ray, context, hit.t + 1e-6);
  }
  return colour + share * shade(scene, ray, hit);
}

void CameraRenderer::accumulate(const Scene& scene, const PoseAt& T_W_C_at, double t, uint64_t key, float weight,
                                std::vector<float>* rgb, std::vector<float>* z_depth) const {
  Mat3 R = Mat3::Identity();
  Ray ray;
  double pose_time = std::numeric_limits<double>::quiet_NaN();
  Scene::Candidates candidates;
  for (const Tile& tile : tiles_) {
    const double row_time = t + rowTimeOffset(tile.y0);  // one-row tiles under a rolling shutter
    if (!(row_time == pose_time)) {
      const Pose3 T_W_C = T_W_C_at(row_time);
      R = T_W_C.linear();
      ray.origin = T_W_C.translation();
      pose_time = row_time;
    }
    CastContext context = CastContext::camera(row_time, 0);
    if (tile.culled) {
      const Vec3 normals[4] = {R * tile.normals[0], R * tile.normals[1], R * tile.normals[2], R * tile.normals[3]};
      scene.cullPyramid(ray.origin, normals, &candidates);
    }
    int hint = -1;
    for (int y = tile.y0; y < tile.y1; ++y) {
      for (int x = tile.x0; x < tile.x1; ++x) {
        const size_t k = static_cast<size_t>(y) * rig_.width + x;
        ray.direction = R * rays_[k].cast<double>();
        context.key = mix64(key ^ (k * 0x9e3779b97f4a7c15ULL));
        const RayHit hit = tile.culled ? scene.castAmong(ray, candidates, hint, context) : scene.cast(ray, context);
        hint = hit.object;
        if (z_depth) {
          // a depth camera's stereo matching fails on glass: no depth there
          const bool depth = hit.valid() && scene.material(hit.object).kind != MaterialKind::kGlass;
          (*z_depth)[k] = depth ? static_cast<float>(hit.t) * rays_[k].z() : 0.0f;
        }
        if (!rgb) continue;
        const Eigen::Vector3f c = shadeThroughGlass(scene, ray, hit, context);
        float* px = &(*rgb)[3 * k];
        px[0] += weight * c[0];
        px[1] += weight * c[1];
        px[2] += weight * c[2];
      }
    }
  }
}

CameraImage CameraRenderer::render(const Scene& scene, const BodyTrajectory& trajectory, double t_mid, int64_t utime,
                                   Random rng) const {
  return render(scene, trajectory, t_mid, utime, rng, ExposureSetting{exposureAt(t_mid), 1.0});
}

CameraImage CameraRenderer::render(const Scene& scene, const BodyTrajectory& trajectory, double t_mid, int64_t utime,
                                   Random rng, const ExposureSetting& setting, std::vector<float>* z_depth) const {
  const double exposure = setting.exposure;
  const int samples = std::max(1, effects_.motion_blur_samples);
  const uint64_t key = rng.key();  // seeds the per-pixel interactions (vegetation depth)
  auto T_W_C_at = [&](double t) { return Pose3(trajectory.at(t).T_W_I * rig_.T_I_C); };
  std::vector<float> rgb(rays_.size() * 3, 0.0f);
  if (z_depth) z_depth->assign(rays_.size(), 0.0f);
  // an odd number of sub-frames has one at t_mid, whose rays give the depth; else a pass of its own
  const int depth_sample = z_depth && samples % 2 == 1 ? samples / 2 : -1;
  for (int s = 0; s < samples; ++s) {
    const double t = samples == 1 ? t_mid : t_mid + exposure * ((s + 0.5) / samples - 0.5);
    accumulate(scene, T_W_C_at, t, mix64(key + static_cast<uint64_t>(s)), 1.0f / samples, &rgb,
               s == depth_sample ? z_depth : nullptr);
  }
  if (z_depth && depth_sample < 0)
    accumulate(scene, T_W_C_at, t_mid, mix64(key + static_cast<uint64_t>(samples)), 0.0f, nullptr, z_depth);
  CameraImage img;
  img.utime = utime;
  img.log_utime = utime;
  img.width = rig_.width;
  img.height = rig_.height;
  img.color = rig_.color;
  img.exposure_time = static_cast<float>(exposure);
  const int channels = rig_.color ? 3 : 1;
  img.data.resize(rays_.size() * channels);
  const double illumination = effects_.auto_exposure.enabled ? illuminationAt(t_mid) : 1.0;
  const double gain = 255.0 * effects_.brightness * exposure / effects_.exposure_time * setting.gain * illumination;
  auto quantize = [&](double v) {
    v += effects_.noise_std * rng.normal();
    return static_cast<uint8_t>(std::clamp(std::lround(v), 0L, 255L));
  };
  for (size_t k = 0; k < rays_.size(); ++k) {
    const double g = gain * vignette_[k];
    const float* px = &rgb[3 * k];
    if (rig_.color) {
      for (int c = 0; c < 3; ++c) img.data[3 * k + c] = quantize(g * px[c]);
    } else {
      img.data[k] = quantize(g * (0.299 * px[0] + 0.587 * px[1] + 0.114 * px[2]));
    }
  }
  return img;
}

}  // namespace livo::sim
