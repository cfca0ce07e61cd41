// The evaluation as tables: plain text for the terminal and a Markdown report that embeds the plot.
#pragma once

#include <iosfwd>
#include <string>

#include "livo/evaluate/evaluation.hpp"

namespace livo::evaluate {

void printSummary(std::ostream& os, const Evaluation& ev, const TrajectoryInput& est, const TrajectoryInput& gt,
                  const EvaluationOptions& options);

/// `plot_path`, if not empty, is embedded by its path relative to the report's folder.
void writeMarkdownReport(const std::string& path, const Evaluation& ev, const TrajectoryInput& est,
                         const TrajectoryInput& gt, const EvaluationOptions& options, const std::string& plot_path);

}  // namespace livo::evaluate
