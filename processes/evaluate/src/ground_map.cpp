#include "livo/evaluate/ground_map.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "livo/flat_key_index.hpp"
#include "livo/time.hpp"
#include "livo/voxel_key.hpp"

namespace livo::evaluate {

// Memory: a 2-minute 16-beam run registers tens of millions of points, so no point is kept. The
// scans are read twice. The first pass counts each cell's true heights in 1 cm bins (dense from
// the cell's lowest bin to its highest: a few dozen bins for the ground, one per centimetre of a
// wall) and takes the 5th percentile from them; the histograms are then dropped. The second pass
// keeps per cell only the sums the two standard deviations need, over the points in the band.
// Reading the log twice costs less than keeping two heights per point (8 bytes times tens of
// millions), and the percentile to 1 cm moves the band's edges by less than the range noise.

namespace {

constexpr double kBinsPerMetre = 100.0;  // the floor percentile's resolution: 1 cm
constexpr double kFloorFraction = 0.05;  // the floor: the 5th percentile of a cell's true heights
constexpr size_t kMinGroundPoints = 10;  // a cell counts with this many ground points, from 2 scans
constexpr double kGridLimit = 1 << 20;   // cells (and centimetres of height) from the origin: packVoxel's range

/// Counts of a cell's true heights in 1 cm bins, dense from the lowest bin seen to the highest.
class HeightHistogram {
 public:
  void add(int64_t bin) {
    if (counts_.empty()) {
      first_bin_ = bin;
      counts_.push_back(0);
    } else if (bin < first_bin_) {
      counts_.insert(counts_.begin(), static_cast<size_t>(first_bin_ - bin), 0);
      first_bin_ = bin;
    } else if (bin >= first_bin_ + static_cast<int64_t>(counts_.size())) {
      counts_.resize(static_cast<size_t>(bin - first_bin_ + 1), 0);
    }
    ++counts_[static_cast<size_t>(bin - first_bin_)];
    ++total_;
  }

  /// The bin of the k-th lowest height, k = ceil(fraction * count), at least 1 (the nearest rank).
  int64_t percentileBin(double fraction) const {
    const auto rank = std::max<uint64_t>(1, static_cast<uint64_t>(std::ceil(fraction * static_cast<double>(total_))));
    uint64_t at_or_below = 0;
    for (size_t i = 0; i < counts_.size(); ++i) {
      at_or_below += counts_[i];
      if (at_or_below >= rank) return first_bin_ + static_cast<int64_t>(i);
    }
    return first_bin_ + static_cast<int64_t>(counts_.size()) - 1;
  }

 private:
  int64_t first_bin_ = 0;
  std::vector<uint32_t> counts_;
  uint64_t total_ = 0;
};

/// What the two standard deviations of a cell's ground points need: their count, whether they
/// came from more than one scan, and the sums of their heights. Each height is taken relative to
/// one of the cell's (the floor; the first estimated height, as the estimate's world may sit far
/// from the truth's), so that E[d^2] - E[d]^2 does not cancel the digits of a large height.
struct GroundLayer {
  int64_t floor_bin = 0;  // the bin of the 5th percentile of the cell's true heights
  double floor_m = 0.0;   // its lower edge
  size_t points = 0;
  int64_t first_scan = -1;
  bool several_scans = false;
  double est_origin = 0.0;
  double est_sum = 0.0, est_squares = 0.0;
  double true_sum = 0.0, true_squares = 0.0;

  void add(double est_z, double true_z, int64_t scan) {
    if (points == 0) {
      first_scan = scan;
      est_origin = est_z;
    } else if (scan != first_scan) {
      several_scans = true;
    }
    const double e = est_z - est_origin, t = true_z - floor_m;
    est_sum += e;
    est_squares += e * e;
    true_sum += t;
    true_squares += t * t;
    ++points;
  }
  bool counts() const { return points >= kMinGroundPoints && several_scans; }
  double estimatedStd() const { return deviation(est_sum, est_squares); }
  double trueStd() const { return deviation(true_sum, true_squares); }

