#include "livo/lio/voxel_map.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <mutex>
#include <stdexcept>

namespace livo::lio {

namespace {
constexpr int64_t kSortedCandidates = 16;  // knn: up to this many voxels in a stage are sorted, not heaped
/// Bits needed to hold v (0 for 0).
int bitWidth(uint64_t v) { return v == 0 ? 0 : 64 - __builtin_clzll(v); }
}  // namespace

VoxelMap::VoxelMap(VoxelMapOptions options) : options_(options) {
  if (!(options_.voxel_size > 0.0) || options_.max_points_per_voxel < 1)
    throw std::invalid_argument("VoxelMap: voxel_size > 0 and max_points_per_voxel >= 1 required");
  inv_size_ = 1.0 / options_.voxel_size;
  stride_ = 3 * static_cast<size_t>(options_.max_points_per_voxel);
}

bool VoxelMap::insert(const Vec3& p) { return insert(p, 0.0); }

bool VoxelMap::insert(const Vec3& p, double range) {
  if (!p.allFinite()) return false;
  const int64_t cx = floorToInt(p.x() * inv_size_);
  const int64_t cy = floorToInt(p.y() * inv_size_);
  const int64_t cz = floorToInt(p.z() * inv_size_);
  const VoxelKey key = packVoxel(cx, cy, cz);
  const int32_t next = static_cast<int32_t>(voxels_.size());
  const int32_t v = index_.insert(key, next);
  if (v == next) {
    markOccupied(key);
    voxels_.push_back(Voxel{key, 0, static_cast<int32_t>(cx), static_cast<int32_t>(cy), static_cast<int32_t>(cz)});
    pool_.resize(pool_.size() + stride_);
    misses_.resize(misses_.size() + static_cast<size_t>(options_.max_points_per_voxel), 0);
    ranges_.resize(ranges_.size() + static_cast<size_t>(options_.max_points_per_voxel), 0.0f);
  }
  Voxel& vox = voxels_[static_cast<size_t>(v)];
  float* pts = voxelPoints(v);
  uint8_t* misses = voxelMisses(v);
  float* ranges = voxelRanges(v);
  const double min_d2 = options_.min_point_distance * options_.min_point_distance;
  const double seen_d2 = options_.seen_again_distance * options_.seen_again_distance;
  int nearest = -1;  // the nearest stored point closer than min_point_distance
  double nearest_d2 = min_d2;
  int farthest_seen = -1;  // the stored point seen from the longest range
  for (int i = 0; i < vox.count; ++i) {
    const double dx = pts[3 * i] - p.x(), dy = pts[3 * i + 1] - p.y(), dz = pts[3 * i + 2] - p.z();
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 < seen_d2) misses[i] = 0;  // seen again
    if (d2 < nearest_d2) nearest = i, nearest_d2 = d2;
    if (farthest_seen < 0 || ranges[i] > ranges[farthest_seen]) farthest_seen = i;
  }
  int slot = vox.count;
  if (nearest >= 0 || vox.count >= options_.max_points_per_voxel) {
    slot = nearest >= 0 ? nearest : farthest_seen;
    if (!(range < options_.refresh_range_ratio * ranges[slot])) return false;
  } else {
    ++vox.count;
  }
  pts[3 * slot] = static_cast<float>(p.x());
  pts[3 * slot + 1] = static_cast<float>(p.y());
  pts[3 * slot + 2] = static_cast<float>(p.z());
  misses[slot] = 0;
  ranges[slot] = static_cast<float>(range);
  return true;
}

size_t VoxelMap::insert(const std::vector<Vec3>& points) {
  size_t n = 0;
  for (const auto& p : points) n += insert(p, 0.0) ? 1 : 0;
  return n;
}

size_t VoxelMap::insert(const std::vector<Vec3>& points, const Vec3& origin) {
  size_t n = 0;
  for (const auto& p : points) n += insert(p, (p - origin).norm()) ? 1 : 0;
  return n;
}

// knn: the k nearest so far, sorted by squared distance (into the caller's arrays).
struct VoxelMap::KnnResult {
  int k;
  Vec3* points;
  double* sq_dist;
  int found;
  double worst;  // admit points with d2 <= worst
};

