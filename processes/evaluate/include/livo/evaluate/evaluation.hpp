// The whole evaluation of an estimated trajectory against ground truth: association, alignment,
// absolute trajectory error with coverage, relative pose error, KITTI drift, and for a ground
// vehicle the ATE after a 4-DoF alignment, the vertical drift and the roll / pitch error (and, from
// the registered scans, the ground-map thickness: ground_map.hpp).
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "livo/evaluate/association.hpp"
#include "livo/evaluate/attitude_error.hpp"
#include "livo/evaluate/error_statistics.hpp"
#include "livo/evaluate/four_dof_alignment.hpp"
#include "livo/evaluate/ground_map.hpp"
#include "livo/evaluate/kitti_drift.hpp"
#include "livo/evaluate/relative_pose_error.hpp"
#include "livo/evaluate/trajectory_input.hpp"
#include "livo/evaluate/umeyama.hpp"
#include "livo/evaluate/vertical_drift.hpp"

namespace livo::evaluate {

class EvaluationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// kFourDof: yaw about z and translation (fourDofAlignment), for worlds with z up.
enum class Alignment { kNone, kSE3, kSim3, kFourDof };
const char* alignmentName(Alignment a);
/// "none", "se3", "sim3" or "4dof"; throws std::invalid_argument otherwise.
Alignment parseAlignment(const std::string& name);

struct EvaluationOptions {
  Alignment alignment = Alignment::kSE3;  // Umeyama on the associated positions (evo -a / -as), or 4-DoF
  double max_dt = 0.01;                   // s, largest stamp gap of a pair (evo's default)
  Vec3 gt_offset = Vec3::Zero();          // body frame; moves each estimated pose to that point
  double coverage_gap = 0.0;              // s; 0: three times the median interval between pairs
  RelativePoseErrorOptions rpe;
  KittiDriftOptions drift;

  /// Throws std::invalid_argument naming the offending option.
  void validate() const;
};

/// The share of the ground truth's time span during which the estimate had associated poses:
/// the intervals between consecutive distinct ground-truth stamps of the pairs (sorted) count as
/// covered when no longer than `gap`, and their sum is divided by the span from the first to the
/// last ground-truth stamp. A ground truth of one instant counts as covered by any pair.
struct Coverage {
  double fraction = 0.0;
  double gap = 0.0;      // threshold used, s (frames when paired by index)
  double covered = 0.0;  // s
  double span = 0.0;     // s
};
Coverage groundTruthCoverage(std::vector<double> pair_gt_stamps, double gt_first, double gt_last, double gap);

/// Drift at the end: the estimate anchored on the ground truth at the first pair (rigidly, no
/// fit), its error at the last pair, and the ground-truth path length between them.
struct EndPointDrift {
  double translation_m = 0.0;
  double rotation_deg = 0.0;
  double path_length_m = 0.0;
  double percent() const { return path_length_m > 0.0 ? 100.0 * translation_m / path_length_m : 0.0; }
};

struct Evaluation {
  size_t est_poses = 0;  // as read
  size_t gt_poses = 0;
  PosePairs pairs;
  std::vector<double> est_stamps;  // per pair
  std::vector<double> gt_stamps;   // per pair
  std::vector<Pose3> gt;           // per pair
  std::vector<Pose3> est;          // per pair, offset applied and aligned
  std::vector<Vec3> gt_path;       // every ground-truth position, for plots
  Similarity3 alignment;           // identity when not aligned
  std::vector<double> ate_m;       // per pair: |p_est - p_gt|
  ErrorStatistics ate;
  Coverage coverage;
  RelativePoseError rpe;
  ErrorStatistics rpe_translation_m;
  ErrorStatistics rpe_rotation_deg;
  KittiDrift drift;
  EndPointDrift end_point;
  // Whatever `alignment` is: the ATE after a 4-DoF alignment (count 0 when the yaw is undefined),
  // and on the estimate as read (not aligned): the vertical drift, heights anchored at the first
  // pair, and the roll / pitch / tilt error (a world yaw, all a 4-DoF alignment rotates, changes
  // none of the three).
  std::vector<double> ate_4dof_m;  // per pair, empty when the yaw is undefined
  ErrorStatistics ate_4dof;
  VerticalDrift vertical;
  AttitudeError attitude;
  // From the registered scans when asked for (livo-evaluate --ground-map), not by evaluateTrajectory.
  std::optional<GroundMapThickness> ground_map;
};

/// Pairs by time stamp when both sides have stamps, else by index. Throws EvaluationError when no
/// pair forms (saying what the two time ranges were) or alignment is impossible.
Evaluation evaluateTrajectory(const TrajectoryInput& est, const TrajectoryInput& gt, const EvaluationOptions& options);

}  // namespace livo::evaluate
