// Where the estimate was weak, from a run's recorded outputs: the LIO's degenerate sweeps merged
// into stretches, with the direction the position was least certain in; the sweeps predicted
// without a LiDAR update; the images a VIO did not use, and why; the loop closures.
// `livo-report extract` writes it as weak_spots.json, `livo-report markdown` renders it in
// report.md, and `livo-evaluate --marks` draws it on the trajectory figure.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "livo/report/pipeline_outputs.hpp"

namespace livo::report {

/// A stretch of consecutive flagged samples: the stamps (s) of its first and last, and how many.
struct TimeSpan {
  double from = 0.0;
  double to = 0.0;
  int64_t count = 0;
  double duration() const { return to - from; }
};

/// Merges runs of consecutive flagged samples (consecutive in the order given, the time order)
/// into spans, in that order. Throws std::invalid_argument if the sizes differ.
std::vector<TimeSpan> mergeFlaggedRuns(const std::vector<double>& stamps, const std::vector<bool>& flagged);

/// The spans longest first: by duration (within 1 ms: equal), then by samples, the earlier first
/// on a tie.
std::vector<TimeSpan> longestFirst(std::vector<TimeSpan> spans);

/// Where the position was least certain (the largest eigenvalue of its covariance), against the
/// motion: along the velocity (within 30 deg), across it (more than 60 deg off), vertical (within
/// 30 deg of the world's z), oblique; at rest below kAtRestSpeed; no single direction when the
/// largest eigenvalue is less than kDominance times the second.
enum class WeakDirection { kNoSingle, kAlongTravel, kAcrossTravel, kVertical, kOblique, kAtRest };

struct WeakAxis {
  WeakDirection direction = WeakDirection::kNoSingle;
  int body_axis = -1;  // 0, 1, 2: the body axis (x, y, z) it lies along within 30 deg; -1: none
};

constexpr double kAtRestSpeed = 0.1;  // m/s
constexpr double kDominance = 2.0;

/// position_covariance and velocity in the world frame W; R_W_I the body's orientation.
WeakAxis weakAxis(const Mat3& position_covariance, const Vec3& velocity, const Mat3& R_W_I);

/// "along the direction of travel (body x)", "no single direction", ...
std::string describe(const WeakAxis& axis);

/// A stretch of degenerate sweeps and the most frequent description of its weak direction.
struct DegenerateStretch {
  TimeSpan span;
  std::string direction;
};

/// A VIO's images that were not used: from its STATE_POSTERIOR answers (valid = 0: the prior was
/// kept) and the counts by reason its final HEALTH carries (livo/reason_counts.hpp).
struct VisualRefusals {
  std::string node;
  std::string what;  // how the node names them: "priors kept", "images refused"
  int64_t refused = 0;
  int64_t of = 0;                          // images answered or handled; 0: unknown
  std::map<std::string, int64_t> reasons;  // empty: the node did not say
  std::vector<TimeSpan> spans;             // runs of kept priors, in time order
};

/// A loop closure with the stamps of its keyframes (NaN when the log does not hold them).
struct LoopMark {
  LoopEvent event;
  double from_stamp = 0.0;
  double to_stamp = 0.0;
};

struct WeakSpots {
  double start = 0.0;  // stamp (s) of the first odometry pose: report.md counts time from it
  int64_t sweeps = 0;  // odometry poses
  int64_t degenerate = 0;
  std::vector<DegenerateStretch> degenerate_stretches;  // in time order
  std::string direction;                                // the most frequent description over every degenerate sweep
  double direction_share = 0.0;                         // of the degenerate sweeps it describes
  int64_t predicted = 0;                                // sweeps without a LiDAR update (after each epoch's first)
  std::vector<TimeSpan> predicted_spans;
  int64_t state_priors = 0;  // images lio handed to a VIO (STATE_PRIOR)
  std::vector<VisualRefusals> visual;
  std::vector<LoopMark> loops;  // in log order
};

/// `camera_channel` names the images' channel in the VIOs' HEALTH (how many they handled).
WeakSpots findWeakSpots(const PipelineOutputs& outputs, const std::string& camera_channel = "CAMERA");

nlohmann::json weakSpotsJson(const WeakSpots& w);
/// Reads weakSpotsJson() back; throws nlohmann::json::exception on a malformed document.
WeakSpots weakSpotsFromJson(const nlohmann::json& j);

constexpr size_t kListedStretches = 10;  // stretches (the longest) and loops (the largest) listed; the rest counted

/// The "Where the estimate was weak" section of report.md.
std::string weakSpotsMarkdown(const WeakSpots& w);

}  // namespace livo::report
