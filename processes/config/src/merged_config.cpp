#include "livo/config/merged_config.hpp"

#include <sstream>

#include "livo/config.hpp"

namespace livo::config {

std::string mergedConfig(const std::string& base, const std::vector<std::string>& overlays) {
  const Config merged = Config::load(base, overlays);
  merged.checkKeysIn(kConfigSections);
  std::string header = "# livo-config merge: " + base;
  for (const std::string& o : overlays) header += " + " + o;
  return header + "\n" + Config::mergedText(base, overlays);
}

std::vector<std::string> overlayList(const std::string& comma_separated) {
  std::vector<std::string> files;
  std::stringstream list(comma_separated);
  for (std::string f; std::getline(list, f, ',');)
    if (!f.empty()) files.push_back(f);
  return files;
}

}  // namespace livo::config
