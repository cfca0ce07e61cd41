// livo-evaluate --est E --gt G [--align se3|sim3|4dof|none] [--max-dt S] [--ground-map LOG[:CH]] [--json F] [--plot F]
// ...
#include <iostream>

#include "livo/evaluate/evaluate_command.hpp"

int main(int argc, char** argv) { return livo::evaluate::runEvaluateCommand(argc, argv, std::cout, std::cerr); }
