// What the trajectory figure marks besides the error: stretches where the estimator was weak and
// loop closures, by sensor time. Read from the weak_spots.json `livo-report extract` writes for a
// pipeline run (only the keys below; times are stamps in seconds, on the estimate's clock).
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace livo {

struct PlotMarks {
  /// [from, to] stamps of the sweeps flagged degenerate (degenerate.spans[].from/to).
  std::vector<std::pair<double, double>> degenerate;
  /// [from, to] stamps of the sweeps predicted without a LiDAR update (predicted.spans[].from/to).
  std::vector<std::pair<double, double>> predicted;
  struct Loop {
    double time = 0.0;        // when the correction came (loops[].time)
    double from_stamp = 0.0;  // the loop's keyframes (loops[].from_time, to_time; NaN if unknown)
    double to_stamp = 0.0;
  };
  std::vector<Loop> loops;

  bool empty() const { return degenerate.empty() && predicted.empty() && loops.empty(); }
};

/// How every figure draws them (livo-evaluate's, livo-report's trajectory_top.svg): a wide
/// translucent stroke over the path, a dashed line between a loop's keyframes.
inline constexpr const char* kDegenerateColour = "#ff8c00";
inline constexpr const char* kPredictedColour = "#5e5e5e";
inline constexpr const char* kLoopColour = "#c51b7d";

/// Reads the marks from a weak_spots.json; throws std::runtime_error naming the file when it cannot
/// be read or lacks a key above.
PlotMarks readPlotMarks(const std::string& path);

}  // namespace livo
