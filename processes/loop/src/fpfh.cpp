#include "livo/loop/fpfh.hpp"

#include <algorithm>
#include <cmath>

namespace livo::loop {

namespace {
constexpr int kBins = 11;

// atan2 to within 1e-5 rad (a minimax polynomial for atan on [0, 1] and the octant symmetries):
// enough to bin angles into 11 bins, and about ten times cheaper than std::atan2, which took a
// quarter of the feature time.
double fastAtan2(double y, double x) {
  const double ax = std::abs(x), ay = std::abs(y);
  const double mx = std::max(ax, ay);
  if (mx == 0.0) return 0.0;
  const double a = std::min(ax, ay) / mx, s = a * a;
  double r = ((-0.0464964749 * s + 0.15931422) * s - 0.327622764) * s * a + a;
  if (ay > ax) r = M_PI_2 - r;
  if (x < 0.0) r = M_PI - r;
  return y < 0.0 ? -r : r;
}

int bin(double value, double lo, double hi) {
  const int b = static_cast<int>(std::floor((value - lo) / (hi - lo) * kBins));
  return std::min(std::max(b, 0), kBins - 1);
}

// Histogram bins (theta, alpha, phi) of the Darboux-frame angles of the pair (p1, n1), (p2, n2),
// with the source chosen as the point whose normal makes the smaller angle with the connecting
// line, so that the pair gives the same bins from either end. False if degenerate.
bool pairBins(const Vec3& p1, const Vec3& n1, const Vec3& p2, const Vec3& n2, int bins[3]) {
  Vec3 d = p2 - p1;
  const double len = d.norm();
  if (len <= 0.0) return false;
  d /= len;
  const double c1 = n1.dot(d);
  const double c2 = n2.dot(d);
  const Vec3* u = &n1;
  const Vec3* nt = &n2;
  double phi = c1;
  if (std::abs(c1) < std::abs(c2)) {  // the angle at p1 is larger: use p2 as the source
    u = &n2;
    nt = &n1;
    d = -d;
    phi = -c2;
  }
  Vec3 v = d.cross(*u);
  const double vn = v.norm();
  if (vn <= 1e-12) return false;
  v /= vn;
  const Vec3 w = u->cross(v);
  bins[0] = bin(fastAtan2(w.dot(*nt), u->dot(*nt)), -M_PI, M_PI);
  bins[1] = kBins + bin(v.dot(*nt), -1.0, 1.0);
  bins[2] = 2 * kBins + bin(phi, -1.0, 1.0);
  return true;
}
}  // namespace

Features computeFpfh(const Points& points, const Points& normals, const PointTree& tree, double radius,
                     const std::vector<int>& at) {
  const size_t n = points.size();
  // The keypoints' neighbourhoods, and which points need an SPFH.
  std::vector<std::vector<std::pair<size_t, double>>> around(at.size());
  std::vector<char> needed(n, 0);
  for (size_t k = 0; k < at.size(); ++k) {
    const size_t i = static_cast<size_t>(at[k]);
    if (normals[i].isZero()) continue;
    tree.radius(points[i], radius, around[k], false);
    for (const auto& [j, d2] : around[k]) needed[j] = 1;
  }
  // SPFH: each pair once (its bins are the same from either end), added to both ends that need it.
  Features spfh(n, Fpfh::Zero());
  std::vector<int> count(n, 0);
  std::vector<int> keypoint_of(n, -1);
  for (size_t k = 0; k < at.size(); ++k) keypoint_of[at[k]] = static_cast<int>(k);
  std::vector<std::pair<size_t, double>> searched;
  for (size_t i = 0; i < n; ++i) {
    if (!needed[i] || normals[i].isZero()) continue;
    const std::vector<std::pair<size_t, double>>* neighbours = &searched;
    if (keypoint_of[i] >= 0)
      neighbours = &around[keypoint_of[i]];
    else
      tree.radius(points[i], radius, searched, false);
    for (const auto& [j, d2] : *neighbours) {
      if (j == i || normals[j].isZero() || (needed[j] && j < i)) continue;  // j < i: added when j was visited
      int b[3];
      if (!pairBins(points[i], normals[i], points[j], normals[j], b)) continue;
      for (int c : b) spfh[i][c] += 1.0f;
      ++count[i];
      if (needed[j]) {
        for (int c : b) spfh[j][c] += 1.0f;
        ++count[j];
      }
    }
  }
  for (size_t i = 0; i < n; ++i)
    if (count[i] > 0) spfh[i] *= 100.0f / static_cast<float>(count[i]);
  Features out(at.size(), Fpfh::Zero());
  for (size_t k = 0; k < at.size(); ++k) {
    const size_t i = static_cast<size_t>(at[k]);
    if (spfh[i].isZero()) continue;
    Fpfh acc = Fpfh::Zero();
    for (const auto& [j, d2] : around[k]) {
      if (j == i || spfh[j].isZero() || d2 <= 0.0) continue;
      acc += spfh[j] * static_cast<float>(1.0 / std::sqrt(d2));
    }
    // Normalise each sub-histogram of the weighted sum to 100, then add the point's own SPFH.
    for (int s = 0; s < 3; ++s) {
      const float sum = acc.segment<kBins>(s * kBins).sum();
      if (sum > 0.0f) acc.segment<kBins>(s * kBins) *= 100.0f / sum;
    }
    out[k] = spfh[i] + acc;
  }
  return out;
}

bool anyNonZeroFpfh(const Points& points, const Points& normals, const PointTree& tree, double radius,
                    const std::vector<int>& at) {
  // A point's FPFH is non-zero iff its SPFH is (the weighted neighbour sum added to it is
  // non-negative or NaN), iff computeFpfh's SPFH loop counts a valid pair for it (a bin then
  // holds at least 100/11). That loop visits every needed point (within `radius` of a point `at`
  // with a normal) that has a normal, with the same radius search as here, and takes a pair of
  // two needed points only from the lower index, as ordered there (pairBins may find one order
  // degenerate and not the other when both angles are equal). For a point i `at` with a normal,
  // visited because its own search holds it, and a neighbour j with a normal (needed, being in
  // i's neighbourhood), the pair is counted for i
  //   j > i: when i is visited, iff pairBins(i, j);
  //   j < i: when j is visited, iff i is in j's neighbourhood and pairBins(j, i).
  std::vector<std::pair<size_t, double>> around, back;
  int bins[3];
  for (const int a : at) {
    const size_t i = static_cast<size_t>(a);
    if (normals[i].isZero()) continue;
    tree.radius(points[i], radius, around, false);
    if (std::none_of(around.begin(), around.end(), [&](const auto& nb) { return nb.first == i; })) continue;
    for (const auto& [j, d2] : around)
      if (j > i && !normals[j].isZero() && pairBins(points[i], normals[i], points[j], normals[j], bins)) return true;
    for (const auto& [j, d2] : around) {
      if (j >= i || normals[j].isZero() || !pairBins(points[j], normals[j], points[i], normals[i], bins)) continue;
      tree.radius(points[j], radius, back, false);
      if (std::any_of(back.begin(), back.end(), [&](const auto& nb) { return nb.first == i; })) return true;
    }
  }
  // No point `at` has a pair counted from its own neighbourhood. Were neighbourhoods symmetric
  // (j finds i iff i finds j) that would settle it, but nanoflann prunes with a rounded bound, so
  // a point at the radius could be found from j and not from i. Rare (sparse or degenerate
  // clouds), and then no dearer than before: the features themselves.
  const Features features = computeFpfh(points, normals, tree, radius, at);
  return std::any_of(features.begin(), features.end(), [](const Fpfh& f) { return !f.isZero(); });
}

}  // namespace livo::loop
