#include "livo/evaluate/evaluation.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace livo::evaluate {

const char* alignmentName(Alignment a) {
  switch (a) {
    case Alignment::kSE3: return "se3";
    case Alignment::kSim3: return "sim3";
    case Alignment::kFourDof: return "4dof";
    case Alignment::kNone: break;
  }
  return "none";
}

Alignment parseAlignment(const std::string& name) {
  if (name == "se3") return Alignment::kSE3;
  if (name == "sim3") return Alignment::kSim3;
  if (name == "none") return Alignment::kNone;
  if (name == "4dof") return Alignment::kFourDof;
  throw std::invalid_argument(
      "--align: expected se3, sim3 or none, or 4dof (yaw about z and translation), "
      "got '" +
      name + "'");
}

void EvaluationOptions::validate() const {
  if (!(max_dt >= 0.0) || !std::isfinite(max_dt))
    throw std::invalid_argument("--max-dt must be a non-negative number of seconds");
  if (!gt_offset.allFinite()) throw std::invalid_argument("--gt-offset must be three finite numbers");
  if (!(coverage_gap >= 0.0) || !std::isfinite(coverage_gap))
    throw std::invalid_argument("--coverage-gap must be a non-negative number of seconds");
  if (rpe.delta < 1) throw std::invalid_argument("--rpe-delta must be at least 1 frame");
  if (drift.step < 1) throw std::invalid_argument("--drift-step must be at least 1 pose");
  if (drift.segment_lengths.empty()) throw std::invalid_argument("--drift-lengths needs at least one length");
  for (double L : drift.segment_lengths)
    if (!(L > 0.0) || !std::isfinite(L)) throw std::invalid_argument("--drift-lengths must be positive metres");
}

Coverage groundTruthCoverage(std::vector<double> stamps, double gt_first, double gt_last, double gap) {
  Coverage c;
  c.span = gt_last - gt_first;
  std::sort(stamps.begin(), stamps.end());
  stamps.erase(std::unique(stamps.begin(), stamps.end()), stamps.end());
  std::vector<double> intervals;
  for (size_t i = 1; i < stamps.size(); ++i) intervals.push_back(stamps[i] - stamps[i - 1]);
  if (gap > 0.0) {
    c.gap = gap;
  } else if (!intervals.empty()) {
    std::vector<double> sorted = intervals;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2), sorted.end());
    c.gap = 3.0 * sorted[sorted.size() / 2];
  }
  for (double dt : intervals)
    if (dt <= c.gap) c.covered += dt;
  if (c.span > 0.0)
    c.fraction = std::min(1.0, c.covered / c.span);
  else
    c.fraction = stamps.empty() ? 0.0 : 1.0;
  return c;
}

namespace {
std::string timeRange(const Trajectory& t) {
  double lo = t.front().stamp, hi = t.front().stamp;
  for (const auto& s : t) lo = std::min(lo, s.stamp), hi = std::max(hi, s.stamp);
  std::ostringstream os;
  os << std::fixed << std::setprecision(6) << t.size() << " poses, " << lo << " .. " << hi << " s";
  return os.str();
}

Similarity3 alignmentFor(Alignment mode, const std::vector<Vec3>& est_positions,
                         const std::vector<Vec3>& gt_positions) {
  switch (mode) {
    case Alignment::kSE3: return umeyamaAlignment(est_positions, gt_positions, false);
    case Alignment::kSim3: return umeyamaAlignment(est_positions, gt_positions, true);
    case Alignment::kFourDof: return fourDofAlignment(est_positions, gt_positions);
    case Alignment::kNone: break;
  }
  return Similarity3{};
}

/// Per pair |p_est - p_gt| after a 4-DoF alignment of the estimate; empty when its yaw is undefined.
std::vector<double> fourDofPositionErrors(const std::vector<Vec3>& est_positions,
                                          const std::vector<Vec3>& gt_positions) {
  Similarity3 yaw_and_shift;
  try {
    yaw_and_shift = fourDofAlignment(est_positions, gt_positions);
  } catch (const AlignmentError&) {
    return {};
  }
  std::vector<double> errors;
  for (size_t k = 0; k < est_positions.size(); ++k)
    errors.push_back((yaw_and_shift.apply(est_positions[k]) - gt_positions[k]).norm());
  return errors;
}

/// The metrics a ground-vehicle claim needs, on the estimate as read (offset applied, not aligned).
void addGroundVehicleMetrics(Evaluation& ev, const std::vector<Pose3>& est_as_read,
                             const std::vector<Vec3>& est_positions, const std::vector<Vec3>& gt_positions) {
  ev.ate_4dof_m = fourDofPositionErrors(est_positions, gt_positions);
  ev.ate_4dof = summarizeErrors(ev.ate_4dof_m);
  ev.vertical = verticalDrift(ev.gt, est_as_read);
  ev.attitude = attitudeError(ev.gt, est_as_read);
}
}  // namespace

