#include "livo/lio_graph/plane_extraction.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <optional>
#include <random>

#include <Eigen/Core>

#include "livo/flat_key_index.hpp"
#include "livo/kdtree.hpp"
#include "livo/voxel_key.hpp"

namespace livo::lio_graph {

namespace {

/// Local normals (the plane of each point's k nearest neighbours, itself included, as fitPlane
/// gives it; zero where they are degenerate), computed when first asked for, a grid cell at a
/// time: only the points that are some plane's distance inliers are ever asked for. The neighbours
/// are exact (a kd-tree's): a cell's candidates are the points of the cells up to `shell` cells
/// away, and a point's k nearest among them are taken only if the k-th is nearer than the boundary
/// of that block of cells; otherwise the block grows, and past kMaxShell a kd-tree (built when
/// first needed) answers. The cell size decides the speed only, not the result.
class LocalNormals {
 public:
  // m: a 16-beam sweep at 0.2 m voxels has 8-NN radii of 0.4 m (median) to 0.65 m (90 %), so one
  // shell nearly always settles them, with about 80 candidates a point
  static constexpr double kCell = 0.7;
  static constexpr int kMaxShell = 2;
  static constexpr double kMaxCoordinate = 1e5;  // m: beyond, the grid's keys would wrap

  LocalNormals(const std::vector<Vec3>& points, int k) : points_(points) {
    normal_.assign(points.size(), Vec3::Zero());
    done_.assign(points.size(), 0);
    cell_of_.assign(points.size(), -1);
    size_t finite = 0;
    for (const Vec3& p : points) {
      if (!p.allFinite()) continue;
      ++finite;
      if (p.cwiseAbs().maxCoeff() > kMaxCoordinate) grid_ = false;
    }
    k_ = std::min<size_t>(static_cast<size_t>(std::max(3, k)), finite);
    for (int shell = 1; shell <= kMaxShell; ++shell) {
      std::vector<Eigen::Vector3i> offsets;
      for (int dz = -shell; dz <= shell; ++dz)
        for (int dy = -shell; dy <= shell; ++dy)
          for (int dx = -shell; dx <= shell; ++dx) {
            const Eigen::Vector3i d(dx, dy, dz);
            const int ring = d.cwiseAbs().maxCoeff();
            if (ring == shell || (shell == 1 && ring == 0)) offsets.push_back(d);
          }
      std::stable_sort(offsets.begin(), offsets.end(), [](const Eigen::Vector3i& a, const Eigen::Vector3i& b) {
        return a.squaredNorm() < b.squaredNorm();
      });
      shells_.push_back(std::move(offsets));
    }
    idx_.resize(k_), d2_.resize(k_), nb_.resize(k_);
    if (!grid_) return;
    // cells in first-seen order, their points (ascending) in one array
    const double inv = 1.0 / kCell;
    index_.resetFor(finite / 2 + 16);
    std::vector<int> count;
    for (size_t i = 0; i < points.size(); ++i) {
      if (!points[i].allFinite()) continue;
      const Eigen::Vector3i c(static_cast<int>(std::floor(points[i].x() * inv)),
                              static_cast<int>(std::floor(points[i].y() * inv)),
                              static_cast<int>(std::floor(points[i].z() * inv)));
      const int32_t next = static_cast<int32_t>(cells_.size());
      const int32_t id = index_.insert(packVoxel(c.x(), c.y(), c.z()), next);
      if (id == next) cells_.push_back(c), count.push_back(0);
      cell_of_[i] = id;
      ++count[id];
    }
    start_.assign(cells_.size() + 1, 0);
    for (size_t c = 0; c < cells_.size(); ++c) start_[c + 1] = start_[c] + count[c];
    members_.resize(finite);
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    for (size_t i = 0; i < points.size(); ++i)
      if (cell_of_[i] >= 0) members_[fill[cell_of_[i]]++] = static_cast<int>(i);
  }

  const Vec3& operator()(int i) {
    if (!done_[i]) {
      if (grid_ && cell_of_[i] >= 0)
        computeCell(cell_of_[i]);
      else
        computeWithTree(i);
    }
    return normal_[i];
  }

