// `--check-config`, offered the same way by every process that reads a project config: the config
// is read and validated exactly as at start-up (the same reader, the same errors and exit status)
// and the options are printed as at start-up, then the process exits 0 before it touches LCM.
//
//   livo::CommandLine cli("livo-x", "...");
//   cli.option("--config", "FILE", "...");
//   livo::declareConfigCheck(cli);
//   ...
//   const auto options = livo::x::readXNodeOptions(livo::Config::load(file));  // errors: as always
//   if (!quiet) livo::x::printOptions(options, std::cerr);
//   if (livo::configCheckDone(cli, std::cout)) return 0;                       // before makeLcm
#pragma once

#include <iosfwd>

#include "livo/command_line.hpp"

namespace livo {

/// Declares the flag `--check-config` on a process's command line.
CommandLine& declareConfigCheck(CommandLine& cli);

/// Whether `--check-config` was given; if so, says on `out` that the file named by `--config` is
/// valid for this process. Call it once the options are read, validated and printed, and return 0
/// when it is true.
bool configCheckDone(const CommandLine& cli, std::ostream& out);

}  // namespace livo
