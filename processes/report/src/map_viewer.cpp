#include "livo/report/map_viewer.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <nlohmann/json.hpp>

#include "livo/report/base64.hpp"
#include "livo/report/map_views.hpp"
#include "livo/text_format.hpp"
#include "livo/voxel_downsample.hpp"

namespace livo::report {

namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the page reads the float32 arrays as little-endian");

constexpr size_t kMaxPathPositions = 50'000;
constexpr double kPathSpacing_m = 0.05;

// The script that draws the scene (three.js r111 API: BufferGeometry.setAttribute,
// THREE.VertexColors). Runs once the page has reached it; draws on demand, not in a loop.
const char* const kViewerScript = R"JS(
(function () {
  'use strict';
  var status = document.getElementById('viewer-status');
  function say(text, state) { status.textContent = text; status.setAttribute('data-state', state); }
  function bytes(id) {
    var s = atob(document.getElementById(id).textContent.replace(/\s+/g, ''));
    var b = new Uint8Array(s.length);
    for (var i = 0; i < s.length; ++i) b[i] = s.charCodeAt(i);
    return b;
  }
  if (typeof THREE === 'undefined' || typeof THREE.OrbitControls === 'undefined') {
    say('No 3D view: three.js is not in this page (see the note above).', 'no-three');
    return;
  }
  var probe = document.createElement('canvas');
  if (!window.WebGLRenderingContext || !(probe.getContext('webgl') || probe.getContext('experimental-webgl'))) {
    say('No 3D view: this browser cannot draw WebGL here. The pictures below show the map.', 'no-webgl');
    return;
  }
  var meta = JSON.parse(document.getElementById('livo-scene').textContent);
  var container = document.getElementById('viewer');
  var renderer = new THREE.WebGLRenderer({antialias: true});
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  renderer.localClippingEnabled = true;
  container.appendChild(renderer.domElement);
  var scene = new THREE.Scene();
  scene.background = new THREE.Color(0x1d1f23);

  var cut = new THREE.Plane(new THREE.Vector3(0, 0, -1), meta.cut_z);  // keeps z <= cut_z
  var pointMaterial = new THREE.PointsMaterial({size: meta.point_size, vertexColors: THREE.VertexColors,
                                                clippingPlanes: [cut]});
  if (meta.points > 0) {
    var cloud = new THREE.BufferGeometry();
    cloud.setAttribute('position', new THREE.BufferAttribute(new Float32Array(bytes('livo-positions').buffer), 3));
    cloud.setAttribute('color', new THREE.BufferAttribute(bytes('livo-colours'), 3, true));
    scene.add(new THREE.Points(cloud, pointMaterial));
  }
  var pathGroup = new THREE.Group();
  if (meta.path_pieces.length > 0) {
    var path = new Float32Array(bytes('livo-path').buffer);
    var lineMaterial = new THREE.LineBasicMaterial({color: 0x00e5ff});
    var start = 0;
    meta.path_pieces.forEach(function (n) {
      var piece = new THREE.BufferGeometry();
      piece.setAttribute('position', new THREE.BufferAttribute(path.subarray(3 * start, 3 * (start + n)), 3));
      pathGroup.add(new THREE.Line(piece, lineMaterial));
      start += n;
    });
    var ends = new THREE.BufferGeometry();
    ends.setAttribute('position', new THREE.BufferAttribute(new Float32Array(
        [path[0], path[1], path[2], path[3 * start - 3], path[3 * start - 2], path[3 * start - 1]]), 3));
    ends.setAttribute('color', new THREE.BufferAttribute(new Float32Array([0.24, 0.71, 0.24, 0.86, 0.16, 0.16]), 3));
    pathGroup.add(new THREE.Points(ends, new THREE.PointsMaterial({size: 10, sizeAttenuation: false,
                                                                   vertexColors: THREE.VertexColors})));
    scene.add(pathGroup);
  }

  var reach = Math.max(1, meta.radius);
  var camera = new THREE.PerspectiveCamera(meta.fov, 1, reach / 2000, reach * 40);
  camera.up.set(0, 0, 1);
  var controls = new THREE.OrbitControls(camera, renderer.domElement);
  function render() { renderer.render(scene, camera); }
  // The start view: from the direction of meta.camera, as near as keeps the framed box's eight
  // corners inside the canvas, whatever its shape.
  function home() {
    var target = new THREE.Vector3().fromArray(meta.target);
    var back = new THREE.Vector3().fromArray(meta.camera).sub(target).normalize();
    var right = new THREE.Vector3(0, 0, 1).cross(back).normalize();
    var up = new THREE.Vector3().crossVectors(back, right);
    var tanV = Math.tan(camera.fov * Math.PI / 360), tanH = tanV * camera.aspect;
    var distance = 0;
    for (var k = 0; k < 8; ++k) {
      var c = new THREE.Vector3((k & 1) ? meta.box_max[0] : meta.box_min[0], (k & 2) ? meta.box_max[1] : meta.box_min[1],
                                (k & 4) ? meta.box_max[2] : meta.box_min[2]).sub(target);
      distance = Math.max(distance, c.dot(back) + Math.abs(c.dot(right)) / tanH, c.dot(back) + Math.abs(c.dot(up)) / tanV);
    }
    camera.position.copy(target).addScaledVector(back, 1.1 * distance);
    controls.target.copy(target);
    controls.update();
  }
  function resize() {
    var w = Math.max(1, container.clientWidth), h = Math.max(1, container.clientHeight);
    renderer.setSize(w, h);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
  }
  controls.addEventListener('change', render);
  window.addEventListener('resize', function () { resize(); render(); });

  var cutInput = document.getElementById('viewer-cut'), cutValue = document.getElementById('viewer-cut-value');
  function showCut() {
    cut.constant = parseFloat(cutInput.value);
    cutValue.textContent = (cut.constant + meta.origin[2]).toFixed(1) + ' m';
  }
  cutInput.addEventListener('input', function () { showCut(); render(); });
  document.getElementById('viewer-size').addEventListener('input', function (e) {
    pointMaterial.size = meta.point_size * parseFloat(e.target.value);
    render();
  });
  document.getElementById('viewer-path').addEventListener('change', function (e) {
    pathGroup.visible = e.target.checked;
    render();
  });
  document.getElementById('viewer-home').addEventListener('click', function () { home(); render(); });

  showCut();
  resize();
  home();
  render();
  var r = renderer.domElement.getBoundingClientRect();
  status.setAttribute('data-canvas-rect', [r.left + window.pageXOffset, r.top + window.pageYOffset, r.width, r.height]
                                              .map(Math.round).join(','));
  say('Drawn: ' + meta.points + ' points' + (meta.path_pieces.length ? ' and the trajectory' : '') +
      '. Drag to turn, right-drag to pan, wheel to zoom.', 'drawn');
})();
)JS";