 private:
  double deviation(double sum, double squares) const {
    const double n = static_cast<double>(points), mean = sum / n;
    return std::sqrt(std::max(0.0, squares / n - mean * mean));  // population (numpy's ddof = 0)
  }
};

Trajectory sortedByStamp(Trajectory t) {
  std::stable_sort(t.begin(), t.end(), [](const StampedPose& a, const StampedPose& b) { return a.stamp < b.stamp; });
  return t;
}

/// Both passes: which scans are used, where their points truly are, which cell each falls in.
/// The first pass counts heights per cell and the scans and points; the second adds the ground
/// points of each cell; a scan or point the first pass skipped, the second skips the same way.
class GroundMapBuilder {
 public:
  GroundMapBuilder(Trajectory gt, const GroundMapOptions& options)
      : gt_(sortedByStamp(std::move(gt))), options_(options), inv_cell_(1.0 / options.cell_m) {}

  void countHeights(const GroundScan& scan) {
    Pose3 true_from_est;
    if (!usable(scan, &true_from_est)) {
      ++result_.scans_skipped;
      result_.scans_empty += scan.size == 0 ? 1 : 0;
      return;
    }
    ++result_.scans;
    forEachPoint(
        scan, true_from_est,
        [&](const Vec3&, const Vec3& q, VoxelKey key) {
          const int32_t cell = cells_.insert(key, static_cast<int32_t>(histograms_.size()));
          if (cell == static_cast<int32_t>(histograms_.size())) histograms_.emplace_back();
          histograms_[static_cast<size_t>(cell)].add(floorToInt(q.z() * kBinsPerMetre));
          ++result_.points_binned;
        },
        &result_.points_skipped);
  }

  /// Each cell's floor from its histogram; the histograms are not needed after this.
  void placeFloors() {
    layers_.resize(histograms_.size());
    for (size_t c = 0; c < histograms_.size(); ++c) {
      layers_[c].floor_bin = histograms_[c].percentileBin(kFloorFraction);
      layers_[c].floor_m = static_cast<double>(layers_[c].floor_bin) / kBinsPerMetre;
    }
    std::vector<HeightHistogram>().swap(histograms_);
  }

  void addGroundPoints(const GroundScan& scan) {
    Pose3 true_from_est;
    if (!usable(scan, &true_from_est)) return;
    size_t skipped = 0;  // counted in the first pass
    const double band_bins = options_.band_m * kBinsPerMetre;
    forEachPoint(
        scan, true_from_est,
        [&](const Vec3& p, const Vec3& q, VoxelKey key) {
          const int32_t cell = cells_.find(key);
          if (cell < 0) return;  // a source that gave other scans the second time
          GroundLayer& layer = layers_[static_cast<size_t>(cell)];
          // in bins, as the first pass binned: the point at the percentile is in the band whatever the rounding
          const double height = q.z() * kBinsPerMetre, floor = static_cast<double>(layer.floor_bin);
          if (height >= floor && height <= floor + band_bins) layer.add(p.z(), q.z(), scan_no_);
        },
        &skipped);
    ++scan_no_;
  }

  GroundMapThickness result() const {
    GroundMapThickness r = result_;
    r.cell_m = options_.cell_m;
    r.band_m = options_.band_m;
    for (const GroundLayer& layer : layers_) {
      if (!layer.counts()) continue;
      r.thickness_m.push_back(layer.estimatedStd());
      r.truth_m.push_back(layer.trueStd());
      r.points += layer.points;
    }
    r.cells = r.thickness_m.size();
    r.thickness = summarizeErrors(r.thickness_m);
    r.truth = summarizeErrors(r.truth_m);
    return r;
  }

