// livo-evaluate --est E --gt G [--align se3|sim3|none] [--max-dt S] [--gt-offset x,y,z] [--json F] [--plot F]
#include <iostream>

#include "livo/evaluate/evaluate_command.hpp"

int main(int argc, char** argv) { return livo::evaluate::runEvaluateCommand(argc, argv, std::cout, std::cerr); }