// The map's points kept for the page and the grid that kept them.
struct KeptPoints {
  std::vector<size_t> indices;
  double voxel_m = 0.0;  // 0: every finite point
  double point_size_m = 0.0;
};

// The first point of each voxel of the finest grid that keeps at most max_points, or every
// finite point when there are no more than that.
KeptPoints keptPoints(const std::vector<Vec3>& xyz, const std::vector<size_t>& finite, const ViewerOptions& options) {
  KeptPoints out;
  out.indices = finite;
  out.point_size_m = options.point_size_m;
  std::vector<size_t>& kept = out.indices;
  if (kept.size() <= options.max_points) return out;
  // grids point_size_m x 1.25^k; the search starts where a surface sampled at point_size_m
  // would fit and walks to the smallest k that fits
  const auto grid = [&](int k) { return options.point_size_m * std::pow(1.25, k); };
  const double ratio = static_cast<double>(kept.size()) / static_cast<double>(std::max<size_t>(options.max_points, 1));
  int k = static_cast<int>(std::lround(std::log(std::max(1.0, 0.8 * std::sqrt(ratio))) / std::log(1.25)));
  kept = firstPointPerVoxel(xyz, finite, grid(k));
  if (kept.size() <= options.max_points) {
    while (k > 0) {
      std::vector<size_t> finer = firstPointPerVoxel(xyz, finite, grid(k - 1));
      if (finer.size() > options.max_points) break;
      kept.swap(finer);
      --k;
    }
  } else {
    while (kept.size() > options.max_points) kept = firstPointPerVoxel(xyz, finite, grid(++k));
  }
  out.voxel_m = grid(k);
  out.point_size_m = std::max(options.point_size_m, out.voxel_m);
  return out;
}