 private:
  /// The map from the scan's estimated world to the true one, q = T_gt(t) T_est^-1 p_w; false for
  /// an empty scan or one the ground truth does not bracket within max_dt.
  bool usable(const GroundScan& scan, Pose3* true_from_est) const {
    Pose3 T_gt;
    if (scan.size == 0 || !groundTruthAt(gt_, toSeconds(scan.utime), options_.max_dt, &T_gt)) return false;
    T_gt.translation() -= T_gt.linear() * options_.gt_offset;  // from the tracked point to the body origin
    *true_from_est = T_gt * scan.T_W_I.inverse();
    return true;
  }

  /// Calls visit(p_w, q, cell key) for every finite point of the scan inside the grid; counts the
  /// others in `skipped`.
  template <class Visit>
  void forEachPoint(const GroundScan& scan, const Pose3& true_from_est, Visit visit, size_t* skipped) const {
    for (size_t i = 0; i < scan.size; ++i) {
      const Vec3 p(scan.x[i], scan.y[i], scan.z[i]);
      const Vec3 q = true_from_est * p;
      VoxelKey key;
      if (!p.allFinite() || !cellOf(q, scan.epoch, &key)) {
        ++*skipped;
        continue;
      }
      visit(p, q, key);
    }
  }

  /// The key of q's cell in the scan's epoch (a reset starts an unrelated world frame, whose
  /// heights cannot be compared with the earlier ones); false beyond the grid.
  bool cellOf(const Vec3& q, int32_t epoch, VoxelKey* key) const {
    const double cx = q.x() * inv_cell_, cy = q.y() * inv_cell_, cz = q.z() * kBinsPerMetre;
    if (!(std::abs(cx) < kGridLimit && std::abs(cy) < kGridLimit && std::abs(cz) < kGridLimit)) return false;
    if (epoch < 0 || epoch >= kGridLimit) return false;
    *key = packVoxel(floorToInt(cx), floorToInt(cy), epoch);
    return true;
  }

  const Trajectory gt_;
  const GroundMapOptions options_;
  const double inv_cell_;
  FlatKeyIndex cells_{1 << 16};
  std::vector<HeightHistogram> histograms_;  // first pass, per cell
  std::vector<GroundLayer> layers_;          // second pass, per cell
  int64_t scan_no_ = 0;                      // second pass: the scan's number among those used
  GroundMapThickness result_;                // the first pass's counts
};

}  // namespace

void GroundMapOptions::validate() const {
  if (!(cell_m > 0.0) || !std::isfinite(cell_m))
    throw std::invalid_argument("--ground-cell must be a positive number of metres");
  if (!(band_m > 0.0) || !std::isfinite(band_m))
    throw std::invalid_argument("--ground-band must be a positive number of metres");
  if (!(max_dt >= 0.0) || !std::isfinite(max_dt))
    throw std::invalid_argument("--ground-max-dt must be a non-negative number of seconds");
  if (!gt_offset.allFinite()) throw std::invalid_argument("--gt-offset must be three finite numbers");
}

bool groundTruthAt(const Trajectory& gt, double t, double max_dt, Pose3* T) {
  const auto after =
      std::lower_bound(gt.begin(), gt.end(), t, [](const StampedPose& s, double v) { return s.stamp < v; });
  if (after == gt.end()) return false;
  if (after->stamp == t) {
    *T = after->pose;
    return true;
  }
  if (after == gt.begin()) return false;
  const auto before = std::prev(after);
  if (t - before->stamp > max_dt || after->stamp - t > max_dt) return false;
  *T = se3::interpolate(before->pose, after->pose, (t - before->stamp) / (after->stamp - before->stamp));
  return true;
}

GroundMapThickness groundMapThickness(const GroundScanSource& scans, const Trajectory& gt,
                                      const GroundMapOptions& options) {
  options.validate();
  GroundMapBuilder builder(gt, options);
  scans([&](const GroundScan& scan) { builder.countHeights(scan); });
  builder.placeFloors();
  scans([&](const GroundScan& scan) { builder.addGroundPoints(scan); });
  return builder.result();
}

}  // namespace livo::evaluate
