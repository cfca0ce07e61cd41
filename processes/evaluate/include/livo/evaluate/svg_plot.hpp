// A figure a person can read: the top view of ground truth and the aligned estimate coloured by
// its absolute error, beside the absolute and relative errors over time. Hand-written SVG. With
// marks (a pipeline run's weak_spots.json), the estimate's degenerate and predicted stretches are
// overlaid on its path and shaded on the time axes, and each loop closure joins its two keyframes.
#pragma once

#include <string>

#include "livo/evaluate/evaluation.hpp"
#include "livo/plot_marks.hpp"

namespace livo::evaluate {

struct PlotOptions {
  std::string title;  // first line of the figure
  double width = 1500;
  double height = 760;
  PlotMarks marks;  // none: the figure as without
};

std::string evaluationSvg(const Evaluation& ev, const PlotOptions& options);

/// Writes evaluationSvg to `path`; throws std::runtime_error naming the file if it cannot.
void writeEvaluationSvg(const std::string& path, const Evaluation& ev, const PlotOptions& options);

}  // namespace livo::evaluate
