// livo-evaluate's command line: reads the two trajectories, evaluates, prints and writes outputs.
#pragma once

#include <iosfwd>

namespace livo::evaluate {

/// Exit code 0 on success, 1 on bad input or when nothing associates (message on `err`), 2 on a
/// usage error.
int runEvaluateCommand(int argc, char** argv, std::ostream& out, std::ostream& err);

}  // namespace livo::evaluate
