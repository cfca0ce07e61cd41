// What a pipeline run left in its recorded outputs log: the online odometry with what each pose
// says of its own quality, the keyframes, the loop corrections, the VIO's answers, and every
// node's final HEALTH.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "livo/health_t.hpp"
#include "livo/loop_correction_t.hpp"
#include "livo/trajectory_io.hpp"

namespace livo::report {

struct PipelineChannels {
  std::string odometry = "ODOMETRY";
  std::string keyframe = "KEYFRAME";
  std::string loop_correction = "LOOP_CORRECTION";
  std::string health = "HEALTH";
  std::string state_prior = "STATE_PRIOR";
  std::string state_posterior = "STATE_POSTERIOR";
  std::string camera = "CAMERA";  // only its name: the VIOs' HEALTH counts the images on it
};

/// The frame a published pose is in (odometry_t / keyframe_t epoch and correction_id).
struct PublishedFrame {
  int32_t epoch = 0;
  int64_t correction_id = 0;
};

struct KeyframePose {
  int64_t id = 0;
  double stamp = 0.0;
  Pose3 pose = Pose3::Identity();  // as published (odometry frame at that time)
  PublishedFrame frame;
};

/// What an odometry message says of its own quality (odometry_t).
struct OdometryQuality {
  bool degenerate = false;                  // some direction was left to the prediction
  int32_t num_residuals = 0;                // 0: no LiDAR update (predicted, or seeding the map)
  Vec3 velocity = Vec3::Zero();             // W_v_I
  Mat3 position_covariance = Mat3::Zero();  // of W_p_I
};

/// A LOOP_CORRECTION: the loop that triggered it and how far it moved the newest keyframe.
struct LoopEvent {
  int64_t correction_id = 0;
  int32_t epoch = 0;
  double stamp = 0.0;              // the newest keyframe in the graph
  int64_t from_id = 0, to_id = 0;  // the loop edge's keyframes
  double fitness = 0.0;            // m^2
  double shift_m = 0.0;            // the newest corrected keyframe moved by it (T_Ck_Cj)
  double turn_deg = 0.0;           // its rotation
};

/// A STATE_POSTERIOR: a VIO's answer to the prior of the image at `stamp`.
struct VisualAnswer {
  double stamp = 0.0;
  std::string source;  // the answering node
  bool valid = false;  // false: the prior was kept (the image was not used)
};

/// An LIO reset seen in the outputs: the first odometry of a new epoch.
struct OdometryReset {
  double stamp = 0.0;  // first odometry of the new epoch
  int32_t epoch = 0;   // the new epoch
  std::string reason;  // from lio's HEALTH ("odometry reset to epoch N: ..."), empty if not logged
};

struct PipelineOutputs {
  Trajectory odometry;                                       // body pose at every scan, in stamp order
  std::vector<PublishedFrame> odometry_frames;               // the frame of each odometry pose (same order)
  std::vector<OdometryQuality> odometry_quality;             // and what it says of itself (same order)
  std::vector<KeyframePose> keyframes;                       // in id order
  std::map<int32_t, loop_correction_t> last_loop;            // the newest LOOP_CORRECTION of each epoch
  std::map<int64_t, std::pair<int32_t, Pose3>> corrections;  // every correction: id -> (epoch, T_Ck_O)
  int64_t loop_corrections = 0;
  std::vector<LoopEvent> loops;                  // every LOOP_CORRECTION, in log order
  int64_t state_priors = 0;                      // STATE_PRIOR: images handed to a VIO
  std::vector<VisualAnswer> visual_answers;      // STATE_POSTERIOR, in stamp order
  std::vector<OdometryReset> resets;             // in stamp order
  std::map<std::string, health_t> final_health;  // newest HEALTH per node
  int64_t undecodable = 0;                       // messages on these channels that did not decode
  int64_t non_finite = 0;                        // odometry poses dropped for NaN/Inf
};

/// Reads the log; throws std::runtime_error naming the file if it cannot be opened.
PipelineOutputs readPipelineOutputs(const std::string& log_path, const PipelineChannels& channels = {});

/// The final trajectory. Each pose is first taken back to the raw odometry frame of its epoch
/// through the loop correction it says it includes (correction_id; so a pose published after lio
/// adopted a correction is never corrected twice, whatever the arrival order), then moved by the
/// correction of the newest keyframe of its epoch at or before it, K_corrected * K_raw^-1, using
/// the last loop correction of that epoch (keyframes newer than it take its odometry_to_corrected).
/// Identical to the odometry when there was no loop correction. Epochs stay separate (each in its
/// own frame). Throws std::runtime_error for a pose in a correction the log does not hold.
/// An epoch with loop corrections but no recorded KEYFRAME cannot be anchored: its poses are kept
/// as published (the online trajectory) and a line is added to `warnings` if given.
Trajectory loopCorrectedTrajectory(const PipelineOutputs& outputs, std::vector<std::string>* warnings = nullptr);

/// The resets as JSON: [{"time": s, "epoch": n, "reason": "..."}].
std::string resetsJson(const std::vector<OdometryReset>& resets);

}  // namespace livo::report
