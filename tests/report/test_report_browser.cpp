// report.html in a real browser: headless Chromium opens a synthetic run's page from file:// (its
// network off: inside scripts/private_bus.sh's namespace, which has no route out, and with its
// background networking switched off), WebGL on SwiftShader (no GPU needed). The page must draw the
// RGB map (the 3D canvas shows the map's colours, not only its background) and log no script
// error (the page keeps every error and console.error in #script-errors, read from the DOM).
// Skipped, saying so, only when chromium is not installed; scripts/install_deps.sh installs it.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "livo/report/html_report.hpp"
#include "livo/report/run_pictures.hpp"
#include "livo/report/run_report.hpp"
#include "report_fixtures.hpp"
#include "temp_path.hpp"

using namespace livo;
using namespace livo::report;
namespace fs = std::filesystem;
using livo_test::addPlane;

namespace {

constexpr int kWidth = 1280, kHeight = 1400;  // the browser window; the canvas sits inside it

std::string shellQuote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::string findChromium() {
  if (const char* env = std::getenv("LIVO_CHROMIUM"); env && *env) return env;
  for (const char* name : {"chromium", "chromium-browser", "google-chrome"})
    for (const char* dir : {"/usr/bin", "/usr/local/bin", "/snap/bin"})
      if (fs::exists(fs::path(dir) / name)) return (fs::path(dir) / name).string();
  return "";
}

int run(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// A run folder as run_pipeline.sh leaves it: a 6 x 4 m room (red floor, green walls), the path
/// through it, its pictures and report.md, and report.html.
std::string makeRun(const std::string& dir) {
  fs::create_directories(dir);
  ColouredPoints room;
  addPlane(&room, 0.0, 6.0, 0.0, 4.0, 0.0, 0.04, {220, 40, 40});
  for (double z = 0.02; z < 2.4; z += 0.04) {
    addPlane(&room, 0.0, 6.0, 3.96, 4.0, z, 0.04, {40, 200, 60});
    addPlane(&room, 5.96, 6.0, 0.0, 4.0, z, 0.04, {40, 200, 60});
  }
  std::string error;
  EXPECT_TRUE(writePly(dir + "/colour_map.ply", room, &error)) << error;
  Trajectory path;
  for (int i = 0; i <= 100; ++i) {
    Pose3 T = Pose3::Identity();
    T.translation() = Vec3(0.5 + 0.05 * i, 2.0 + 0.8 * std::sin(0.06 * i), 1.2);
    path.push_back({50.0 + 0.1 * i, T});
  }
  writeTum(dir + "/trajectory.tum", path);
  writeTum(dir + "/odometry.tum", path);
  ReportInputs in;
  in.run.log = "room.lcmlog";
  in.run.config = "room.yaml";
  in.run.processes = {"lio", "colour"};
  in.run.mode = "lockstep";
  in.timing = nlohmann::json::object();
  in.pictures = makePictures(dir);
  std::ofstream(dir + "/report.md") << reportMarkdown(in);
  const HtmlReport page = reportHtml(dir);
  EXPECT_FALSE(page.three_missing) << "three.js is missing: sudo apt-get install libjs-three";
  std::ofstream(dir + "/report.html", std::ios::binary) << page.html;
  return dir + "/report.html";
}

}  // namespace

TEST(ReportBrowser, ChromiumDrawsTheMapWithoutScriptErrors) {
  const std::string chromium = findChromium();
  if (chromium.empty())
    GTEST_SKIP()
        << "chromium is not installed (scripts/install_deps.sh installs it): report.html was not opened in a browser";
  ASSERT_TRUE(fs::exists("/usr/share/javascript/three/three.min.js"))
      << "three.js is missing: sudo apt-get install libjs-three (scripts/install_deps.sh installs it)";
  const std::string dir = livo_test::tempPath("browser_run");
  const std::string page = makeRun(dir);
  const std::string home = dir + "/home";
  fs::create_directories(home);

  // On a private network namespace when we can make one (no route out), else the flags alone.
  const std::string bus = std::string(LIVO_SOURCE_DIR) + "/scripts/private_bus.sh";
  const bool isolated = run(shellQuote(bus) + " true >/dev/null 2>&1") == 0;
  if (!isolated)
    std::cerr << "note: no private network namespace here; Chromium's networking is off by its flags only\n";
  std::string base = "env HOME=" + shellQuote(home) + " XDG_CONFIG_HOME=" + shellQuote(home) +
                     " XDG_CACHE_HOME=" + shellQuote(home) + " " + (isolated ? shellQuote(bus) + " " : "") +
                     "timeout --kill-after=5 60 " + shellQuote(chromium) +
                     " --headless --use-angle=swiftshader --enable-unsafe-swiftshader --user-data-dir=" +
                     shellQuote(dir + "/profile") +
                     " --no-first-run --no-default-browser-check --disable-background-networking"
                     " --disable-component-update --disable-sync --disable-default-apps --disable-extensions"
                     " --disable-domain-reliability --disable-client-side-phishing-detection"
                     " --disable-features=Translate,MediaRouter,OptimizationHints,AutofillServerCommunication"
                     " --metrics-recording-only --no-pings --enable-logging=stderr --v=0 --hide-scrollbars"
                     " --force-device-scale-factor=1 --window-size=" +
                     std::to_string(kWidth) + "," + std::to_string(kHeight);
  // Chromium refuses to run as root with its sandbox, and inside private_bus.sh's user namespace
  // it is root; the page is our own file and the network is off, so no sandbox is needed.
  base += " --no-sandbox";
  const std::string url = " " + shellQuote("file://" + fs::absolute(page).string());

  // 1. The DOM once the page has run: no script error, the view drawn, where its canvas is.
  ASSERT_EQ(
      run(base + " --dump-dom" + url + " >" + shellQuote(dir + "/dom.html") + " 2>" + shellQuote(dir + "/dom.log")), 0)
      << readText(dir + "/dom.log");
  const std::string dom = readText(dir + "/dom.html");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(dom, m, std::regex(R"(<pre id="script-errors"[^>]*>([^<]*)</pre>)")))
      << "no #script-errors";
  EXPECT_EQ(m[1].str(), "") << "script errors in report.html";
  ASSERT_TRUE(std::regex_search(dom, m, std::regex(R"(<p id="viewer-status"[^>]*>)")));
  const std::string status_tag = m[0].str();
  EXPECT_NE(status_tag.find("data-state=\"drawn\""), std::string::npos)
      << status_tag << "\n"
      << dom.substr(dom.find("id=\"viewer-status\""), 400);
  ASSERT_TRUE(std::regex_search(status_tag, m, std::regex(R"re(data-canvas-rect="(\d+),(\d+),(\d+),(\d+)")re")))
      << status_tag;
  const cv::Rect canvas(std::stoi(m[1]), std::stoi(m[2]), std::stoi(m[3]), std::stoi(m[4]));
  ASSERT_GT(canvas.area(), 400 * 300);
  EXPECT_EQ(readText(dir + "/dom.log").find("Uncaught"), std::string::npos) << readText(dir + "/dom.log");