// knn: a box of voxels [lo, hi] per axis.
struct VoxelMap::KnnBox {
  int64_t lo[3] = {1, 1, 1}, hi[3] = {0, 0, 0};  // empty
  bool contains(int64_t x, int64_t y, int64_t z) const {
    return lo[0] <= x && x <= hi[0] && lo[1] <= y && y <= hi[1] && lo[2] <= z && z <= hi[2];
  }
};

// knn: one stage's voxels meeting the ball. An entry of the heap is one integer, the voxel's
// distance as float bits (non-negative floats order as their bits) above its place in the stage's
// box, so a heap step moves 8 bytes; the stop test uses the double distance. The place packs the
// voxel's offsets in the box into bit fields (x above y above z: the order of a linear index, for
// equal distances), so that a visit decodes it with shifts, not divisions, and its key is the box
// corner's plus the offsets (packVoxel's fields do not carry within its coordinate range).
struct VoxelMap::KnnStage {
  KnnBox box;
  double r2 = 0.0;  // the stage's squared radius
  int bits_z = 0, shift_x = 0;
  uint32_t mask_y = 0, mask_z = 0;
  VoxelKey corner = 0;
  uint64_t* heap = heap_small;
  double* cand_d2 = d2_small;  // by place in the box
  int64_t nc = 0;              // entries of the heap
  uint64_t heap_small[64];
  double d2_small[64];
  std::vector<uint64_t> heap_large;
  std::vector<double> d2_large;

  VoxelKey keyAt(uint64_t x, uint64_t y, uint64_t z) const { return corner + x + (y << 21) + (z << 42); }
  VoxelKey keyOf(uint32_t index) const { return keyAt(index >> shift_x, (index >> bits_z) & mask_y, index & mask_z); }
};

