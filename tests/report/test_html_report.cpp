// report.html: base64 against RFC 4648's vectors, the 3D view's thinning (few enough points, the
// same every time, positions and colours kept), and the page: self-contained (pictures inlined,
// no network source), three.js inlined, byte-identical twice, written all the same without three.js.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "livo/report/base64.hpp"
#include "livo/report/html_report.hpp"
#include "temp_path.hpp"

using namespace livo;
using namespace livo::report;
namespace fs = std::filesystem;

namespace {

ColouredPoints planeOfPoints(int n_side, double step) {
  ColouredPoints p;
  for (int i = 0; i < n_side; ++i)
    for (int j = 0; j < n_side; ++j) {
      p.position.emplace_back(static_cast<float>(1000.0 + i * step), static_cast<float>(-500.0 + j * step), 2.0f);
      p.rgb.push_back({static_cast<uint8_t>(i % 256), static_cast<uint8_t>(j % 256), 7});
    }
  return p;
}

Trajectory pathAlongX(double x0, double x1, double y, double z) {
  Trajectory t;
  for (int i = 0; i <= 100; ++i) {
    Pose3 T = Pose3::Identity();
    T.translation() = Vec3(x0 + (x1 - x0) * i / 100.0, y, z);
    t.push_back({10.0 + 0.1 * i, T});
  }
  return t;
}

// A run folder with a report, a picture and an RGB map.
std::string runFolder(const std::string& name) {
  const std::string dir = livo_test::tempPath(name);
  fs::create_directories(dir);
  std::ofstream(dir + "/report.md")
      << "# Pipeline run\n\n| | |\n| --- | --- |\n| log | `x.lcmlog` |\n\n## Accuracy\n\n"
         "![a figure](figure.svg)\n\n![gone](missing.png)\n\n![remote](https://example.com/x.png)\n\n"
         "## Warnings\n\nNone.\n";
  std::ofstream(dir + "/figure.svg") << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"10\" height=\"10\"/>\n";
  std::string error;
  EXPECT_TRUE(writePly(dir + "/colour_map.ply", planeOfPoints(100, 0.05), &error)) << error;
  writeTum(dir + "/trajectory.tum", pathAlongX(1000.0, 1005.0, -498.0, 3.0));
  return dir;
}

}  // namespace

