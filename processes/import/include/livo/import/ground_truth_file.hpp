// Ground truth from a trajectory file (TUM, EuRoC/ASL csv; detected from the first data line)
// written as pose_t messages.
#pragma once

#include <string>

#include "livo/import/import_report.hpp"
#include "livo/import/sorted_log_writer.hpp"

namespace livo::import {

/// Returns the number of poses written. Errors (unreadable file, bad line) go to the report.
int64_t importGroundTruthFile(const std::string& path, const std::string& channel, const std::string& child_frame,
                              SortedLogWriter& writer, ImportReport& report);

}  // namespace livo::import