inline __attribute__((always_inline)) void VoxelMap::scanVoxel(VoxelKey key, const Vec3& q, KnnResult* best) const {
  const int32_t v = index_.find(key);
  if (v < 0) return;
  const int k = best->k;
  double* out_sq_dist = best->sq_dist;
  Vec3* out_points = best->points;
  const float* pts = voxelPoints(v);
  const int cnt = voxels_[static_cast<size_t>(v)].count;
  for (int i = 0; i < cnt; ++i) {
    const double dx = pts[3 * i] - q.x(), dy = pts[3 * i + 1] - q.y(), dz = pts[3 * i + 2] - q.z();
    const double d2 = dx * dx + dy * dy + dz * dz;
    if (d2 > best->worst) continue;
    if (best->found == k && d2 >= out_sq_dist[k - 1]) continue;
    int j = best->found < k ? best->found++ : k - 1;
    while (j > 0 && out_sq_dist[j - 1] > d2) {
      out_sq_dist[j] = out_sq_dist[j - 1];
      out_points[j] = out_points[j - 1];
      --j;
    }
    out_sq_dist[j] = d2;
    out_points[j] = Vec3(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
    if (best->found == k) best->worst = out_sq_dist[k - 1];
  }
}

void VoxelMap::stageCandidates(const Vec3& q, double stage_r, const KnnBox& inner, double inner2,
                               KnnStage* stage) const {
  const double vs = options_.voxel_size;
  const double stage_r2 = stage_r * stage_r;
  stage->r2 = stage_r2;
  KnnBox& box = stage->box;
  double ax[3][8];  // per axis: the squared distance from q to each cell's slab (0 in q's own)
  for (int a = 0; a < 3; ++a) {
    box.lo[a] = floorToInt((q[a] - stage_r) * inv_size_);
    box.hi[a] = floorToInt((q[a] + stage_r) * inv_size_);
  }
  const int64_t nx = box.hi[0] - box.lo[0] + 1, ny = box.hi[1] - box.lo[1] + 1, nz = box.hi[2] - box.lo[2] + 1;
  const int64_t ncand = nx * ny * nz;
  std::vector<double> ax_large;
  double* axis[3] = {ax[0], ax[1], ax[2]};
  if (std::max({nx, ny, nz}) > 8) {
    ax_large.resize(static_cast<size_t>(nx + ny + nz));
    axis[0] = ax_large.data(), axis[1] = axis[0] + nx, axis[2] = axis[1] + ny;
  }
  for (int a = 0; a < 3; ++a)
    for (int64_t c = box.lo[a]; c <= box.hi[a]; ++c) {
      // the distance to the cell's slab: max(0, below, above) by branches (std::max of a list
      // was a tenth of the search)
      const double below = c * vs - q[a], above = q[a] - (c + 1) * vs;
      const double d = below > 0.0 ? below : above > 0.0 ? above : 0.0;
      axis[a][c - box.lo[a]] = d * d;
    }
  const int bits_y = bitWidth(static_cast<uint64_t>(ny - 1)), bits_z = bitWidth(static_cast<uint64_t>(nz - 1));
  const int shift_x = bits_y + bits_z;
  stage->bits_z = bits_z;
  stage->shift_x = shift_x;
  stage->mask_y = (uint32_t{1} << bits_y) - 1;
  stage->mask_z = (uint32_t{1} << bits_z) - 1;
  const size_t places = size_t{1} << (bitWidth(static_cast<uint64_t>(nx - 1)) + shift_x);
  stage->corner = packVoxel(box.lo[0], box.lo[1], box.lo[2]);
  if (places > 64) {
    stage->heap_large.resize(static_cast<size_t>(ncand));
    stage->d2_large.resize(places);
    stage->heap = stage->heap_large.data();
    stage->cand_d2 = stage->d2_large.data();
  }
  uint64_t* heap = stage->heap;
  double* cand_d2 = stage->cand_d2;
  int64_t nc = 0;
  for (int64_t x = 0; x < nx; ++x)
    for (int64_t y = 0; y < ny; ++y) {
      const double dxy = axis[0][x] + axis[1][y];
      if (dxy > stage_r2) continue;
      for (int64_t z = 0; z < nz; ++z) {
        const double d2 = dxy + axis[2][z];
        if (d2 > stage_r2) continue;
        if (d2 <= inner2 && inner.contains(box.lo[0] + x, box.lo[1] + y, box.lo[2] + z)) continue;  // visited
        // a voxel the occupancy bits rule out holds nothing: it never enters the order (most of
        // the ball is empty space outdoors, and each entry costs a heap step)
        if (!mayHold(stage->keyAt(x, y, z))) continue;
        const uint32_t index = static_cast<uint32_t>((x << shift_x) | (y << bits_z) | z);
        const float f = static_cast<float>(d2);
        uint32_t bits;
        std::memcpy(&bits, &f, sizeof bits);
        cand_d2[index] = d2;
        heap[nc++] = (uint64_t{bits} << 32) | index;
      }
    }
  stage->nc = nc;
}

void VoxelMap::visitNearestFirst(KnnStage* stage, const Vec3& q, KnnResult* best) const {
  uint64_t* heap = stage->heap;
  const double* cand_d2 = stage->cand_d2;
  const int64_t nc = stage->nc;
  if (nc <= kSortedCandidates) {
    // a few candidates (the first stage's, usually): an insertion sort costs less than the heap
    for (int64_t i = 1; i < nc; ++i) {
      const uint64_t e = heap[i];
      int64_t j = i;
      for (; j > 0 && heap[j - 1] > e; --j) heap[j] = heap[j - 1];
      heap[j] = e;
    }
    for (int64_t i = 0; i < nc; ++i) {
      const uint32_t index = static_cast<uint32_t>(heap[i]);
      if (cand_d2[index] > best->worst) break;  // this stage's others are farther still
      scanVoxel(stage->keyOf(index), q, best);
    }
  } else {
    const std::greater<uint64_t> farther;  // std::*_heap with greater: a min-heap
    std::make_heap(heap, heap + nc, farther);
    for (int64_t left = nc; left > 0; --left) {
      const uint32_t index = static_cast<uint32_t>(heap[0]);
      if (cand_d2[index] > best->worst) break;  // this stage's others are farther still
      std::pop_heap(heap, heap + left, farther);
      scanVoxel(stage->keyOf(index), q, best);
    }
  }
}

int VoxelMap::knn(const Vec3& q, int k, double max_distance, Vec3* out_points, double* out_sq_dist) const {
  if (k <= 0 || k > 32 || voxels_.empty() || !q.allFinite()) return 0;
  const double vs = options_.voxel_size;
  KnnResult best{k, out_points, out_sq_dist, 0, max_distance * max_distance};
  // The voxels meeting the ball (less those the occupancy bits rule out) are visited nearest
  // first and looked up in the index lazily, so the search stops after the few nearest (about 8 at
  // the defaults). It runs in two stages: the voxels within half the radius (a fifth of the ball's
  // 64 at the defaults), then, only if the k nearest are not settled by then, the rest; each stage
  // orders its voxels with a min-heap, which pays only for those visited (or, up to
  // kSortedCandidates of them, with an insertion sort). The order decides only which voxel is
  // looked up first: the result is exact.
  KnnBox inner;          // the previous stage's box ...
  double inner2 = -1.0;  // ... whose voxels with d2 <= inner2 were visited
  for (const double stage_r : {0.5 * max_distance, max_distance}) {
    KnnStage stage;
    stageCandidates(q, stage_r, inner, inner2, &stage);
    visitNearestFirst(&stage, q, &best);
    // Settled when no unvisited voxel can hold a nearer point: those left are this stage's beyond
    // worst, and those beyond stage_r or outside the box (whose faces are about stage_r from q; the
    // exact distance guards rounding).
    double unvisited2 = stage.r2;
    for (int a = 0; a < 3; ++a) {
      const double face = std::min(q[a] - stage.box.lo[a] * vs, (stage.box.hi[a] + 1) * vs - q[a]);
      unvisited2 = std::min(unvisited2, face * face);
    }
    if (best.found == k && best.worst <= unvisited2) return best.found;
    inner = stage.box;
    inner2 = stage.r2;
  }
  return best.found;
}

void VoxelMap::removePoint(int32_t v, int i) {
  Voxel& vox = voxels_[static_cast<size_t>(v)];
  float* pts = voxelPoints(v);
  uint8_t* misses = voxelMisses(v);
  const int last = --vox.count;
  std::copy_n(pts + 3 * last, 3, pts + 3 * i);
  misses[i] = misses[last];
  voxelRanges(v)[i] = voxelRanges(v)[last];
}

namespace {
constexpr uint8_t kSeenThroughThisSweep = 0x80;
}  // namespace

namespace {
/// Whether the beam from the origin along dir, reaching `reach`, passes through the point at q
/// (relative to the origin): within the beam's radius of the ray, between min_range and reach.
bool beamPassesThrough(const Vec3& q, const Vec3& dir, double reach, const SeenThroughOptions& o) {
  const double along = q.dot(dir);
  if (along < o.min_range || along > reach) return false;
  const double radius = o.beam_radius + o.beam_divergence * along;
  return q.squaredNorm() - along * along < radius * radius;
}
}  // namespace

void VoxelMap::markSeenThrough(int32_t v, const Vec3& origin, const Vec3& dir, double reach,
                               const SeenThroughOptions& o, std::vector<int32_t>* touched) {
  const float* pts = voxelPoints(v);
  uint8_t* misses = voxelMisses(v);
  for (int i = 0; i < voxels_[static_cast<size_t>(v)].count; ++i) {
    if (misses[i] & kSeenThroughThisSweep) continue;
    if (!beamPassesThrough(Vec3(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]) - origin, dir, reach, o)) continue;
    touched->push_back(v);
    misses[i] |= kSeenThroughThisSweep;
  }
}