TEST(HtmlReport, Base64OfTheRfcVectors) {
  EXPECT_EQ(base64Encode(""), "");
  EXPECT_EQ(base64Encode("f"), "Zg==");
  EXPECT_EQ(base64Encode("fo"), "Zm8=");
  EXPECT_EQ(base64Encode("foo"), "Zm9v");
  EXPECT_EQ(base64Encode("foob"), "Zm9vYg==");
  EXPECT_EQ(base64Encode("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64Encode("foobar"), "Zm9vYmFy");
  const uint8_t high[] = {0xff, 0xfe, 0x00};
  EXPECT_EQ(base64Encode(high, 3), "//4A");
}

TEST(HtmlReport, ViewerSceneThinsToTheCapTheSameEveryTime) {
  const ColouredPoints map = planeOfPoints(300, 0.01);  // 90,000 points, 1 cm apart
  const Trajectory path = pathAlongX(1000.0, 1003.0, -499.0, 3.5);
  ViewerOptions o;
  o.max_points = 10'000;
  const ViewerScene a = viewerScene(map, path, {}, o), b = viewerScene(map, path, {}, o);
  EXPECT_EQ(a.map_points, 90'000u);
  EXPECT_LE(a.size(), 10'000u);
  EXPECT_GT(a.size(), 2'000u);  // the finest grid that fits, not a much coarser one
  EXPECT_GT(a.voxel_m, 0.0);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.colours, b.colours);
  EXPECT_EQ(a.positions.size(), 3 * a.size());
  // positions relative to a round origin near the map; colours go with their points
  EXPECT_EQ(a.origin, a.origin.array().round().matrix().eval());
  EXPECT_NEAR(a.origin.x(), 1001.5, 0.6);
  EXPECT_NEAR(a.origin.y(), -498.5, 0.6);
  EXPECT_EQ(a.origin.z(), 2.0);
  for (size_t k = 0; k < a.size(); k += 97) {
    const double x = a.positions[3 * k] + a.origin.x(), y = a.positions[3 * k + 1] + a.origin.y();
    const int i = static_cast<int>(std::lround((x - 1000.0) / 0.01)),
              j = static_cast<int>(std::lround((y + 500.0) / 0.01));
    EXPECT_EQ(a.colours[3 * k], i % 256);
    EXPECT_EQ(a.colours[3 * k + 1], j % 256);
  }
  EXPECT_EQ(a.path_pieces, std::vector<uint32_t>{51});  // 3 cm steps, kept 5 cm apart: every second
  // the start view looks at the map from above
  EXPECT_GT(a.camera.z(), a.target.z());
  // below the cap: every point
  o.max_points = 100'000;
  const ViewerScene all = viewerScene(map, path, {}, o);
  EXPECT_EQ(all.size(), 90'000u);
  EXPECT_EQ(all.voxel_m, 0.0);
}

TEST(HtmlReport, APageWithNothingFromANetworkTheSameTwice) {
  ASSERT_TRUE(fs::exists("/usr/share/javascript/three/three.min.js"))
      << "three.js is missing: sudo apt-get install libjs-three (scripts/install_deps.sh installs it)";
  const std::string dir = runFolder("html_run");
  const HtmlReport page = reportHtml(dir);
  const std::string& html = page.html;
  EXPECT_FALSE(page.three_missing);
  EXPECT_EQ(page.points_shown, 10'000u);
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("<img src=\"data:image/svg+xml;base64,"), std::string::npos);
  EXPECT_NE(html.find("<span class=\"missing-image\">[gone: missing.png]</span>"), std::string::npos);
  EXPECT_NE(html.find("<span class=\"missing-image\">[remote: https://example.com/x.png]</span>"), std::string::npos);
  ASSERT_EQ(page.warnings.size(), 1u);
  EXPECT_NE(page.warnings[0].find("missing.png"), std::string::npos);
  EXPECT_NE(html.find("REVISION=\"111\""), std::string::npos) << "three.js inlined";
  EXPECT_NE(html.find("OrbitControls"), std::string::npos);
  EXPECT_NE(html.find("<h2 id=\"map-in-3d\">Map in 3D</h2>"), std::string::npos);
  EXPECT_LT(html.find("id=\"map-in-3d\""), html.find("id=\"accuracy\"")) << "the 3D view before the first section";
  EXPECT_NE(html.find("<a href=\"#accuracy\">Accuracy</a>"), std::string::npos) << "the contents";
  // nothing the browser would fetch: no external script, style, frame or picture
  for (const char* fetch : {"src=\"http", "src='http", "<link", "<iframe", "@import", "url(http"})
    EXPECT_EQ(html.find(fetch), std::string::npos) << fetch;
  EXPECT_EQ(reportHtml(dir).html, html) << "the same folder gives the same page";
}

TEST(HtmlReport, WithoutThreeJsThePageIsWrittenWithANote) {
  const std::string dir = runFolder("html_no_three");
  HtmlOptions o;
  o.three_dir = livo_test::tempPath("no_three_here");
  const HtmlReport page = reportHtml(dir, o);
  EXPECT_TRUE(page.three_missing);
  EXPECT_NE(page.html.find("libjs-three"), std::string::npos);
  EXPECT_NE(page.html.find("The rest of this report is complete."), std::string::npos);
  EXPECT_NE(page.html.find("<h2 id=\"warnings\">Warnings</h2>"), std::string::npos);
  EXPECT_EQ(page.html.find("livo-positions"), std::string::npos) << "no point data without a viewer";
  // no map and no trajectory: no 3D section, nothing missing
  const std::string bare = livo_test::tempPath("html_bare");
  fs::create_directories(bare);
  std::ofstream(bare + "/report.md") << "# Pipeline run\n\n## Warnings\n\nNone.\n";
  const HtmlReport plain = reportHtml(bare, o);
  EXPECT_FALSE(plain.three_missing);
  EXPECT_EQ(plain.html.find("map-in-3d"), std::string::npos);
  EXPECT_THROW(reportHtml(livo_test::tempPath("no_such_run")), std::runtime_error);
}

TEST(HtmlReport, DataUrisByExtension) {
  const std::string dir = livo_test::tempPath("uris");
  fs::create_directories(dir);
  std::ofstream(dir + "/a.PNG") << "abc";
  std::ofstream(dir + "/b.txt") << "abc";
  EXPECT_EQ(dataUri(dir + "/a.PNG"), "data:image/png;base64,YWJj");
  EXPECT_EQ(dataUri(dir + "/b.txt"), "");
  EXPECT_EQ(dataUri(dir + "/c.png"), "");
}