 private:
  void computeCell(int cell) {
    const Eigen::Vector3i& c = cells_[cell];
    guess_ = std::numeric_limits<double>::infinity();
    std::vector<int>& pending = pending_;
    pending.assign(members_.begin() + start_[cell], members_.begin() + start_[cell + 1]);
    cand_.clear();
    cx_.clear(), cy_.clear(), cz_.clear();
    for (int shell = 1; shell <= kMaxShell && !pending.empty(); ++shell) {
      // the cells at Chebyshev distance `shell` (shell 1 with the centre), nearest first: the
      // nearest neighbours then tend to come early, and fewer candidates displace others
      for (const Eigen::Vector3i& d : shells_[shell - 1]) {
        const int32_t id = index_.find(packVoxel(c.x() + d.x(), c.y() + d.y(), c.z() + d.z()));
        if (id < 0) continue;
        for (int m = start_[id]; m < start_[id + 1]; ++m) {
          const Vec3& q = points_[members_[m]];
          cand_.push_back(members_[m]);
          cx_.push_back(q.x()), cy_.push_back(q.y()), cz_.push_back(q.z());
        }
      }
      const Vec3 lo = (c - Eigen::Vector3i::Constant(shell)).cast<double>() * kCell;
      const Vec3 hi = (c + Eigen::Vector3i::Constant(shell + 1)).cast<double>() * kCell;
      size_t still = 0;
      for (int i : pending) {
        const Vec3& p = points_[i];
        const double margin = std::min((p - lo).minCoeff(), (hi - p).minCoeff());
        if (!nearest(p, margin * margin)) {
          pending[still++] = i;
          continue;
        }
        normalFrom(i);
      }
      pending.resize(still);
    }
    for (int i : pending) computeWithTree(i);
  }

  /// The k nearest candidates of p (ascending distance) into idx_, if the k-th is within
  /// sqrt(certain2) (nothing outside the candidates' block can then be nearer).
  bool nearest(const Vec3& p, double certain2) {
    const size_t n = cand_.size(), k = k_;
    if (n < k) return false;
    // the squared distances all at once (vectorised; the sums in nanoflann's order), then the k
    // smallest
    using Map = Eigen::Map<const Eigen::ArrayXd>;
    const Eigen::Index len = static_cast<Eigen::Index>(n);
    dist_.resize(len);
    dist_ = ((Map(cx_.data(), len) - p.x()).square() + (Map(cy_.data(), len) - p.y()).square()) +
            (Map(cz_.data(), len) - p.z()).square();
    const double* dist = dist_.data();
    const int* cand = cand_.data();
    double* d2 = d2_.data();
    size_t* idx = idx_.data();
    auto insert = [&](size_t at, double d, size_t i) {  // into the sorted d2[0, at]
      while (at > 0 && d2[at - 1] > d) {
        d2[at] = d2[at - 1];
        idx[at] = idx[at - 1];
        --at;
      }
      d2[at] = d;
      idx[at] = i;
    };
    // the candidates within a guess (the previous point's k-th distance, grown: the points of a
    // cell have similar neighbourhoods) hold the k nearest if there are k of them; else all count
    sel_.resize(n);
    int* sel = sel_.data();
    size_t m = 0;
    for (size_t j = 0; j < n; ++j) {
      sel[m] = static_cast<int>(j);
      m += dist[j] <= guess_;
    }
    if (m < k) {
      for (size_t j = 0; j < n; ++j) sel[j] = static_cast<int>(j);
      m = n;
    }
    for (size_t j = 0; j < k; ++j) insert(j, dist[sel[j]], static_cast<size_t>(cand[sel[j]]));
    double worst = d2[k - 1];
    for (size_t s = k; s < m; ++s) {
      const int j = sel[s];
      if (dist[j] < worst) {
        insert(k - 1, dist[j], static_cast<size_t>(cand[j]));
        worst = d2[k - 1];
      }
    }
    guess_ = 1.5 * worst;
    return worst <= certain2;
  }

