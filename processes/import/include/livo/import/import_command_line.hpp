// livo-import's command line read into an ImportJob (main.cpp declares the flags), and its two
// listings (--list-presets, --list-topics).
#pragma once

#include <iosfwd>
#include <string>

#include "livo/command_line.hpp"
#include "livo/import/import_job.hpp"

namespace livo::import {

/// The job a parsed command line asks for: FORMAT, INPUT, --out, the --rig (read here, its channel
/// names taken unless a --*-channel flag says otherwise), the channels and each format's options; a
/// --preset fills the rosbag topics the flags left empty. Throws (std::invalid_argument naming the
/// flag, or the rig's error) for a missing or bad value.
ImportJob importJobFromCommandLine(const CommandLine& cli);

/// --list-presets: one line per preset, "name: description".
void printRosbagPresets(std::ostream& out);

/// --list-topics: one line per topic of the bag, "topic  type  messages" (throws unless `format`
/// is rosbag, or when the bag cannot be read).
void printBagTopics(const std::string& format, const std::string& bag, std::ostream& out);

}  // namespace livo::import
