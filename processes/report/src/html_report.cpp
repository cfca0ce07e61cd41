#include "livo/report/html_report.hpp"

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "livo/report/base64.hpp"
#include "livo/report/map_views.hpp"
#include "livo/report/markdown_html.hpp"
#include "livo/text_format.hpp"

namespace livo::report {

namespace {

namespace fs = std::filesystem;

const char* const kStyle = R"CSS(
body { font-family: "DejaVu Sans", Arial, sans-serif; color: #1d1f23; background: #ffffff; margin: 0; }
main { max-width: 1180px; margin: 0 auto; padding: 8px 24px 48px; line-height: 1.45; }
h1 { font-size: 1.7em; margin: 0.6em 0 0.4em; }
h2 { font-size: 1.3em; margin-top: 1.8em; border-bottom: 1px solid #d0d4da; padding-bottom: 0.2em; }
table { border-collapse: collapse; margin: 0.6em 0 1em; font-size: 0.92em; }
th, td { border: 1px solid #d0d4da; padding: 3px 9px; text-align: left; vertical-align: top; }
th { background: #eef1f4; }
tbody tr:nth-child(even) { background: #f7f8fa; }
code { font-family: "DejaVu Sans Mono", monospace; font-size: 0.9em; background: #f0f2f4; padding: 0 3px; border-radius: 3px; }
pre { background: #f0f2f4; padding: 8px 12px; overflow-x: auto; }
pre code { background: none; padding: 0; }
img { max-width: 100%; height: auto; border: 1px solid #e2e5e9; }
nav.contents { font-size: 0.92em; margin: 0.4em 0 1em; }
nav.contents a { margin-right: 1.1em; white-space: nowrap; }
.viewer { width: 100%; height: 68vh; min-height: 420px; max-height: 960px; background: #1d1f23; }
.viewer canvas { display: block; }
.viewer-controls { display: flex; flex-wrap: wrap; gap: 6px 22px; align-items: center; margin: 8px 0; font-size: 0.92em; }
.viewer-controls input[type=range] { vertical-align: middle; width: 180px; }
#viewer-status { font-size: 0.92em; color: #4a4f57; }
.viewer-note { background: #fff4e0; border-left: 4px solid #ff8c00; padding: 8px 12px; }
.missing-image { color: #a02020; }
#script-errors { color: #a02020; background: #fff0f0; padding: 8px 12px; white-space: pre-wrap; }
)CSS";

// First in the page: every script error and console.error is kept and shown in #script-errors
// (a person sees it; a test reads it from the DOM).
const char* const kErrorCapture = R"JS(
(function () {
  'use strict';
  var seen = [];
  function show() {
    var box = document.getElementById('script-errors');
    if (!box) return;
    box.hidden = seen.length === 0;
    box.textContent = seen.join('\n');
  }
  function note(text) { seen.push(String(text)); show(); }
  window.addEventListener('error', function (e) {
    note('error: ' + e.message + (e.filename ? ' (' + e.filename.split('/').pop() + ':' + e.lineno + ')' : ''));
  });
  window.addEventListener('unhandledrejection', function (e) { note('unhandled rejection: ' + e.reason); });
  var consoleError = console.error;
  console.error = function () {
    note('console.error: ' + Array.prototype.map.call(arguments, String).join(' '));
    return consoleError.apply(console, arguments);
  };
  document.addEventListener('DOMContentLoaded', show);
})();
)JS";

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return {};
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string inDir(const std::string& dir, const std::string& file) {
  return fs::path(file).is_absolute() ? file : (fs::path(dir) / file).string();
}

// Script text that cannot end its <script> element early or open an HTML comment in it; the
// escapes mean the same inside JavaScript strings and regular expressions.
std::string scriptSafe(std::string js) {
  for (const auto& [from, to] : {std::make_pair(std::string("</script"), std::string("<\\/script")),
                                 std::make_pair(std::string("<!--"), std::string("<\\!--"))})
    for (size_t at = js.find(from); at != std::string::npos; at = js.find(from, at + to.size()))
      js.replace(at, from.size(), to);
  return js;
}

// The <h2 id="...">...</h2> of the page as links (found by hand: the page holds megabytes of
// inlined pictures, too much for std::regex).
std::string contents(const std::string& body) {
  static const std::regex tag("<[^>]*>");
  const std::string open = "<h2 id=\"";
  std::string nav;
  for (size_t at = body.find(open); at != std::string::npos; at = body.find(open, at + 1)) {
    const size_t id_end = body.find('"', at + open.size());
    const size_t text = body.find('>', id_end);
    const size_t end = body.find("</h2>", text);
    if (id_end == std::string::npos || text == std::string::npos || end == std::string::npos) break;
    nav += "<a href=\"#" + body.substr(at + open.size(), id_end - at - open.size()) + "\">" +
           std::regex_replace(body.substr(text + 1, end - text - 1), tag, "") + "</a>\n";
  }
  return nav.empty() ? "" : "<nav class=\"contents\">\n" + nav + "</nav>\n";
}

// The folder's own name ("h_room" for /tmp/h_room/).
std::string folderName(const std::string& dir) {
  fs::path p = fs::absolute(dir).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();
  return p.filename().string();
}

Trajectory readTrajectoryIfAny(const std::string& dir, std::string* name) {
  for (const char* f : {"trajectory.tum", "odometry.tum"}) {
    const std::string path = inDir(dir, f);
    if (!fs::exists(path)) continue;
    try {
      Trajectory t = readTum(path);
      if (!t.empty()) {
        *name = f;
        return t;
      }
    } catch (const std::exception&) {
      // a broken file: the next, or none
    }
  }
  return {};
}

std::vector<double> resetStamps(const std::string& dir) {
  std::vector<double> stamps;
  std::ifstream f(inDir(dir, "resets.json"));
  if (!f) return stamps;
  try {
    for (const auto& r : nlohmann::json::parse(f)) stamps.push_back(r.at("time").get<double>());
  } catch (const std::exception&) {
    stamps.clear();
  }
  return stamps;
}

std::string thousands(size_t n) {
  std::string s = std::to_string(n);
  for (int i = static_cast<int>(s.size()) - 3; i > 0; i -= 3) s.insert(static_cast<size_t>(i), ",");
  return s;
}

// The 3D section, or a note of why there is none; fills the counts and errors of `report`.
std::string mapSection(const std::string& dir, const HtmlOptions& o, bool have_three, HtmlReport* report) {
  ColouredPoints map;
  const std::string map_path = inDir(dir, o.colour_map);
  const std::string map_name = fs::path(o.colour_map).filename().string();
  std::string map_note;
  if (fs::exists(map_path)) {
    std::string error;
    if (!readPly(map_path, &map, &error)) {
      report->warnings.push_back("the RGB map is not in the 3D view: " + error);
      map_note = "The RGB map is not shown: " + escapeMarkup(error) + ".";
      map = {};
    }
  } else {
    map_note = "No RGB map in this run (no <code>" + escapeMarkup(map_name) + "</code>): the trajectory alone.";
  }
  std::string path_name;
  const Trajectory path = newestEpoch(readTrajectoryIfAny(dir, &path_name), resetStamps(dir));  // the map's epoch
  if (map.size() == 0 && path.empty()) return "";
  if (!have_three) {
    return "<section id=\"map-3d\">\n<h2 id=\"map-in-3d\">Map in 3D</h2>\n<p class=\"viewer-note\" "
           "id=\"viewer-status\" "
           "data-state=\"no-three\">No 3D view: it needs three.js from Debian's <code>libjs-three</code> when the page "
           "is made (<code>sudo apt-get install libjs-three</code>, then <code>livo-report html --dir DIR</code> "
           "again): "
           "<code>" +
           escapeMarkup(o.three_dir) +
           "/three.min.js</code> or its <code>examples/js/controls/OrbitControls.js"
           "</code> is missing. The rest of this report is complete.</p>\n</section>\n";
  }
  const ViewerScene scene = viewerScene(map, path, {}, o.viewer);
  report->viewer = true;
  report->points_shown = scene.size();
  report->map_points = scene.map_points;
  report->voxel_m = scene.voxel_m;
  std::string description;
  if (scene.size() > 0) {
    description = thousands(scene.size()) + " points of <code>" + escapeMarkup(map_name) + "</code>";
    description += scene.voxel_m > 0 ? " (of " + thousands(scene.map_points) + ": the first of each " +
                                           formatSignificant(scene.voxel_m, 3) + " m voxel)"
                                     : " (all of them)";
  } else {
    description = map_note;
  }
  if (!path.empty())
    description += std::string(scene.size() > 0 ? ", " : " ") + "the trajectory (<code>" + path_name +
                   "</code>) in cyan from the green dot to the red one";
  description +=
      ". Drag to turn, right-drag (or ctrl-drag) to pan, wheel to zoom; the cut leaves out what is "
      "above a height (a ceiling), the start view cuts 1 m above the trajectory.";
  if (!map_note.empty() && scene.size() > 0) description += " " + map_note;
  return viewerSection(scene, description);
}

}  // namespace

std::string dataUri(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const char* type = ext == ".png"                     ? "image/png"
                     : ext == ".jpg" || ext == ".jpeg" ? "image/jpeg"
                     : ext == ".gif"                   ? "image/gif"
                     : ext == ".svg"                   ? "image/svg+xml"
                     : ext == ".webp"                  ? "image/webp"
                                                       : nullptr;
  if (!type || !fs::is_regular_file(path)) return {};
  const std::string bytes = readFile(path);
  return std::string("data:") + type + ";base64," + base64Encode(bytes);
}

HtmlReport reportHtml(const std::string& dir, const HtmlOptions& options) {
  HtmlReport report;
  const std::string md_path = inDir(dir, "report.md");
  if (!fs::exists(md_path)) throw std::runtime_error(md_path + ": missing (livo-report markdown writes it)");
  const std::string markdown = readFile(md_path);

  MarkdownHtmlOptions md_options;
  md_options.image_source = [&](const std::string& src) -> std::string {
    if (src.rfind("data:image/", 0) == 0) return src;
    if (src.find("://") != std::string::npos) return {};  // nothing from a network
    const std::string uri = dataUri(inDir(dir, src));
    if (uri.empty()) report.warnings.push_back("the picture " + src + " is missing or not a picture");
    return uri;
  };
  std::string body = markdownToHtml(markdown, md_options);

  const std::string three = readFile(fs::path(options.three_dir) / "three.min.js");
  const std::string orbit = readFile(fs::path(options.three_dir) / "examples/js/controls/OrbitControls.js");
  const bool have_three = !three.empty() && !orbit.empty();
  const std::string section = mapSection(dir, options, have_three, &report);
  report.three_missing = !section.empty() && !have_three;
  // the 3D view right after the run's summary, before the first section; the contents under the title
  const size_t at = body.find("<h2");
  body.insert(at == std::string::npos ? body.size() : at, section);
  const size_t h1_end = body.find("</h1>\n");
  body.insert(h1_end == std::string::npos ? 0 : h1_end + 6, contents(body));

  std::string title = "Pipeline run";
  static const std::regex h1(R"(^# (.+)$)");
  std::smatch m;
  const std::string first_line = markdown.substr(0, markdown.find('\n'));
  if (std::regex_match(first_line, m, h1)) title = m[1].str();
  title += " - " + folderName(dir);

  std::string& html = report.html;
  html.reserve(body.size() + three.size() + orbit.size() + 16384);
  html += "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  html += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  html += "<meta name=\"generator\" content=\"livo-report html\">\n";
  html += "<title>" + escapeMarkup(title) + "</title>\n<style>" + std::string(kStyle) + "</style>\n";
  html += "<script>" + std::string(kErrorCapture) + "</script>\n";
  if (have_three && !section.empty()) {
    html += "<script>/* three.js r111 (Debian libjs-three, MIT licence) */\n" + scriptSafe(three) + "\n</script>\n";
    html += "<script>/* three.js OrbitControls (MIT licence) */\n" + scriptSafe(orbit) + "\n</script>\n";
  }
  html += "</head>\n<body>\n<main>\n<pre id=\"script-errors\" hidden></pre>\n";
  html += body;
  html += "</main>\n</body>\n</html>\n";
  return report;
}

}  // namespace livo::report
