#include "livo/config_check.hpp"

#include <ostream>

namespace livo {

namespace {
const char* const kFlag = "--check-config";
}  // namespace

CommandLine& declareConfigCheck(CommandLine& cli) {
  return cli.flag(kFlag,
                  "read and validate the config as at start-up, print the options, exit (0: valid) without "
                  "touching LCM");
}

bool configCheckDone(const CommandLine& cli, std::ostream& out) {
  if (!cli.has(kFlag)) return false;
  out << cli.program() << ": " << cli.get("--config") << ": valid (" << kFlag << ": not started)" << std::endl;
  return true;
}

}  // namespace livo
