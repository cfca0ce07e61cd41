// livo-config's work: a config file with overlays merged over it (livo::Config::load with
// overlays: maps key by key, any other value replaced), checked as every process reads it.
#pragma once

#include <string>
#include <vector>

namespace livo::config {

/// BASE with `overlays` merged over it in order, as one file: a comment line naming the files,
/// then the merged YAML. Throws ConfigError (livo/config.hpp) for an unreadable file, a YAML
/// error or a top-level section no process reads.
std::string mergedConfig(const std::string& base, const std::vector<std::string>& overlays);

}  // namespace livo::config