template <typename VisitVoxel>
void VoxelMap::forEachVoxelNearBeams(const Vec3& origin, const std::vector<Vec3>& endpoints,
                                     const SeenThroughOptions& o, size_t first_beam, size_t end_beam,
                                     VisitVoxel visit) const {
  // Any step gives the same result (the cubes below hold every voxel within the beam's radius of
  // the ray, and the points themselves are tested): one voxel walks the ray in half the samples of
  // half a voxel, for a few more voxels tested.
  const double step = options_.voxel_size;
  const size_t stride = static_cast<size_t>(std::max(1, o.ray_stride));
  for (size_t beam = first_beam; beam < end_beam; ++beam) {
    const Vec3 w = endpoints[beam * stride] - origin;
    const double range = w.norm();
    if (!(range > o.min_range) || range > o.max_range) continue;
    const Vec3 dir = w / range;
    const double reach = range - std::max(o.end_margin, o.end_margin_fraction * range);
    // the voxels within the beam's radius of the ray up to `reach`: the cube of half-size
    // step / 2 + radius around every sample holds every voxel the ray passes within radius of
    const double half = 0.5 * step + o.beam_radius + o.beam_divergence * reach;
    // The samples whose cube holds a given voxel are consecutive (the cube's centre moves along
    // a line, and the centres whose cube meets a voxel lie in a box around it): a voxel in the
    // previous sample's cube has been visited, any other has not.
    int64_t prev_lo[3] = {1, 1, 1}, prev_hi[3] = {0, 0, 0};  // empty
    for (double t = o.min_range; t < reach + step; t += step) {
      const Vec3 c = origin + std::min(t, reach) * dir;
      int64_t lo[3], hi[3];
      for (int a = 0; a < 3; ++a) {
        lo[a] = floorToInt((c[a] - half) * inv_size_);
        hi[a] = floorToInt((c[a] + half) * inv_size_);
      }
      for (int64_t x = lo[0]; x <= hi[0]; ++x) {
        const bool x_seen = prev_lo[0] <= x && x <= prev_hi[0];
        for (int64_t y = lo[1]; y <= hi[1]; ++y) {
          const bool xy_seen = x_seen && prev_lo[1] <= y && y <= prev_hi[1];
          for (int64_t z = lo[2]; z <= hi[2]; ++z) {
            if (xy_seen && prev_lo[2] <= z && z <= prev_hi[2]) continue;
            const VoxelKey key = packVoxel(x, y, z);
            if (!mayHold(key)) continue;
            const int32_t v = index_.find(key);
            if (v >= 0) visit(v, dir, reach);
          }
        }
      }
      std::copy_n(lo, 3, prev_lo);
      std::copy_n(hi, 3, prev_hi);
    }
  }
}

