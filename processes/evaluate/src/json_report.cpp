#include "livo/evaluate/json_report.hpp"

#include <fstream>
#include <stdexcept>

namespace livo::evaluate {

namespace {
using nlohmann::json;

json statistics(const ErrorStatistics& s) {
  if (s.count == 0)
    return json{{"count", 0},     {"rmse", nullptr}, {"mean", nullptr}, {"median", nullptr},
                {"std", nullptr}, {"min", nullptr},  {"max", nullptr},  {"sse", nullptr}};
  return json{{"count", s.count}, {"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median},
              {"std", s.std},     {"min", s.min},   {"max", s.max},   {"sse", s.sse}};
}

json input(const TrajectoryInput& in) {
  return json{{"source", in.spec}, {"path", in.path}, {"format", in.format}, {"poses", in.poses.size()}};
}

json vec(const Vec3& v) { return json::array({v.x(), v.y(), v.z()}); }

json verticalDrift(const VerticalDrift& v) {
  return json{{"end_m", v.end_m},
              {"per_100m", v.hasPath() ? json(v.per100m()) : json(nullptr)},
              {"max_abs_m", v.max_abs_m},
              {"path_length_m", v.path_length_m}};
}

json attitude(const AttitudeError& a) {
  if (a.tilt.count == 0)
    return json{
        {"roll_rmse_deg", nullptr}, {"pitch_rmse_deg", nullptr}, {"tilt_rmse_deg", nullptr}, {"tilt_max_deg", nullptr}};
  return json{{"roll_rmse_deg", a.roll.rmse},
              {"pitch_rmse_deg", a.pitch.rmse},
              {"tilt_rmse_deg", a.tilt.rmse},
              {"tilt_max_deg", a.tilt.max}};
}
json groundMap(const GroundMapThickness& g) {
  const auto measured = [&](double v) { return g.cells ? json(v) : json(nullptr); };
  return json{{"source", g.source},
              {"cell_m", g.cell_m},
              {"band_m", g.band_m},
              {"thickness_rms_m", measured(g.thickness.rmse)},
              {"thickness_median_m", measured(g.thickness.median)},
              {"truth_rms_m", measured(g.truth.rmse)},
              {"truth_median_m", measured(g.truth.median)},
              {"cells", g.cells},
              {"points", g.points},
              {"points_binned", g.points_binned},
              {"points_skipped", g.points_skipped},
              {"scans", g.scans},
              {"scans_skipped", g.scans_skipped},
              {"scans_empty", g.scans_empty}};
}
}  // namespace

json evaluationJson(const Evaluation& ev, const TrajectoryInput& est, const TrajectoryInput& gt,
                    const EvaluationOptions& options) {
  json j;
  j["estimate"] = input(est);
  j["ground_truth"] = input(gt);
  j["gt_offset"] = vec(options.gt_offset);
  j["association"] = {{"method", ev.pairs.by_index ? "index" : "time"},
                      {"max_dt", options.max_dt},
                      {"pairs", ev.pairs.size()},
                      {"estimate_fraction", static_cast<double>(ev.pairs.size()) / static_cast<double>(ev.est_poses)}};
  json rotation = json::array();
  for (int r = 0; r < 3; ++r)
    rotation.push_back({ev.alignment.rotation(r, 0), ev.alignment.rotation(r, 1), ev.alignment.rotation(r, 2)});
  j["alignment"] = {{"mode", alignmentName(options.alignment)},
                    {"scale", ev.alignment.scale},
                    {"rotation", rotation},
                    {"translation", vec(ev.alignment.translation)}};

  json ate = statistics(ev.ate);
  ate["coverage"] = ev.coverage.fraction;
  ate["coverage_gap"] = ev.coverage.gap;
  ate["covered"] = ev.coverage.covered;
  ate["span"] = ev.coverage.span;
  ate["unit"] = "m";
  j["ate"] = ate;

  j["rpe"] = {{"delta_frames", options.rpe.delta},
              {"all_pairs", options.rpe.all_pairs},
              {"pairs", ev.rpe.from.size()},
              {"translation", statistics(ev.rpe_translation_m)},
              {"rotation", statistics(ev.rpe_rotation_deg)},
              {"translation_unit", "m"},
              {"rotation_unit", "deg"}};

  json per_length = json::array();
  for (const auto& d : ev.drift.per_length) {
    per_length.push_back({{"length_m", d.length_m},
                          {"segments", d.segments},
                          {"translation_percent", d.segments ? json(d.translation_percent) : json(nullptr)},
                          {"rotation_deg_per_m", d.segments ? json(d.rotation_deg_per_m) : json(nullptr)}});
  }
  j["drift"] = {{"step", options.drift.step},
                {"segments", ev.drift.segments},
                {"translation_percent", ev.drift.segments ? json(ev.drift.translation_percent) : json(nullptr)},
                {"rotation_deg_per_m", ev.drift.segments ? json(ev.drift.rotation_deg_per_m) : json(nullptr)},
                {"per_length", per_length}};
  j["end_point"] = {{"translation_m", ev.end_point.translation_m},
                    {"rotation_deg", ev.end_point.rotation_deg},
                    {"path_length_m", ev.end_point.path_length_m},
                    {"percent", ev.end_point.percent()}};
  j["ate_4dof"] = ev.ate_4dof.count ? json(ev.ate_4dof.rmse) : json(nullptr);
  j["vertical"] = verticalDrift(ev.vertical);
  j["attitude"] = attitude(ev.attitude);
  j["ground_map"] = ev.ground_map ? groundMap(*ev.ground_map) : json(nullptr);
  return j;
}

void writeEvaluationJson(const std::string& path, const Evaluation& ev, const TrajectoryInput& est,
                         const TrajectoryInput& gt, const EvaluationOptions& options) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path + ": cannot write");
  out << evaluationJson(ev, est, gt, options).dump(2) << "\n";
  if (!out) throw std::runtime_error(path + ": write failed");
}

}  // namespace livo::evaluate
