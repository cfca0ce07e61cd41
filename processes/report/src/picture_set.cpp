#include "livo/report/picture_set.hpp"

#include <sstream>

namespace livo::report {

nlohmann::json picturesJson(const PictureSet& set) {
  nlohmann::json pictures = nlohmann::json::array();
  for (const Picture& p : set.pictures)
    pictures.push_back({{"file", p.file}, {"title", p.title}, {"caption", p.caption}});
  return {{"pictures", pictures}, {"notes", set.notes}};
}

PictureSet picturesFromJson(const nlohmann::json& j) {
  PictureSet set;
  for (const auto& p : j.at("pictures"))
    set.pictures.push_back(
        {p.at("file").get<std::string>(), p.at("title").get<std::string>(), p.at("caption").get<std::string>()});
  set.notes = j.at("notes").get<std::vector<std::string>>();
  return set;
}

std::string mapsMarkdown(const PictureSet& set) {
  std::ostringstream md;
  md << "## Maps\n\n";
  md << "Pictures of what the run mapped (`livo-report pictures`); `report.html` beside this file is this report "
        "with the RGB map and the trajectory in 3D.\n\n";
  for (const Picture& p : set.pictures)
    md << "**" << p.title << "**: " << p.caption << "\n\n![" << p.title << "](" << p.file << ")\n\n";
  if (!set.notes.empty()) {
    for (const std::string& n : set.notes) md << "- " << n << "\n";
    md << "\n";
  }
  return md.str();
}

}  // namespace livo::report