  // 2. What it looks like: the canvas holds the map's colours, not only its background.
  const std::string shot = dir + "/screenshot.png";
  ASSERT_EQ(run(base + " --screenshot=" + shellQuote(shot) + url + " >" + shellQuote(dir + "/shot.log") + " 2>&1"), 0)
      << readText(dir + "/shot.log");
  EXPECT_EQ(readText(dir + "/shot.log").find("Uncaught"), std::string::npos) << readText(dir + "/shot.log");
  const cv::Mat image = cv::imread(shot, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty()) << "no screenshot";
  ASSERT_EQ(image.cols, kWidth);
  const cv::Rect seen = canvas & cv::Rect(0, 0, image.cols, image.rows);
  ASSERT_GT(seen.area(), canvas.area() / 2) << "the canvas is off the screenshot: " << canvas;
  const cv::Vec3b background(0x23, 0x1f, 0x1d);  // BGR of the scene's 0x1d1f23
  size_t drawn = 0, red = 0, green = 0;
  for (int v = seen.y; v < seen.y + seen.height; ++v)
    for (int u = seen.x; u < seen.x + seen.width; ++u) {
      const cv::Vec3b c = image.at<cv::Vec3b>(v, u);
      const int diff = std::abs(c[0] - background[0]) + std::abs(c[1] - background[1]) + std::abs(c[2] - background[2]);
      drawn += diff > 60;
      red += c[2] > 150 && c[1] < 90 && c[0] < 90;
      green += c[1] > 140 && c[2] < 90 && c[0] < 110;
    }
  const double area = seen.area();
  std::cout << "canvas " << canvas << ": " << 100.0 * drawn / area << " % drawn, " << 100.0 * red / area << " % red, "
            << 100.0 * green / area << " % green\n";
  EXPECT_GT(drawn, 0.10 * area) << "the 3D canvas is (nearly) blank";
  EXPECT_GT(red, 0.03 * area) << "the red floor is not in the 3D view";
  EXPECT_GT(green, 0.005 * area) << "the green walls are not in the 3D view";
}
