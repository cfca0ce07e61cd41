// The evaluation as JSON: ate.{rmse,mean,median,max,coverage} in metres, rpe.* in metres and
// degrees, drift.* in % and deg/m, ate_4dof, vertical.* and attitude.* (m, deg), ground_map.* (m;
// null when not asked for), plus the inputs, pairing and alignment used.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "livo/evaluate/evaluation.hpp"

namespace livo::evaluate {

nlohmann::json evaluationJson(const Evaluation& ev, const TrajectoryInput& est, const TrajectoryInput& gt,
                              const EvaluationOptions& options);

/// Writes evaluationJson to `path`; throws std::runtime_error naming the file if it cannot.
void writeEvaluationJson(const std::string& path, const Evaluation& ev, const TrajectoryInput& est,
                         const TrajectoryInput& gt, const EvaluationOptions& options);

}  // namespace livo::evaluate
