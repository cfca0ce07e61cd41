// One livo-import run: a format, an input, an output log and the format's options. Runs the
// importer, writes the time-sorted log and its `<log>.meta.yaml` sidecar, prints the summary.
#pragma once

#include <iosfwd>
#include <map>
#include <string>

#include "livo/import/euroc_import.hpp"
#include "livo/import/import_report.hpp"
#include "livo/import/kitti_import.hpp"
#include "livo/import/ouster_import.hpp"
#include "livo/import/rosbag_import.hpp"

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
  bool quiet = false;  // no progress, no warnings on stderr
};

struct ImportOutcome {
  ImportReport report;
  std::map<std::string, int64_t> channel_counts;
  std::map<std::string, std::string> channel_types;
  bool wrote_log = false;
  bool ok() const { return wrote_log && report.errors().empty(); }
};

/// Applies the preset (throws std::invalid_argument if unknown or not for this format). Options
/// already set explicitly (non-empty topics) are kept.
void applyPreset(ImportJob& job);

/// Runs the job; never throws for bad input (errors are in the outcome's report). The summary goes
/// to `summary` (nullptr: none).
ImportOutcome runImport(const ImportJob& job, std::ostream* summary);

}  // namespace livo::import
