// ROS 2 bag (rosbag2 directory, .mcap or .db3) -> LCM log: the same topics, presets, conversions
// and report as the ROS 1 importer (rosbag_import.hpp; both go through ros_message_converter.hpp),
// the messages decoded from CDR (or from ROS 1 serialisation: MCAP files converted from ROS 1
// bags, message encoding "ros1", read without an md5 check). Other serialization formats are skipped.
#pragma once

#include <string>
#include <vector>

#include "livo/import/import_report.hpp"
#include "livo/import/rosbag_import.hpp"
#include "livo/import/sorted_log_writer.hpp"

namespace livo::import {

/// Reads every file of the bag, in order. A read error stops that file; what was read is kept
/// and the error is in the report.
void importRosbag2(const std::string& input, const RosbagImportOptions& options, SortedLogWriter& writer,
                   ImportReport& report);

/// Topics of a ROS 2 bag with type and message count (metadata.yaml or the files' summaries when
/// they have them), for --list-topics.
std::vector<BagTopic> listRosbag2Topics(const std::string& input);

}  // namespace livo::import
