// One livo-import run: a format, an input, an output log and the format's options. Runs the
// importer, writes the time-sorted log and its `<log>.meta.yaml` sidecar, prints the summary;
// optionally writes a starter rig config from what the import saw (starter_rig_config.hpp) and
// checks a given rig against the log (rig_check.hpp).
#pragma once

#include <iosfwd>
#include <map>
#include <optional>
#include <string>

#include "livo/import/euroc_import.hpp"
#include "livo/import/import_report.hpp"
#include "livo/import/kitti_import.hpp"
#include "livo/import/ouster_import.hpp"
#include "livo/import/rig_check.hpp"
#include "livo/import/rosbag_import.hpp"
#include "livo/sensor_rig.hpp"

namespace livo::import {

struct ImportJob {
  std::string format;  // rosbag, kitti, euroc, ouster
  std::string input;
  std::string out;
  std::string preset;  // rosbag only
  ChannelNames channels;
  RosbagImportOptions rosbag;
  KittiImportOptions kitti;
  EurocImportOptions euroc;
  OusterImportOptions ouster;
  int64_t max_buffer_mb = 512;
  bool quiet = false;   // no progress, no warnings on stderr
  std::string rig_out;  // write a starter rig config here ("" = none)
  /// A rig to check the log against (its file name for messages; `rig` is read by the caller,
  /// who also takes its channel names for the job's).
  std::string rig_file;
  std::optional<SensorRig> rig;
};

struct ImportOutcome {
  ImportReport report;
  std::map<std::string, int64_t> channel_counts;
  std::map<std::string, std::string> channel_types;
  bool wrote_log = false;
  SensorSurvey survey;                   // what the messages showed of the sensors
  std::vector<RigFinding> rig_findings;  // job.rig against the log, errors first
  bool ok() const { return wrote_log && report.errors().empty(); }
  bool rigFits() const { return rig_findings.empty() || !rig_findings.front().error; }
};

/// The rig's channel names for the sensors the importers write (imu, lidar, camera, depth,
/// ground_truth); camera_right keeps its name.
ChannelNames channelNamesOf(const SensorRig& rig, ChannelNames names);

/// Applies the preset (throws std::invalid_argument if unknown or not for this format). Options
/// already set explicitly (non-empty topics) are kept.
void applyPreset(ImportJob& job);

/// Runs the job; never throws for bad input (errors are in the outcome's report). The summary goes
/// to `summary` (nullptr: none).
ImportOutcome runImport(const ImportJob& job, std::ostream* summary);

}  // namespace livo::import