size_t VoxelMap::removeSeenThrough(const Vec3& origin, const std::vector<Vec3>& endpoints, const SeenThroughOptions& o,
                                   WorkerThreads* threads) {
  if (!o.enabled || voxels_.empty() || !origin.allFinite()) return 0;
  std::vector<int32_t> touched;  // voxels holding a point seen through in this sweep
  const size_t stride = static_cast<size_t>(std::max(1, o.ray_stride));
  const size_t beams = (endpoints.size() + stride - 1) / stride;
  constexpr size_t kMinBeamsPerThread = 128;
  if (!threads || threads->threads() == 1 || beams < 2 * kMinBeamsPerThread) {
    forEachVoxelNearBeams(origin, endpoints, o, 0, beams, [&](int32_t v, const Vec3& dir, double reach) {
      markSeenThrough(v, origin, dir, reach, o, &touched);
    });
  } else {
    // Shared among threads, the beams only find the points they pass through (the map is read
    // only); the marks are then set here, in share order. The points marked are the same as on
    // one thread, so the result is too.
    std::mutex found_mutex;
    std::vector<std::pair<size_t, std::vector<std::pair<int32_t, int32_t>>>> found;  // by a share's first beam
    threads->forEachShare(
        beams,
        [&](size_t begin, size_t end) {
          std::vector<std::pair<int32_t, int32_t>> mine;
          forEachVoxelNearBeams(origin, endpoints, o, begin, end, [&](int32_t v, const Vec3& dir, double reach) {
            const float* pts = voxelPoints(v);
            for (int i = 0; i < voxels_[static_cast<size_t>(v)].count; ++i)
              if (beamPassesThrough(Vec3(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]) - origin, dir, reach, o))
                mine.emplace_back(v, i);
          });
          std::lock_guard<std::mutex> lock(found_mutex);
          found.emplace_back(begin, std::move(mine));
        },
        kMinBeamsPerThread);
    std::sort(found.begin(), found.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    for (const auto& share : found)
      for (const auto& [v, i] : share.second) {
        uint8_t& miss = voxelMisses(v)[i];
        if (miss & kSeenThroughThisSweep) continue;
        miss |= kSeenThroughThisSweep;
        touched.push_back(v);
      }
  }
  // one miss per sweep for every point seen through; those with enough go
  std::sort(touched.begin(), touched.end());
  touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
  size_t removed = 0;
  for (int32_t v : touched) {
    uint8_t* misses = voxelMisses(v);
    for (int i = 0; i < voxels_[static_cast<size_t>(v)].count;) {
      if (misses[i] & kSeenThroughThisSweep) {
        misses[i] = static_cast<uint8_t>((misses[i] & ~kSeenThroughThisSweep) + 1);
        if (misses[i] >= o.misses_to_remove) {
          removePoint(v, i);
          ++removed;
          continue;  // the last point moved into slot i
        }
      }
      ++i;
    }
  }
  return removed;
}

