// Pairs estimated poses with ground-truth poses: by time stamp, as evo does, or by index (KITTI
// pose files carry no stamps).
#pragma once

#include <cstddef>
#include <stdexcept>
#include <vector>

#include "livo/trajectory_io.hpp"

namespace livo::evaluate {

class AssociationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Index pairs into the estimate and the ground truth; pair k is (est[k], gt[k]).
struct PosePairs {
  std::vector<size_t> est;
  std::vector<size_t> gt;
  bool by_index = false;
  size_t size() const { return est.size(); }
  bool empty() const { return est.empty(); }
};

/// evo's `sync.associate_trajectories(gt, est, max_diff)`: the trajectory with fewer poses (the
/// estimate when both have as many) is the query; each query pose takes the pose of the other
/// trajectory whose stamp is nearest, the first in file order when several are as near, and the
/// pair is kept if the gap is at most `max_dt` seconds. Pairs follow the query's order, and a pose
/// of the longer trajectory may serve several pairs. Stamps need not be sorted.
PosePairs associateByTime(const Trajectory& est, const Trajectory& gt, double max_dt);

/// Pose i with pose i. Throws AssociationError if the two trajectories differ in length.
PosePairs associateByIndex(const Trajectory& est, const Trajectory& gt);

/// Nearest-stamp look-up over an unsorted sequence of stamps, with evo's tie rule
/// (`numpy.argmin` of |stamp - t|: the smallest index among the nearest).
class NearestStamp {
 public:
  explicit NearestStamp(std::vector<double> stamps);
  /// Index of the nearest stamp; the sequence must not be empty.
  size_t nearest(double t) const;
  double stamp(size_t index) const { return stamps_[index]; }

 private:
  std::vector<double> stamps_;
  std::vector<size_t> order_;  // indices sorted by (stamp, index)
};

}  // namespace livo::evaluate