// The median height of the trajectory's positions (at least one).
double medianHeight(const std::vector<Vec3>& path_xyz) {
  std::vector<double> z;
  for (const Vec3& p : path_xyz) z.push_back(p.z());
  std::nth_element(z.begin(), z.begin() + static_cast<std::ptrdiff_t>(z.size() / 2), z.end());
  return z[z.size() / 2];
}

// The trajectory as the page draws it.
struct ScenePath {
  std::vector<float> path;            // x y z, relative to the scene's origin
  std::vector<uint32_t> path_pieces;  // positions per piece
};

// The trajectory's positions relative to `origin`, thinned to 5 cm apart, in pieces.
ScenePath scenePath(const Trajectory& trajectory, const std::vector<double>& reset_stamps, const Vec3& origin) {
  ScenePath out;
  for (const auto& [begin, end] : pathPieces(trajectory, reset_stamps)) {
    uint32_t n = 0;
    Vec3 last = Vec3::Constant(INFINITY);
    for (size_t i = begin; i < end; ++i) {
      const Vec3 p = trajectory[i].pose.translation();
      if (i + 1 < end && (p - last).norm() < kPathSpacing_m) continue;
      last = p;
      for (int a = 0; a < 3; ++a) out.path.push_back(static_cast<float>(p[a] - origin[a]));
      ++n;
    }
    out.path_pieces.push_back(n);
  }
  return out;
}

// A very long run: every k-th position of each piece (and its last), at most kMaxPathPositions.
ScenePath thinnedLongPath(ScenePath in) {
  if (in.path.size() / 3 <= kMaxPathPositions) return in;
  const size_t k = (in.path.size() / 3 + kMaxPathPositions - 1) / kMaxPathPositions;
  ScenePath out;
  size_t start = 0;
  for (uint32_t n : in.path_pieces) {
    uint32_t m = 0;
    for (size_t j = 0; j < n; ++j)
      if (j % k == 0 || j + 1 == n) {
        for (int a = 0; a < 3; ++a) out.path.push_back(in.path[3 * (start + j) + a]);
        ++m;
      }
    out.path_pieces.push_back(m);
    start += n;
  }
  return out;
}

// The scene's start view (obliqueView of what is framed, with the trajectory), its height range
// (of everything) and its height cut, relative to its origin.
ViewerScene withStartView(ViewerScene s, const std::vector<Vec3>& framed, const Box3& points_box,
                          const Trajectory& trajectory, double cut_z) {
  const Box3 box = withTrajectory(percentileBox(framed, 0.005, 0.995), trajectory);
  const PerspectiveView view = obliqueView(box, majorHorizontalAxis(framed));
  s.camera = view.position - s.origin;
  s.target = box.centre() - s.origin;
  s.box_min = box.min - s.origin;
  s.box_max = box.max - s.origin;
  s.fov_deg = 55.0;
  const Box3 everything = withTrajectory(points_box, trajectory);
  s.z_min = everything.min.z() - s.origin.z();
  s.z_max = everything.max.z() - s.origin.z();
  s.cut_z = std::min(cut_z - s.origin.z(), s.z_max);
  return s;
}

}  // namespace

ViewerScene viewerScene(const ColouredPoints& map, const Trajectory& trajectory,
                        const std::vector<double>& reset_stamps, const ViewerOptions& options) {
  ViewerScene s;
  s.map_points = map.size();
  std::vector<Vec3> xyz;
  std::vector<size_t> finite;
  xyz.reserve(map.size());
  for (size_t i = 0; i < map.size(); ++i) {
    xyz.push_back(map.position[i].cast<double>());
    if (xyz.back().allFinite()) finite.push_back(i);
  }
  std::vector<Vec3> path_xyz;
  for (const StampedPose& p : trajectory)
    if (p.pose.translation().allFinite()) path_xyz.push_back(p.pose.translation());
  if (finite.empty() && path_xyz.empty()) return s;

  const KeptPoints kept = keptPoints(xyz, finite, options);
  s.voxel_m = kept.voxel_m;
  s.point_size_m = kept.point_size_m;
  std::vector<Vec3> box_points;
  for (size_t i : kept.indices) box_points.push_back(xyz[i]);
  const Box3 all = percentileBox(box_points.empty() ? path_xyz : box_points, 0.0, 1.0);
  s.origin = all.centre().array().round().matrix();
  // no trajectory to cut above: nothing cut at the start
  const double cut_z = path_xyz.empty() ? INFINITY : medianHeight(path_xyz) + options.cut_above_m;

  s.positions.reserve(3 * kept.indices.size());
  s.colours.reserve(3 * kept.indices.size());
  std::vector<Vec3> below;  // what the start view frames: the points under the cut
  for (size_t i : kept.indices) {
    const Vec3 p = xyz[i] - s.origin;
    for (int a = 0; a < 3; ++a) s.positions.push_back(static_cast<float>(p[a]));
    for (int c = 0; c < 3; ++c) s.colours.push_back(map.rgb[i][c]);
    if (xyz[i].z() <= cut_z) below.push_back(xyz[i]);
  }

  ScenePath path = thinnedLongPath(scenePath(trajectory, reset_stamps, s.origin));
  s.path = std::move(path.path);
  s.path_pieces = std::move(path.path_pieces);
  const std::vector<Vec3>& framed = below.empty() ? (box_points.empty() ? path_xyz : box_points) : below;
  return withStartView(std::move(s), framed, all, trajectory, cut_z);
}

