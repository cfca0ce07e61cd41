// livo-evaluate run in process from the tests: its exit code and what it printed.
#pragma once

#include <sstream>
#include <string>
#include <vector>

#include "livo/evaluate/evaluate_command.hpp"

namespace livo::evaluate::test {

struct CommandResult {
  int code;
  std::string out, err;
};

/// livo-evaluate with `args` (without the program name).
inline CommandResult runEvaluate(std::vector<std::string> args) {
  args.insert(args.begin(), "livo-evaluate");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  std::ostringstream out, err;
  const int code = runEvaluateCommand(static_cast<int>(argv.size()), argv.data(), out, err);
  return {code, out.str(), err.str()};
}

}  // namespace livo::evaluate::test
