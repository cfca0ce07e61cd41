// The trajectory from above without ground truth (a real recording has none): the final estimate,
// the online odometry where it differs, and where the estimate was weak (weak_spots.json: the
// degenerate and predicted stretches over the path, each loop closure joining its keyframes), as
// livo-evaluate's figure marks them. Hand-written SVG.
#pragma once

#include <string>
#include <vector>

#include "livo/plot_marks.hpp"
#include "livo/trajectory_io.hpp"

namespace livo::report {

struct TrajectoryFigureInputs {
  Trajectory final_estimate;         // trajectory.tum (loop-corrected); empty: the odometry is drawn as the estimate
  Trajectory odometry;               // odometry.tum; drawn in grey beneath when it differs from the final
  PlotMarks marks;                   // none: nothing marked
  std::vector<double> reset_stamps;  // odometry resets: the path is broken there (resets.json)
  std::string title;
};

/// `width` px wide; the height follows the path's extent (equal scales on both axes). Throws
/// std::invalid_argument when neither trajectory has a finite pose.
std::string trajectoryTopSvg(const TrajectoryFigureInputs& in, double width = 1000.0);

}  // namespace livo::report
