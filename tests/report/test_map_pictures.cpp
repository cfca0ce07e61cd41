// The pictures of a run's maps against numbers: coloured planes land on the pixels they cover (top
// view and a pinhole camera, the nearer or higher one in front), the OctoMap slice of a known
// room keeps its walls and leaves out its floor and ceiling, the trajectory's height under a step,
// the trajectory figure's marks, and `livo-report pictures` on an empty and a synthetic run folder
// (every picture, nothing fatal when a map is missing, byte-identical twice).
#include <filesystem>
#include <fstream>
#include <set>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "livo/coloured_point_files.hpp"
#include "livo/report/map_views.hpp"
#include "livo/report/octomap_slice.hpp"
#include "livo/report/picture_annotations.hpp"
#include "livo/report/run_pictures.hpp"
#include "livo/report/trajectory_figure.hpp"
#include "report_fixtures.hpp"
#include "temp_path.hpp"

using namespace livo;
using namespace livo::report;
namespace fs = std::filesystem;
using livo_test::addPlane;

namespace {

const std::array<uint8_t, 3> kRed{220, 30, 30}, kGreen{30, 200, 40}, kBlue{20, 40, 230};

cv::Vec3b bgr(const std::array<uint8_t, 3>& rgb) { return {rgb[2], rgb[1], rgb[0]}; }

size_t countColour(const cv::Mat& image, const cv::Vec3b& c) {
  size_t n = 0;
  for (int v = 0; v < image.rows; ++v)
    for (int u = 0; u < image.cols; ++u) n += image.at<cv::Vec3b>(v, u) == c;
  return n;
}

Trajectory straightPath(double x0, double x1, double z, int n = 41) {
  Trajectory t;
  for (int i = 0; i < n; ++i) {
    Pose3 T = Pose3::Identity();
    T.translation() = Vec3(x0 + (x1 - x0) * i / (n - 1), 0.0, z);
    t.push_back({100.0 + 0.1 * i, T});
  }
  return t;
}

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

}  // namespace