std::string viewerSection(const ViewerScene& scene, const std::string& description) {
  const double step = std::max(0.05, (scene.z_max - scene.z_min) / 200.0);
  const double radius = std::max({(scene.camera - scene.target).norm(), scene.z_max - scene.z_min, 1.0});
  nlohmann::json meta = {{"points", scene.size()},
                         {"point_size", scene.point_size_m},
                         {"origin", {scene.origin.x(), scene.origin.y(), scene.origin.z()}},
                         {"camera", {scene.camera.x(), scene.camera.y(), scene.camera.z()}},
                         {"target", {scene.target.x(), scene.target.y(), scene.target.z()}},
                         {"box_min", {scene.box_min.x(), scene.box_min.y(), scene.box_min.z()}},
                         {"box_max", {scene.box_max.x(), scene.box_max.y(), scene.box_max.z()}},
                         {"fov", scene.fov_deg},
                         {"radius", radius},
                         {"cut_z", scene.cut_z},
                         {"path_pieces", scene.path_pieces}};
  std::string out;
  out += "<section id=\"map-3d\">\n<h2 id=\"map-in-3d\">Map in 3D</h2>\n";
  out += "<p>" + description + "</p>\n";
  out += "<div id=\"viewer\" class=\"viewer\"></div>\n";
  out += "<div class=\"viewer-controls\">\n";
  out += "<label>cut above <input type=\"range\" id=\"viewer-cut\" min=\"" + formatFixed(scene.z_min, 2) + "\" max=\"" +
         formatFixed(scene.z_max + step, 2) + "\" step=\"" + formatFixed(step, 3) + "\" value=\"" +
         formatFixed(scene.cut_z, 2) + "\"> <span id=\"viewer-cut-value\"></span></label>\n";
  out +=
      "<label>point size <input type=\"range\" id=\"viewer-size\" min=\"0.25\" max=\"4\" step=\"0.25\" "
      "value=\"1\"></label>\n";
  out += "<label><input type=\"checkbox\" id=\"viewer-path\" checked> trajectory</label>\n";
  out += "<button type=\"button\" id=\"viewer-home\">start view</button>\n</div>\n";
  out += "<p id=\"viewer-status\" data-state=\"loading\">The 3D view needs JavaScript and WebGL.</p>\n";
  std::string json = meta.dump();
  for (size_t at = json.find("</"); at != std::string::npos; at = json.find("</", at)) json.replace(at, 2, "<\\/");
  out += "<script type=\"application/json\" id=\"livo-scene\">" + json + "</script>\n";
  out += "<script type=\"application/x-base64\" id=\"livo-positions\">" +
         base64Encode(scene.positions.data(), scene.positions.size() * sizeof(float)) + "</script>\n";
  out += "<script type=\"application/x-base64\" id=\"livo-colours\">" +
         base64Encode(scene.colours.data(), scene.colours.size()) + "</script>\n";
  out += "<script type=\"application/x-base64\" id=\"livo-path\">" +
         base64Encode(scene.path.data(), scene.path.size() * sizeof(float)) + "</script>\n";
  out += "<script>" + std::string(kViewerScript) + "</script>\n</section>\n";
  return out;
}

}  // namespace livo::report
