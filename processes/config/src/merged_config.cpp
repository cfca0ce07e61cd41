#include "livo/config/merged_config.hpp"

#include "livo/config.hpp"

namespace livo::config {

std::string mergedConfig(const std::string& base, const std::vector<std::string>& overlays) {
  const Config merged = Config::load(base, overlays);
  merged.checkKeysIn(kConfigSections);
  std::string header = "# livo-config merge: " + base;
  for (const std::string& o : overlays) header += " + " + o;
  return header + "\n" + Config::mergedText(base, overlays);
}

}  // namespace livo::config
