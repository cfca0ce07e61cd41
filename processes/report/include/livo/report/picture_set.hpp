// What `livo-report pictures` drew (pictures.json): each picture's file, title and caption, and
// notes on what it could not draw. `livo-report markdown` makes the report's "Maps" section of it.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace livo::report {

struct Picture {
  std::string file;     // in the run's folder
  std::string title;    // "RGB map from above"
  std::string caption;  // markdown: what is drawn, how
};

struct PictureSet {
  std::vector<Picture> pictures;
  std::vector<std::string> notes;  // what was not drawn, and why (markdown)
};

nlohmann::json picturesJson(const PictureSet& set);
/// Reads picturesJson() back; throws nlohmann::json::exception on a malformed document.
PictureSet picturesFromJson(const nlohmann::json& j);

/// The report's "Maps" section: each picture under its title and caption, then the notes.
std::string mapsMarkdown(const PictureSet& set);

}  // namespace livo::report