size_t VoxelMap::removeFarFrom(const Vec3& centre, double radius) {
  const double r2 = radius * radius;
  const double vs = options_.voxel_size;
  size_t kept = 0;
  for (size_t v = 0; v < voxels_.size(); ++v) {
    const Voxel& vox = voxels_[v];
    const Vec3 c((vox.cx + 0.5) * vs, (vox.cy + 0.5) * vs, (vox.cz + 0.5) * vs);
    if ((c - centre).squaredNorm() > r2) continue;
    if (kept != v) {
      voxels_[kept] = vox;
      std::copy_n(&pool_[v * stride_], stride_, &pool_[kept * stride_]);
      const size_t slots = static_cast<size_t>(options_.max_points_per_voxel);
      std::copy_n(&misses_[v * slots], slots, &misses_[kept * slots]);
      std::copy_n(&ranges_[v * slots], slots, &ranges_[kept * slots]);
    }
    ++kept;
  }
  const size_t removed = voxels_.size() - kept;
  if (removed == 0) return 0;
  voxels_.resize(kept);
  pool_.resize(kept * stride_);
  misses_.resize(kept * static_cast<size_t>(options_.max_points_per_voxel));
  ranges_.resize(kept * static_cast<size_t>(options_.max_points_per_voxel));
  voxels_.shrink_to_fit();
  pool_.shrink_to_fit();
  misses_.shrink_to_fit();
  ranges_.shrink_to_fit();
  index_.resetFor(kept);
  std::fill(occupied_.begin(), occupied_.end(), 0);
  for (size_t v = 0; v < kept; ++v) {
    index_.insert(voxels_[v].key, static_cast<int32_t>(v));
    markOccupied(voxels_[v].key);
  }
  return removed;
}

void VoxelMap::transform(const Pose3& T) {
  std::vector<std::pair<Vec3, double>> stored;
  stored.reserve(numPoints());
  for (size_t v = 0; v < voxels_.size(); ++v) {
    const float* pts = voxelPoints(static_cast<int32_t>(v));
    const float* ranges = voxelRanges(static_cast<int32_t>(v));
    for (int i = 0; i < voxels_[v].count; ++i)
      stored.emplace_back(T * Vec3(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]), ranges[i]);
  }
  clear();
  for (const auto& [p, range] : stored) insert(p, range);
}

void VoxelMap::clear() {
  voxels_.clear();
  pool_.clear();
  misses_.clear();
  ranges_.clear();
  index_.resetFor(0);
  std::fill(occupied_.begin(), occupied_.end(), 0);
}

size_t VoxelMap::numPoints() const {
  size_t n = 0;
  for (const auto& v : voxels_) n += static_cast<size_t>(v.count);
  return n;
}

std::vector<Vec3> VoxelMap::points() const {
  std::vector<Vec3> out;
  out.reserve(numPoints());
  for (size_t v = 0; v < voxels_.size(); ++v) {
    const float* pts = voxelPoints(static_cast<int32_t>(v));
    for (int i = 0; i < voxels_[v].count; ++i) out.emplace_back(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]);
  }
  return out;
}

}  // namespace livo::lio