Evaluation evaluateTrajectory(const TrajectoryInput& est_in, const TrajectoryInput& gt_in,
                              const EvaluationOptions& options) {
  options.validate();
  Trajectory est = est_in.poses;
  const Trajectory& gt = gt_in.poses;
  if (est.empty() || gt.empty()) throw EvaluationError("nothing to evaluate: an input has no poses");
  applyBodyOffset(est, options.gt_offset);

  Evaluation ev;
  ev.est_poses = est.size();
  ev.gt_poses = gt.size();
  try {
    ev.pairs =
        est_in.has_stamps && gt_in.has_stamps ? associateByTime(est, gt, options.max_dt) : associateByIndex(est, gt);
  } catch (const AssociationError& e) {
    throw EvaluationError(std::string(e.what()) + " (" + est_in.path + " and " + gt_in.path +
                          "; a KITTI pose file has no time stamps, so poses pair by index)");
  }
  if (ev.pairs.empty()) {
    std::ostringstream os;
    os << "no estimated pose lies within " << options.max_dt << " s of a ground-truth pose: estimate " << est_in.path
       << " has " << timeRange(est) << "; ground truth " << gt_in.path << " has " << timeRange(gt)
       << " (check the time base, or raise --max-dt)";
    throw EvaluationError(os.str());
  }

  const size_t n = ev.pairs.size();
  std::vector<Vec3> est_positions(n), gt_positions(n);
  std::vector<Pose3> est_as_read;  // per pair, offset applied
  for (size_t k = 0; k < n; ++k) {
    const StampedPose& e = est[ev.pairs.est[k]];
    const StampedPose& g = gt[ev.pairs.gt[k]];
    ev.est_stamps.push_back(e.stamp);
    ev.gt_stamps.push_back(g.stamp);
    ev.gt.push_back(g.pose);
    est_as_read.push_back(e.pose);
    est_positions[k] = e.pose.translation();
    gt_positions[k] = g.pose.translation();
  }
  for (const auto& g : gt) ev.gt_path.push_back(g.pose.translation());

  if (options.alignment != Alignment::kNone) {
    try {
      ev.alignment = alignmentFor(options.alignment, est_positions, gt_positions);
    } catch (const AlignmentError& e) {
      throw EvaluationError(std::string(e.what()) + " (" + std::to_string(n) + " pairs; try --align none)");
    }
  }
  for (size_t k = 0; k < n; ++k) {
    ev.est.push_back(ev.alignment.apply(est[ev.pairs.est[k]].pose));
    ev.ate_m.push_back((ev.est[k].translation() - ev.gt[k].translation()).norm());
  }
  ev.ate = summarizeErrors(ev.ate_m);

  double gt_first = gt.front().stamp, gt_last = gt.front().stamp;
  for (const auto& g : gt) gt_first = std::min(gt_first, g.stamp), gt_last = std::max(gt_last, g.stamp);
  ev.coverage = groundTruthCoverage(ev.gt_stamps, gt_first, gt_last, options.coverage_gap);

  ev.rpe = relativePoseError(ev.gt, ev.est, options.rpe);
  ev.rpe_translation_m = summarizeErrors(ev.rpe.translation_m);
  ev.rpe_rotation_deg = summarizeErrors(ev.rpe.rotation_deg);
  ev.drift = kittiDrift(ev.gt, ev.est, options.drift);

  const Pose3 anchor = ev.gt.front() * est[ev.pairs.est.front()].pose.inverse();
  const Pose3 end_error = ev.gt.back().inverse() * (anchor * est[ev.pairs.est.back()].pose);
  ev.end_point.translation_m = end_error.translation().norm();
  ev.end_point.rotation_deg = rotationAngle(end_error.linear()) * 180.0 / M_PI;
  for (size_t k = 1; k < n; ++k) ev.end_point.path_length_m += (gt_positions[k] - gt_positions[k - 1]).norm();
  addGroundVehicleMetrics(ev, est_as_read, est_positions, gt_positions);
  return ev;
}

}  // namespace livo::evaluate