  void computeWithTree(int i) {
    done_[i] = 1;
    if (!points_[i].allFinite() || k_ < 3) return;
    if (!tree_) {
      for (size_t j = 0; j < points_.size(); ++j)
        if (points_[j].allFinite()) finite_.push_back(points_[j]), finite_index_.push_back(j);
      tree_ = std::make_unique<KdTree<Vec3>>(finite_);
    }
    const size_t n = tree_->knn(points_[i], k_, idx_.data(), d2_.data());
    for (size_t j = 0; j < n; ++j) idx_[j] = finite_index_[idx_[j]];
    if (n == k_) normalFrom(i);
  }

  /// The normal of point i from its neighbours in idx_.
  void normalFrom(int i) {
    done_[i] = 1;
    for (size_t j = 0; j < k_; ++j) nb_[j] = points_[idx_[j]];
    PlaneFit fit;
    if (fitPlane(nb_.data(), static_cast<int>(k_), &fit) && fit.spread[1] > 1e-3 * fit.spread[2])
      normal_[i] = fit.plane.normal;
  }

  const std::vector<Vec3>& points_;
  size_t k_ = 0;
  bool grid_ = true;
  std::vector<Vec3> normal_;
  std::vector<char> done_;
  // the grid: cell coordinates, each point's cell, the cells' points (members_[start_[c] ..])
  FlatKeyIndex index_;
  std::vector<Eigen::Vector3i> cells_;
  std::vector<std::vector<Eigen::Vector3i>> shells_;  // cell offsets of each shell, nearest first
  std::vector<int> cell_of_, start_, members_;
  // a cell's candidates (indices and coordinates), the current point's nearest
  std::vector<int> pending_, cand_;
  std::vector<double> cx_, cy_, cz_;
  Eigen::ArrayXd dist_;
  std::vector<int> sel_;
  double guess_ = std::numeric_limits<double>::infinity();
  std::vector<size_t> idx_;
  std::vector<double> d2_;
  std::vector<Vec3> nb_;
  // the fallback
  std::vector<Vec3> finite_;
  std::vector<size_t> finite_index_;
  std::unique_ptr<KdTree<Vec3>> tree_;
};

/// The plane through three points; false if they are (nearly) collinear.
bool planeThrough(const Vec3& a, const Vec3& b, const Vec3& c, Plane* out) {
  const Vec3 n = (b - a).cross(c - a);
  const double norm = n.norm();
  if (!(norm > 1e-9 * (b - a).squaredNorm() + 1e-12)) return false;
  out->normal = n / norm;
  out->offset = -out->normal.dot(a);
  return true;
}

/// How many sample points (coordinates x, y, z) lie within `threshold` of h, or any number up to
/// `to_beat` once it can no longer exceed that: a hypothesis is kept only if it scores more than
/// the best so far, so the choice is the same as with every point counted. |n.x + d| is computed
/// as Plane::distance does (the same products and sums in the same order).
int scoreOf(const Plane& h, const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& z,
            double threshold, int to_beat) {
  const size_t n = x.size();
  const double a = h.normal.x(), b = h.normal.y(), c = h.normal.z(), d = h.offset;
  auto in = [&](size_t i) { return std::abs(a * x[i] + b * y[i] + c * z[i] + d) < threshold ? 1.0 : 0.0; };
  constexpr size_t kBlock = 64;
  int score = 0;
  size_t i = 0;
  // four independent sums of whole numbers (exact in any order): the compiler vectorises them
  for (; i + kBlock <= n; i += kBlock) {
    if (score + static_cast<int>(n - i) <= to_beat) return score;
    double c0 = 0.0, c1 = 0.0, c2 = 0.0, c3 = 0.0;
    for (size_t j = i; j < i + kBlock; j += 4) c0 += in(j), c1 += in(j + 1), c2 += in(j + 2), c3 += in(j + 3);
    score += static_cast<int>((c0 + c1) + (c2 + c3));
  }
  double c0 = 0.0, c1 = 0.0, c2 = 0.0, c3 = 0.0;
  for (; i + 4 <= n; i += 4) c0 += in(i), c1 += in(i + 1), c2 += in(i + 2), c3 += in(i + 3);
  for (; i < n; ++i) c0 += in(i);
  return score + static_cast<int>((c0 + c1) + (c2 + c3));
}

Vec3 centroidOf(const std::vector<Vec3>& points, const std::vector<int>& ids) {
  Vec3 c = Vec3::Zero();
  for (int i : ids) c += points[i];
  return ids.empty() ? c : Vec3(c / static_cast<double>(ids.size()));
}

std::vector<int> finiteIndices(const std::vector<Vec3>& points) {
  std::vector<int> finite;
  finite.reserve(points.size());
  for (size_t i = 0; i < points.size(); ++i)
    if (points[i].allFinite()) finite.push_back(static_cast<int>(i));
  return finite;
}

/// RANSAC's scoring sample: every stride-th remaining point (at most about `score_sample`),
/// coordinate by coordinate.
struct ScoringSample {
  std::vector<double> x, y, z;
};

ScoringSample scoringSample(const std::vector<Vec3>& points, const std::vector<int>& remaining, int score_sample) {
  const size_t stride = std::max<size_t>(1, remaining.size() / static_cast<size_t>(std::max(1, score_sample)));
  const size_t samples = (remaining.size() + stride - 1) / stride;
  ScoringSample s;
  s.x.resize(samples), s.y.resize(samples), s.z.resize(samples);
  for (size_t k = 0; k < samples; ++k) {
    const Vec3& x = points[remaining[k * stride]];
    s.x[k] = x.x(), s.y[k] = x.y(), s.z[k] = x.z();
  }
  return s;
}

struct ScoredPlane {
  Plane plane;
  int score = 0;  // sample points within the threshold
};

/// The best scoring of `iterations` planes through three random remaining points.
ScoredPlane bestRandomPlane(const std::vector<Vec3>& points, const std::vector<int>& remaining,
                            const ScoringSample& sample, double threshold, int iterations, std::mt19937* rng) {
  std::uniform_int_distribution<size_t> pick(0, remaining.size() - 1);
  ScoredPlane best;
  for (int it = 0; it < iterations; ++it) {
    Plane h;
    if (!planeThrough(points[remaining[pick(*rng)]], points[remaining[pick(*rng)]], points[remaining[pick(*rng)]], &h))
      continue;
    const int score = scoreOf(h, sample.x, sample.y, sample.z, threshold, best.score);
    if (score > best.score) best.score = score, best.plane = h;
  }
  return best;
}

/// The remaining points within `threshold` of p.
std::vector<int> inliersOf(const std::vector<Vec3>& points, const std::vector<int>& remaining, const Plane& p,
                           double threshold) {
  std::vector<int> ids;
  for (int i : remaining)
    if (std::abs(p.distance(points[i])) < threshold) ids.push_back(i);
  return ids;
}

/// The least-squares plane of the points `ids`; none for fewer than three or a degenerate fit.
std::optional<Plane> refitPlane(const std::vector<Vec3>& points, const std::vector<int>& ids) {
  std::vector<Vec3> buf;
  for (int i : ids) buf.push_back(points[i]);
  PlaneFit fit;
  if (buf.size() < 3 || !fitPlane(buf.data(), static_cast<int>(buf.size()), &fit)) return std::nullopt;
  return fit.plane;
}

/// The inliers whose local normal agrees with the plane's (within acos(cos_consistent)).
std::vector<int> consistentInliers(const std::vector<int>& in, const Plane& plane, double cos_consistent,
                                   LocalNormals* normals) {
  std::vector<int> consistent;
  for (int i : in)
    if (std::abs((*normals)(i).dot(plane.normal)) >= cos_consistent) consistent.push_back(i);
  return consistent;
}

void removeFromRemaining(const std::vector<int>& ids, std::vector<char>* gone, std::vector<int>* remaining) {
  for (int i : ids) (*gone)[i] = 1;
  remaining->erase(std::remove_if(remaining->begin(), remaining->end(), [&](int i) { return (*gone)[i] != 0; }),
                   remaining->end());
}

/// The plane of the points `ids` turned towards the sensor, with their centroid and its quality.
ExtractedPlane describePlane(const std::vector<Vec3>& points, std::vector<int> ids, Plane plane, double threshold) {
  ExtractedPlane e;
  if (plane.offset < 0.0) plane.normal = -plane.normal, plane.offset = -plane.offset;
  e.plane = plane;
  e.centroid = centroidOf(points, ids);
  e.threshold = threshold;
  double sum = 0.0;
  for (int i : ids) sum += std::abs(plane.distance(points[i]));
  e.quality = sum / static_cast<double>(ids.size());
  e.inliers = std::move(ids);
  return e;
}

enum class GroundTest { kNotGround, kGround, kTiltedGround };

/// The ground-direction constraint: a nearly horizontal plane below the sensor must be level.
GroundTest groundTest(const ExtractedPlane& e, const Vec3& up, const PlaneExtractionOptions& o) {
  const double tilt_deg = std::acos(std::min(1.0, std::abs(e.plane.normal.dot(up)))) * 180.0 / M_PI;
  const bool below = e.centroid.dot(up) < -o.ground_below;
  if (below && tilt_deg <= o.ground_candidate_deg)
    return tilt_deg > o.ground_max_tilt_deg ? GroundTest::kTiltedGround : GroundTest::kGround;
  return GroundTest::kNotGround;
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
  std::vector<int> remaining = finiteIndices(points);
  if (static_cast<int>(remaining.size()) < std::max(3, o.min_inliers)) return planes;

  LocalNormals normals(points, o.normal_neighbours);
  const double cos_consistent = std::cos(o.normal_max_angle_deg * M_PI / 180.0);
  const Vec3 up = o.up.normalized();
  std::mt19937 rng(o.seed);
  std::vector<char> gone(points.size(), 0);
  for (int attempt = 0; attempt < o.max_planes; ++attempt) {
    if (static_cast<int>(remaining.size()) < std::max(3, o.min_inliers)) break;
    const double threshold = adaptiveThreshold(centroidOf(points, remaining), o);
    // hypotheses from three random remaining points, scored on a strided sample
    const ScoredPlane best = bestRandomPlane(points, remaining, scoringSample(points, remaining, o.score_sample),
                                             threshold, o.ransac_iterations, &rng);
    if (best.score < 3) break;
    // every remaining point within the threshold, refitted by least squares, then counted again
    std::vector<int> in = inliersOf(points, remaining, best.plane, threshold);
    Plane plane = best.plane;
    if (const std::optional<Plane> refitted = refitPlane(points, in)) {
      plane = *refitted;
      in = inliersOf(points, remaining, plane, threshold);
    }
    // normal consistency: inliers whose local normal agrees with the plane's
    const std::vector<int> consistent = consistentInliers(in, plane, cos_consistent, &normals);
    if (static_cast<int>(consistent.size()) < o.min_inliers ||
        static_cast<double>(consistent.size()) < o.min_consistent_fraction * static_cast<double>(in.size())) {
      ++st.refused_inconsistent;
      removeFromRemaining(in, &gone, &remaining);  // explained by no plane: not tried again
      continue;
    }
    if (const std::optional<Plane> refitted = refitPlane(points, consistent)) plane = *refitted;
    removeFromRemaining(consistent, &gone, &remaining);

    ExtractedPlane e = describePlane(points, consistent, plane, threshold);
    if (e.quality > o.max_quality_ratio * threshold) {
      ++st.refused_quality;
      continue;
    }
    const GroundTest ground = groundTest(e, up, o);
    if (ground == GroundTest::kTiltedGround) {
      ++st.refused_ground_tilt;
      continue;
    }
    e.ground = ground == GroundTest::kGround;
    planes.push_back(std::move(e));
    ++st.accepted;
  }
  return planes;
}

}  // namespace livo::lio_graph
