#include "livo/lio_graph/plane_extraction.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "livo/kdtree.hpp"

namespace livo::lio_graph {

namespace {

/// Local normals from each point's nearest neighbours (unit; zero where they are degenerate).
std::vector<Vec3> localNormals(const std::vector<Vec3>& points, int k) {
  std::vector<Vec3> normals(points.size(), Vec3::Zero());
  if (points.size() < 3) return normals;
  const KdTree<Vec3> tree(points);
  const size_t kk = std::min<size_t>(static_cast<size_t>(std::max(3, k)), points.size());
  std::vector<size_t> idx(kk);
  std::vector<double> d2(kk);
  std::vector<Vec3> nb(kk);
  for (size_t i = 0; i < points.size(); ++i) {
    const size_t n = tree.knn(points[i], kk, idx.data(), d2.data());
    for (size_t j = 0; j < n; ++j) nb[j] = points[idx[j]];
    PlaneFit fit;
    if (n >= 3 && fitPlane(nb.data(), static_cast<int>(n), &fit) && fit.spread[1] > 1e-3 * fit.spread[2])
      normals[i] = fit.plane.normal;
  }
  return normals;
}

/// The plane through three points; false if they are (nearly) collinear.
bool planeThrough(const Vec3& a, const Vec3& b, const Vec3& c, Plane* out) {
  const Vec3 n = (b - a).cross(c - a);
  const double norm = n.norm();
  if (!(norm > 1e-9 * (b - a).squaredNorm() + 1e-12)) return false;
  out->normal = n / norm;
  out->offset = -out->normal.dot(a);
  return true;
}

Vec3 centroidOf(const std::vector<Vec3>& points, const std::vector<int>& ids) {
  Vec3 c = Vec3::Zero();
  for (int i : ids) c += points[i];
  return ids.empty() ? c : Vec3(c / static_cast<double>(ids.size()));
}

}  // namespace

double adaptiveThreshold(const Vec3& centroid, const PlaneExtractionOptions& o) {
  return std::clamp(o.threshold_base + o.threshold_per_metre * centroid.norm(), o.threshold_min, o.threshold_max);
}

std::vector<ExtractedPlane> extractPlanes(const std::vector<Vec3>& points, const PlaneExtractionOptions& o,
                                          PlaneExtractionStats* stats) {
  PlaneExtractionStats local;
  PlaneExtractionStats& st = stats ? *stats : local;
  st = PlaneExtractionStats{};
  std::vector<ExtractedPlane> planes;
  std::vector<int> remaining;
  remaining.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i)
    if (points[i].allFinite()) remaining.push_back(static_cast<int>(i));
  if (static_cast<int>(remaining.size()) < std::max(3, o.min_inliers)) return planes;

  const std::vector<Vec3> normals = localNormals(points, o.normal_neighbours);
  const double cos_consistent = std::cos(o.normal_max_angle_deg * M_PI / 180.0);
  const Vec3 up = o.up.normalized();
  std::mt19937 rng(o.seed);

  for (int attempt = 0; attempt < o.max_planes; ++attempt) {
    if (static_cast<int>(remaining.size()) < std::max(3, o.min_inliers)) break;
    const double threshold = adaptiveThreshold(centroidOf(points, remaining), o);

    // hypotheses from three random remaining points, scored on a strided sample
    const size_t stride = std::max<size_t>(1, remaining.size() / static_cast<size_t>(std::max(1, o.score_sample)));
    std::uniform_int_distribution<size_t> pick(0, remaining.size() - 1);
    Plane best;
    int best_score = 0;
    for (int it = 0; it < o.ransac_iterations; ++it) {
      Plane h;
      if (!planeThrough(points[remaining[pick(rng)]], points[remaining[pick(rng)]], points[remaining[pick(rng)]], &h))
        continue;
      int score = 0;
      for (size_t j = 0; j < remaining.size(); j += stride) score += std::abs(h.distance(points[remaining[j]])) < threshold;
      if (score > best_score) best_score = score, best = h;
    }
    if (best_score < 3) break;

    // every remaining point within the threshold, refitted by least squares, then counted again
    auto inliersOf = [&](const Plane& p) {
      std::vector<int> in;
      for (int i : remaining)
        if (std::abs(p.distance(points[i])) < threshold) in.push_back(i);
      return in;
    };
    std::vector<int> in = inliersOf(best);
    std::vector<Vec3> buf;
    auto refit = [&](const std::vector<int>& ids, Plane* p) {
      buf.clear();
      for (int i : ids) buf.push_back(points[i]);
      PlaneFit fit;
      if (buf.size() < 3 || !fitPlane(buf.data(), static_cast<int>(buf.size()), &fit)) return false;
      *p = fit.plane;
      return true;
    };
    Plane plane = best;
    if (refit(in, &plane)) in = inliersOf(plane);

    // normal consistency: inliers whose local normal agrees with the plane's
    std::vector<int> consistent;
    for (int i : in)
      if (std::abs(normals[i].dot(plane.normal)) >= cos_consistent) consistent.push_back(i);
    auto removeFromRemaining = [&](const std::vector<int>& ids) {
      std::vector<char> gone(points.size(), 0);
      for (int i : ids) gone[i] = 1;
      remaining.erase(std::remove_if(remaining.begin(), remaining.end(), [&](int i) { return gone[i] != 0; }),
                      remaining.end());
    };
    if (static_cast<int>(consistent.size()) < o.min_inliers ||
        static_cast<double>(consistent.size()) < o.min_consistent_fraction * static_cast<double>(in.size())) {
      ++st.refused_inconsistent;
      removeFromRemaining(in);  // explained by no plane: not tried again
      continue;
    }
    refit(consistent, &plane);
    removeFromRemaining(consistent);

    ExtractedPlane e;
    if (plane.offset < 0.0) plane.normal = -plane.normal, plane.offset = -plane.offset;
    e.plane = plane;
    e.centroid = centroidOf(points, consistent);
    e.threshold = threshold;
    double sum = 0.0;
    for (int i : consistent) sum += std::abs(plane.distance(points[i]));
    e.quality = sum / static_cast<double>(consistent.size());
    if (e.quality > o.max_quality_ratio * threshold) {
      ++st.refused_quality;
      continue;
    }
    // ground-direction constraint: a nearly horizontal plane below the sensor must be level
    const double tilt_deg = std::acos(std::min(1.0, std::abs(plane.normal.dot(up)))) * 180.0 / M_PI;
    const bool below = e.centroid.dot(up) < -o.ground_below;
    if (below && tilt_deg <= o.ground_candidate_deg) {
      if (tilt_deg > o.ground_max_tilt_deg) {
        ++st.refused_ground_tilt;
        continue;
      }
      e.ground = true;
    }
    e.inliers = std::move(consistent);
    planes.push_back(std::move(e));
    ++st.accepted;
  }
  return planes;
}

}  // namespace livo::lio_graph
