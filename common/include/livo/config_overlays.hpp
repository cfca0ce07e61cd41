// The overlay files of a command line (--overlay A.yaml,B.yaml), for livo::Config::load(file, overlays).
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace livo {

/// "A.yaml,B.yaml" as a list, in order (empty entries skipped).
inline std::vector<std::string> overlayFiles(const std::string& comma_separated) {
  std::vector<std::string> files;
  std::stringstream list(comma_separated);
  for (std::string f; std::getline(list, f, ',');)
    if (!f.empty()) files.push_back(f);
  return files;
}

}  // namespace livo