TEST(MapPictures, TopViewPutsEachPlaneOnItsPixelsTheHigherInFront) {
  ColouredPoints pts;
  addPlane(&pts, 0.5, 1.0, 0.5, 1.0, 0.0, 0.01, kRed);        // 50 x 50 px
  addPlane(&pts, 0.75, 1.25, 0.75, 1.25, 0.5, 0.01, kGreen);  // above it, overlapping a quarter
  TopViewFrame f;
  f.x_min = 0.0, f.y_max = 2.0, f.metres_per_pixel = 0.01, f.width = 200, f.height = 200;
  SplatStyle style;
  style.point_size_m = 0.01;  // one pixel each
  cv::Mat1f top_z;
  const cv::Mat image = renderTopView(pts, f, style, &top_z);
  ASSERT_EQ(image.size(), cv::Size(200, 200));
  const auto at = [&](double x, double y) {
    const cv::Point2d p = f.pixel(x, y);
    return image.at<cv::Vec3b>(static_cast<int>(p.y), static_cast<int>(p.x));
  };
  EXPECT_EQ(at(0.6, 0.6), bgr(kRed));
  EXPECT_EQ(at(0.9, 0.9), bgr(kGreen));  // where both are: the higher
  EXPECT_EQ(at(1.2, 1.2), bgr(kGreen));
  EXPECT_EQ(at(1.5, 0.6), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(countColour(image, bgr(kRed)), 50u * 50u - 25u * 25u);
  EXPECT_EQ(countColour(image, bgr(kGreen)), 50u * 50u);
  // pixel (u, v) covers x in [u, u+1) cm and y down from 2 m: the red plane's corner pixel
  EXPECT_EQ(image.at<cv::Vec3b>(149, 50), bgr(kRed));  // x 0.50-0.51, y 0.50-0.51
  EXPECT_EQ(image.at<cv::Vec3b>(150, 50), cv::Vec3b(255, 255, 255));
  EXPECT_FLOAT_EQ(top_z(110, 100), 0.5f);
  EXPECT_TRUE(std::isnan(top_z(10, 10)));
}

TEST(MapPictures, PerspectiveViewDrawsTheNearerPlaneInFront) {
  ColouredPoints pts;
  addPlane(&pts, -1.0, 1.0, -1.0, 1.0, 0.0, 0.02, kRed);
  addPlane(&pts, 0.0, 1.0, 0.0, 1.0, 5.0, 0.02, kGreen);  // halfway up to the camera
  PerspectiveView view;  // 10 m above the origin, looking straight down, image x along world x
  view.position = Vec3(0, 0, 10);
  view.R_C_W << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  view.f = 100, view.cx = 100, view.cy = 100, view.width = 200, view.height = 200;
  SplatStyle style;
  style.point_size_m = 0.02;
  cv::Mat1f depth;
  const cv::Mat image = renderPerspective(pts, view, style, &depth);
  // red: u = 100 + 100 x / 10 in [90, 110]; green (5 m away): u = 100 + 100 x / 5 in [100, 120]
  EXPECT_EQ(image.at<cv::Vec3b>(95, 105), bgr(kGreen));  // v = 100 - 100 y / z: y > 0 is up
  EXPECT_EQ(image.at<cv::Vec3b>(108, 92), bgr(kRed));
  EXPECT_EQ(image.at<cv::Vec3b>(85, 115), bgr(kGreen));  // beyond the red square, the green one
  EXPECT_EQ(image.at<cv::Vec3b>(150, 150), cv::Vec3b(255, 255, 255));
  EXPECT_NEAR(depth(95, 105), 5.0f, 1e-4);
  EXPECT_NEAR(depth(108, 92), 10.0f, 1e-4);
  cv::Point2d px;
  double z = 0;
  EXPECT_FALSE(view.project(Vec3(0, 0, 11), &px, &z));  // behind the camera
}

TEST(MapPictures, ObliqueViewFramesTheBox) {
  Box3 box;
  box.min = Vec3(-20, -3, 0), box.max = Vec3(20, 3, 3);  // a long corridor along x
  const PerspectiveView v = obliqueView(box, majorHorizontalAxis({Vec3(-20, 0, 0), Vec3(20, 0.1, 0), Vec3(0, 1, 0)}));
  EXPECT_EQ(v.width, 1600);
  EXPECT_GE(v.height, 720);
  EXPECT_LE(v.height, 1280);
  double umin = 1e9, umax = -1e9, vmin = 1e9, vmax = -1e9;
  for (int k = 0; k < 8; ++k) {
    const Vec3 c((k & 1) ? box.max.x() : box.min.x(), (k & 2) ? box.max.y() : box.min.y(),
                 (k & 4) ? box.max.z() : box.min.z());
    cv::Point2d px;
    double z = 0;
    ASSERT_TRUE(v.project(c, &px, &z));
    umin = std::min(umin, px.x), umax = std::max(umax, px.x), vmin = std::min(vmin, px.y), vmax = std::max(vmax, px.y);
  }
  EXPECT_GE(umin, 0.0);
  EXPECT_LE(umax, v.width);
  EXPECT_GE(vmin, 0.0);
  EXPECT_LE(vmax, v.height);
  // it fills the image along its longer side (4 % margins)
  EXPECT_TRUE(std::abs(umax - umin - 0.92 * v.width) < 1.0 || std::abs(vmax - vmin - 0.92 * v.height) < 1.0);
  // the camera stands beside the corridor (across its axis, turned 30 deg), above it
  const Vec3 from_centre = v.position - box.centre();
  EXPECT_GT(std::abs(from_centre.y()), std::abs(from_centre.x()));
  EXPECT_GT(from_centre.z(), 0.0);
}

TEST(MapPictures, CropToContentKeepsTheDrawnPixelsAndAMargin) {
  const cv::Vec3b white(255, 255, 255);
  cv::Mat image(100, 200, CV_8UC3, cv::Scalar(255, 255, 255));
  image.at<cv::Vec3b>(20, 30) = cv::Vec3b(0, 0, 255);
  image.at<cv::Vec3b>(60, 150) = cv::Vec3b(0, 255, 0);
  const cv::Mat cut = cropToContent(image, white, 5);
  EXPECT_EQ(cut.cols, 150 - 30 + 1 + 10);
  EXPECT_EQ(cut.rows, 60 - 20 + 1 + 10);
  EXPECT_EQ(cut.at<cv::Vec3b>(5, 5), cv::Vec3b(0, 0, 255));
  EXPECT_EQ(cut.at<cv::Vec3b>(45, 125), cv::Vec3b(0, 255, 0));
  // the margin stops at the image's edge
  const cv::Mat edge = cropToContent(image, white, 50);
  EXPECT_EQ(edge.cols, 200);
  EXPECT_EQ(edge.rows, 100);
  // nothing drawn: the image as it was
  const cv::Mat blank(10, 10, CV_8UC3, cv::Scalar(255, 255, 255));
  EXPECT_EQ(cropToContent(blank, white, 2).size(), blank.size());
}

TEST(MapPictures, TrajectoryHeightFollowsTheNearestPose) {
  Trajectory t = straightPath(0.0, 4.0, 1.0, 21);
  Trajectory up = straightPath(10.0, 14.0, 3.0, 21);
  t.insert(t.end(), up.begin(), up.end());
  const TrajectoryHeight h(t, 20.0, 0.5);
  EXPECT_NEAR(h.at(2.0, 0.0), 1.0, 1e-6);
  EXPECT_NEAR(h.at(2.0, 5.0), 1.0, 1e-6);    // beside the low part
  EXPECT_NEAR(h.at(13.0, -6.0), 3.0, 1e-6);  // beside the high part
  EXPECT_NEAR(h.at(500.0, 0.0), 3.0, 1e-6);  // beyond the grid: its border
  EXPECT_DOUBLE_EQ(h.minimum(), 1.0);
  EXPECT_DOUBLE_EQ(h.maximum(), 3.0);
  EXPECT_TRUE(TrajectoryHeight().empty());
  EXPECT_EQ(TrajectoryHeight().at(1.0, 2.0), 0.0);
  // the ceiling cut relative to it
  ColouredPoints p;
  addPlane(&p, 0.0, 4.0, 0.0, 1.0, 1.8, 0.5, kRed);      // below 1 + 1 m: kept
  addPlane(&p, 0.0, 4.0, 0.0, 1.0, 2.5, 0.5, kBlue);     // the low part's ceiling: cut
  addPlane(&p, 10.0, 14.0, 0.0, 1.0, 2.5, 0.5, kGreen);  // as high, over the high part: kept
  const ColouredPoints kept = pointsBelowCut(p, h, 1.0);
  EXPECT_EQ(kept.size(), 16u + 16u);
  for (const auto& c : kept.rgb) EXPECT_NE(c, kBlue);
}

TEST(MapPictures, OctomapSliceOfARoomKeepsTheWallsNotFloorOrCeiling) {
  ::octomap::OcTree tree(0.1);
  auto occupy = [&](double x, double y, double z) { tree.updateNode(::octomap::point3d(x, y, z), true); };
  // a 4 x 4 m room, floor at z 0, ceiling at 3 m, one wall along y = 2 (centres of 0.1 m voxels)
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) {
      occupy(0.05 + 0.1 * i, -1.95 + 0.1 * j, 0.05);
      occupy(0.05 + 0.1 * i, -1.95 + 0.1 * j, 2.95);
    }
  for (int i = 0; i < 40; ++i)
    for (int k = 1; k < 29; ++k) occupy(0.05 + 0.1 * i, 1.95, 0.05 + 0.1 * k);
  const Trajectory path = straightPath(0.5, 3.5, 1.5);
  const TrajectoryHeight height(path);
  const SliceBand band;  // 0.5 below, 1.0 above: z in [1.0, 2.5]
  const std::vector<OccupiedVoxel> voxels = occupiedVoxelsInBand(tree, height, band);
  ASSERT_FALSE(voxels.empty());
  std::set<int> layers;
  for (const OccupiedVoxel& v : voxels) {
    EXPECT_NEAR(v.centre.y(), 1.95, 1e-3) << "only the wall, no floor or ceiling voxel";
    EXPECT_GE(v.height, -band.below_m);
    EXPECT_LE(v.height, band.above_m);
    layers.insert(static_cast<int>(std::floor(v.centre.z() * 10)));
  }
  EXPECT_EQ(*layers.begin(), 10);  // 1.0-1.1 m: the first voxel within the band (9 only touches it)
  EXPECT_EQ(*layers.rbegin(), 24);
  EXPECT_EQ(voxels.size(), 40u * 15u);

  TopViewFrame f;
  f.x_min = -1.0, f.y_max = 3.0, f.metres_per_pixel = 0.05, f.width = 120, f.height = 120;
  const cv::Mat image = renderSlice(voxels, f, band);
  // the wall: y 1.9-2.0 is rows (3 - 2.0) / 0.05 = 20 and 21; columns of x 0-4 m: 20-99
  double highest = -1.0;
  for (const OccupiedVoxel& v : voxels) highest = std::max(highest, v.height);
  EXPECT_NEAR(highest, 2.45 - 1.5, 1e-6);
  const cv::Vec3b top = heightColour((highest + 0.5) / 1.5);  // the highest voxel shows
  EXPECT_EQ(image.at<cv::Vec3b>(20, 40), top);
  EXPECT_EQ(image.at<cv::Vec3b>(21, 99), top);
  EXPECT_EQ(image.at<cv::Vec3b>(21, 100), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(image.at<cv::Vec3b>(22, 40), cv::Vec3b(255, 255, 255));
  EXPECT_EQ(image.at<cv::Vec3b>(60, 60), cv::Vec3b(255, 255, 255));  // over the floor: nothing
  EXPECT_EQ(countColour(image, top), 80u * 2u);
  // the legend widens the picture and keeps it
  const cv::Mat legend = withHeightLegend(image, -0.5, 1.0, "height");
  EXPECT_EQ(legend.rows, image.rows);
  EXPECT_GT(legend.cols, image.cols);
  EXPECT_EQ(legend.at<cv::Vec3b>(20, 40), top);
}

TEST(MapPictures, ScaleBarLengthsAreRound) {
  EXPECT_DOUBLE_EQ(roundLength(7.3), 5.0);
  EXPECT_DOUBLE_EQ(roundLength(0.031), 0.02);
  EXPECT_DOUBLE_EQ(roundLength(100.0), 100.0);
  EXPECT_EQ(lengthLabel(20.0), "20 m");
  EXPECT_EQ(lengthLabel(0.5), "50 cm");
  EXPECT_EQ(lengthLabel(2000.0), "2 km");
}

TEST(MapPictures, PathPiecesBreakAtResetsAndGapsTheMapsTakeTheNewestEpoch) {
  Trajectory t = straightPath(0.0, 4.0, 1.0, 41);  // stamps 100.0 .. 104.0
  EXPECT_EQ(pathPieces(t), (std::vector<std::pair<size_t, size_t>>{{0, 41}}));
  EXPECT_EQ(pathPieces(t, {102.05}), (std::vector<std::pair<size_t, size_t>>{{0, 21}, {21, 41}}));
  t[30].pose.translation().x() += 50.0;  // a jump away and back
  EXPECT_EQ(pathPieces(t), (std::vector<std::pair<size_t, size_t>>{{0, 30}, {30, 31}, {31, 41}}));
  t[30].pose.translation().x() = NAN;
  EXPECT_EQ(pathPieces(t), (std::vector<std::pair<size_t, size_t>>{{0, 30}, {31, 41}}));
  // the maps are of the newest epoch: the poses from the last reset on
  EXPECT_EQ(newestEpoch(t, {}).size(), 41u);
  const Trajectory newest = newestEpoch(t, {103.05, 101.05});
  ASSERT_EQ(newest.size(), 10u);
  EXPECT_DOUBLE_EQ(newest.front().stamp, t[31].stamp);
}

TEST(MapPictures, TrajectoryFigureMarksOnlyWhatIsThere) {
  TrajectoryFigureInputs in;
  in.final_estimate = straightPath(0.0, 10.0, 0.0, 101);
  in.odometry = in.final_estimate;
  in.title = "Trajectory from above";
  const std::string plain = trajectoryTopSvg(in);
  EXPECT_EQ(plain.rfind("<svg", 0), 0u);
  EXPECT_NE(plain.find("trajectory (trajectory.tum)"), std::string::npos);
  EXPECT_EQ(plain.find("degenerate sweeps"), std::string::npos);
  EXPECT_EQ(plain.find("online odometry"), std::string::npos);  // equal to the final: not drawn twice

  in.odometry[50].pose.translation().y() += 0.5;
  in.marks.degenerate = {{102.0, 103.0}};
  in.marks.predicted = {{105.0, 105.0}};
  in.marks.loops.push_back({108.0, 101.0, 108.0});
  in.reset_stamps = {109.05};
  const std::string marked = trajectoryTopSvg(in);
  for (const char* part : {"degenerate sweeps", "predicted, no LiDAR update", "loop closure", "online odometry",
                           "stroke=\"#ff8c00\"", "stroke=\"#c51b7d\" stroke-width=\"1.8\" stroke-dasharray=\"6,3\""})
    EXPECT_NE(marked.find(part), std::string::npos) << part;
  // the reset breaks the estimate into two polylines
  size_t estimate_lines = 0;
  for (size_t at = marked.find("stroke=\"#1f77b4\" stroke-width=\"1.8\" stroke-linejoin"); at != std::string::npos;
       at = marked.find("stroke=\"#1f77b4\" stroke-width=\"1.8\" stroke-linejoin", at + 1))
    ++estimate_lines;
  EXPECT_EQ(estimate_lines, 2u);
  EXPECT_THROW(trajectoryTopSvg(TrajectoryFigureInputs{}), std::invalid_argument);
}

TEST(MapPictures, AnEmptyRunFolderGivesNotesNotErrors) {
  const std::string dir = livo_test::tempPath("empty_run");
  fs::create_directories(dir);
  std::ofstream(dir + "/map_top.png") << "an earlier run's";
  const PictureSet set = makePictures(dir);
  EXPECT_TRUE(set.pictures.empty());
  ASSERT_EQ(set.notes.size(), 3u);
  EXPECT_NE(set.notes[0].find("No trajectory figure"), std::string::npos);
  EXPECT_NE(set.notes[1].find("no `colour_map.ply`"), std::string::npos);
  EXPECT_NE(set.notes[2].find("no `octomap.bt`"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir + "/map_top.png")) << "a picture not drawn again is removed";
  const PictureSet back = picturesFromJson(picturesJson(set));
  EXPECT_EQ(back.notes, set.notes);
  EXPECT_NE(mapsMarkdown(set).find("## Maps"), std::string::npos);
}

TEST(MapPictures, ASyntheticRunGetsEveryPictureByteIdenticalTwice) {
  // a 6 x 4 m room: red floor, green walls, blue ceiling at 2.5 m; the path at 1.2 m
  ColouredPoints room;
  addPlane(&room, 0.0, 6.0, 0.0, 4.0, 0.0, 0.05, kRed);
  addPlane(&room, 0.0, 6.0, 0.0, 4.0, 2.5, 0.05, kBlue);
  for (double z = 0.025; z < 2.5; z += 0.05) {
    addPlane(&room, 0.0, 6.0, 3.95, 4.0, z, 0.05, kGreen);
    addPlane(&room, 0.0, 6.0, 0.0, 0.05, z, 0.05, kGreen);
  }
  Trajectory path = straightPath(0.5, 5.5, 1.2, 51);
  for (auto& p : path) p.pose.translation().y() = 2.0;
  ::octomap::OcTree tree(0.1);
  for (const auto& p : room.position) tree.updateNode(::octomap::point3d(p.x(), p.y(), p.z()), true);

  std::vector<std::string> dirs = {livo_test::tempPath("run_a"), livo_test::tempPath("run_b")};
  for (const std::string& dir : dirs) {
    fs::create_directories(dir);
    std::string error;
    ASSERT_TRUE(writePly(dir + "/colour_map.ply", room, &error)) << error;
    ASSERT_TRUE(tree.writeBinary(dir + "/octomap.bt"));
    writeTum(dir + "/trajectory.tum", path);
    writeTum(dir + "/odometry.tum", path);
    std::ofstream(dir + "/weak_spots.json")
        << R"({"degenerate": {"spans": [{"from": 101.0, "to": 102.0}]}, "predicted": {"spans": []}, "loops": []})";
    const PictureSet set = makePictures(dir);
    ASSERT_EQ(set.pictures.size(), 4u) << (set.notes.empty() ? "" : set.notes.front());
    EXPECT_TRUE(set.notes.empty()) << set.notes.front();
  }
  for (const std::string& f : pictureFiles()) {
    const std::string a = readBytes(dirs[0] + "/" + f), b = readBytes(dirs[1] + "/" + f);
    EXPECT_FALSE(a.empty()) << f;
    EXPECT_EQ(a, b) << f << " differs between two runs of the same folder";
  }
  const cv::Mat top = cv::imread(dirs[0] + "/map_top.png");
  ASSERT_FALSE(top.empty());
  EXPECT_EQ(std::max(top.cols, top.rows), 1600);
  // from above: the floor and the walls' tops, never the ceiling (cut 1 m above the path)
  size_t reddish = 0, greenish = 0, bluish = 0;
  for (int v = 0; v < top.rows; ++v)
    for (int u = 0; u < top.cols; ++u) {
      const cv::Vec3b c = top.at<cv::Vec3b>(v, u);
      reddish += c[2] > 150 && c[1] < 80 && c[0] < 80;
      greenish += c[1] > 150 && c[2] < 80 && c[0] < 80;
      bluish += c[0] > 150 && c[1] < 80 && c[2] < 80;
    }
  EXPECT_GT(reddish, 100000u);
  EXPECT_GT(greenish, 1000u);
  EXPECT_EQ(bluish, 0u);
  const cv::Mat oblique = cv::imread(dirs[0] + "/map_oblique.png");
  ASSERT_FALSE(oblique.empty());
  EXPECT_LE(oblique.cols, 1600);  // cut to what was drawn
  EXPECT_GT(oblique.cols, 1000);
  const cv::Mat slice = cv::imread(dirs[0] + "/octomap_slice.png");
  ASSERT_FALSE(slice.empty());
  const std::string svg = readBytes(dirs[0] + "/trajectory_top.svg");
  EXPECT_NE(svg.find("degenerate sweeps"), std::string::npos);
  const std::string md = mapsMarkdown(picturesFromJson(picturesJson(makePictures(dirs[0]))));
  for (const char* f : {"(trajectory_top.svg)", "(map_top.png)", "(map_oblique.png)", "(octomap_slice.png)"})
    EXPECT_NE(md.find(f), std::string::npos) << f;
}
