#include "livo/report/run_pictures.hpp"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "livo/coloured_point_files.hpp"
#include "livo/file_output.hpp"
#include "livo/report/map_views.hpp"
#include "livo/report/picture_annotations.hpp"
#include "livo/report/trajectory_figure.hpp"
#include "livo/text_format.hpp"

namespace livo::report {

namespace {

namespace fs = std::filesystem;

const char* const kTrajectoryFile = "trajectory_top.svg";
const char* const kMapTopFile = "map_top.png";
const char* const kMapObliqueFile = "map_oblique.png";
const char* const kSliceFile = "octomap_slice.png";

std::string inDir(const std::string& dir, const std::string& file) {
  return fs::path(file).is_absolute() ? file : (fs::path(dir) / file).string();
}

std::string thousands(size_t n) {  // 79102 -> "79,102"
  std::string s = std::to_string(n);
  for (int i = static_cast<int>(s.size()) - 3; i > 0; i -= 3) s.insert(static_cast<size_t>(i), ",");
  return s;
}

std::string counted(size_t n, const char* one, const char* many) {
  return std::to_string(n) + " " + (n == 1 ? one : many);
}

std::string metres(double v) { return formatSignificant(v, 3) + " m"; }

void writePng(const std::string& path, const cv::Mat& image) {
  std::vector<uchar> bytes;
  if (!cv::imencode(".png", image, bytes, {cv::IMWRITE_PNG_COMPRESSION, 6}))
    throw std::runtime_error(path + ": cannot encode the picture");
  std::string error;
  if (!writeFileAtomically(path, {std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size())}, &error))
    throw std::runtime_error(error);
}

void writeText(const std::string& path, const std::string& text) {
  std::string error;
  if (!writeFileAtomically(path, {text}, &error)) throw std::runtime_error(error);
}

// A trajectory file of the run; empty (with a note) when it is missing or does not read.
Trajectory readRunTrajectory(const std::string& path, std::vector<std::string>* notes) {
  if (!fs::exists(path)) return {};
  try {
    return readTum(path);
  } catch (const std::exception& e) {
    notes->push_back("`" + fs::path(path).filename().string() + "` does not read: " + e.what());
    return {};
  }
}

struct RunFiles {
  Trajectory final_estimate, odometry;
  std::vector<double> reset_stamps;
  PlotMarks marks;
  bool has_marks = false;
  Trajectory map_path;  // path() since the last reset: the maps are of that epoch
  const Trajectory& path() const { return final_estimate.empty() ? odometry : final_estimate; }
  std::string pathName() const { return final_estimate.empty() ? "odometry.tum" : "trajectory.tum"; }
};

RunFiles readRunFiles(const std::string& dir, std::vector<std::string>* notes) {
  RunFiles r;
  r.final_estimate = readRunTrajectory(inDir(dir, "trajectory.tum"), notes);
  r.odometry = readRunTrajectory(inDir(dir, "odometry.tum"), notes);
  if (std::ifstream f(inDir(dir, "resets.json")); f) {
    try {
      for (const auto& reset : nlohmann::json::parse(f)) r.reset_stamps.push_back(reset.at("time").get<double>());
    } catch (const std::exception& e) {
      notes->push_back(std::string("`resets.json` does not read: ") + e.what());
    }
  }
  if (fs::exists(inDir(dir, "weak_spots.json"))) {
    try {
      r.marks = readPlotMarks(inDir(dir, "weak_spots.json"));
      r.has_marks = true;
    } catch (const std::exception& e) {
      notes->push_back(std::string("the weak spots are not marked: ") + e.what());
    }
  }
  r.map_path = newestEpoch(r.path(), r.reset_stamps);
  return r;
}

// The positions of at most ~kFramingSample points, evenly through the file: enough for the
// framing's percentiles and axis, without a copy of a map of millions.
constexpr size_t kFramingSample = 1'000'000;
std::vector<Vec3> framingSample(const ColouredPoints& points) {
  const size_t stride = points.size() / kFramingSample + 1;
  std::vector<Vec3> out;
  out.reserve(points.size() / stride + 1);
  for (size_t i = 0; i < points.size(); i += stride) out.push_back(points.position[i].cast<double>());
  return out;
}

void trajectoryPicture(const std::string& dir, const RunFiles& run, PictureSet* set) {
  if (run.path().empty()) {
    set->notes.push_back("No trajectory figure: neither `trajectory.tum` nor `odometry.tum` holds a pose.");
    return;
  }
  TrajectoryFigureInputs in;
  in.final_estimate = run.final_estimate;
  in.odometry = run.odometry;
  in.marks = run.marks;
  in.reset_stamps = run.reset_stamps;
  in.title = "Trajectory from above (" + run.pathName() + ", " + thousands(run.path().size()) + " poses)";
  writeText(inDir(dir, kTrajectoryFile), trajectoryTopSvg(in));
  std::string caption = "`" + run.pathName() + "` in blue";
  bool differs = run.final_estimate.size() != run.odometry.size();
  for (size_t i = 0; !differs && i < run.odometry.size(); ++i)
    differs = !(run.final_estimate[i].pose.translation() - run.odometry[i].pose.translation()).isZero(1e-6);
  if (!run.final_estimate.empty() && !run.odometry.empty() && differs)
    caption += ", the online `odometry.tum` in grey where it differs";
  if (!run.has_marks) {
    caption += "; no `weak_spots.json`, so no weak spots marked";
  } else if (run.marks.empty()) {
    caption += "; `weak_spots.json` has nothing to mark (no degenerate or predicted sweep, no loop closure)";
  } else {
    std::vector<std::string> marked;
    if (!run.marks.degenerate.empty())
      marked.push_back(counted(run.marks.degenerate.size(), "stretch", "stretches") +
                       " of degenerate sweeps in orange");
    if (!run.marks.predicted.empty())
      marked.push_back(counted(run.marks.predicted.size(), "stretch", "stretches") +
                       " of sweeps predicted without a LiDAR update in grey");
    if (!run.marks.loops.empty())
      marked.push_back(counted(run.marks.loops.size(), "loop closure", "loop closures") +
                       ", each a dashed magenta line between its keyframes");
    caption += "; where the estimate was weak (`weak_spots.json`): ";
    for (size_t i = 0; i < marked.size(); ++i) caption += (i ? ", " : "") + marked[i];
  }
  caption += ". Start: green dot, end: red square. Needs no ground truth.";
  set->pictures.push_back({kTrajectoryFile, "Trajectory from above", caption});
}

void colourMapPictures(const std::string& dir, const RunFiles& run, const TrajectoryHeight& height,
                       const PictureOptions& o, PictureSet* set) {
  const std::string path = inDir(dir, o.colour_map);
  const std::string name = "`" + fs::path(o.colour_map).filename().string() + "`";
  if (!fs::exists(path)) {
    set->notes.push_back("No RGB map pictures: no " + name +
                         " (livo-colour did not run: the rig has no camera, or "
                         "the run left it out).");
    return;
  }
  ColouredPoints all;
  std::string error;
  if (!readPly(path, &all, &error)) {
    set->notes.push_back("No RGB map pictures: " + error + ".");
    return;
  }
  const ColouredPoints points = height.empty() ? all : pointsBelowCut(all, height, o.cut_above_m);
  if (points.size() == 0) {
    set->notes.push_back("No RGB map pictures: " + name + " holds no point" + (all.size() ? " below the cut" : "") +
                         ".");
    return;
  }
  const std::vector<Vec3> xyz = framingSample(points);
  const Box3 box = withTrajectory(percentileBox(xyz), run.map_path);
  const std::string cut = height.empty() ? std::string("all points (no trajectory to cut the ceiling by)")
                                         : "points more than " + metres(o.cut_above_m) +
                                               " above the trajectory left out (ceilings, canopies)";
  const std::string what = name + ", " + thousands(all.size()) + " points; open it in CloudCompare or MeshLab";

  SplatStyle style;
  style.point_size_m = o.point_size_m;
  style.edl_strength = o.top_edl;
  const TopViewFrame frame = topViewFrame(box, o.long_side_px);
  cv::Mat top = renderTopView(points, frame, style);
  drawPathTopView(top, run.map_path, frame);
  drawScaleBar(top, frame.metres_per_pixel);
  drawAxesTopView(top);
  writePng(inDir(dir, kMapTopFile), top);
  set->pictures.push_back({kMapTopFile, "RGB map from above",
                           "the coloured points (" + what + ") from straight above, " + cut +
                               "; edges shaded by height steps. The trajectory in cyan from the green dot to the red "
                               "one."});

  style.edl_strength = o.oblique_edl;
  const PerspectiveView view = obliqueView(box, majorHorizontalAxis(xyz), o.long_side_px);
  cv::Mat1f depth;
  cv::Mat oblique = renderPerspective(points, view, style, &depth);
  drawPathPerspective(oblique, depth, run.map_path, view);
  writePng(inDir(dir, kMapObliqueFile), cropToContent(oblique, style.background, o.long_side_px / 40));
  set->pictures.push_back({kMapObliqueFile, "RGB map from the side",
                           "the same points seen from above one long side of the map (35 deg down), " +
                               std::string(height.empty() ? "all of them" : "the same cut") +
                               "; the trajectory in cyan where no point hides it."});
}

void octomapPicture(const std::string& dir, const RunFiles& run, const TrajectoryHeight& height,
                    const PictureOptions& o, PictureSet* set) {
  const std::string path = inDir(dir, o.octomap);
  const std::string name = "`" + fs::path(o.octomap).filename().string() + "`";
  if (!fs::exists(path)) {
    set->notes.push_back("No OctoMap slice: no " + name + " (livo-octomap did not run).");
    return;
  }
  if (height.empty()) {
    set->notes.push_back("No OctoMap slice: no trajectory to take the slice's heights from.");
    return;
  }
  std::unique_ptr<::octomap::OcTree> tree;
  try {
    tree = readOctomapBinary(path);
  } catch (const std::exception& e) {
    set->notes.push_back(std::string("No OctoMap slice: ") + e.what() + ".");
    return;
  }
  const std::vector<OccupiedVoxel> voxels = occupiedVoxelsInBand(*tree, height, o.band);
  if (voxels.empty()) {
    set->notes.push_back("No OctoMap slice: " + name + " has no occupied voxel within " + metres(o.band.below_m) +
                         " below and " + metres(o.band.above_m) + " above the trajectory.");
    return;
  }
  std::vector<Vec3> centres;
  for (const OccupiedVoxel& v : voxels) centres.push_back(v.centre);
  const TopViewFrame frame = topViewFrame(withTrajectory(percentileBox(centres), run.map_path), o.long_side_px);
  cv::Mat slice = renderSlice(voxels, frame, o.band);
  drawPathTopView(slice, run.map_path, frame);
  drawScaleBar(slice, frame.metres_per_pixel);
  drawAxesTopView(slice);
  writePng(inDir(dir, kSliceFile),
           withHeightLegend(slice, -o.band.below_m, o.band.above_m, "height above\nthe trajectory"));
  set->pictures.push_back(
      {kSliceFile, "OctoMap slice",
       "the occupied voxels of " + name + " (" + metres(tree->getResolution()) + ", " + thousands(voxels.size()) +
           " in the band; open it in `octovis`) from " + metres(o.band.below_m) + " below to " +
           metres(o.band.above_m) +
           " above the trajectory's height, from above, coloured by their height above the "
           "trajectory (the scale on the right); the highest voxel shows. The trajectory in cyan."});
}

}  // namespace

const std::vector<std::string>& pictureFiles() {
  static const std::vector<std::string> files = {kTrajectoryFile, kMapTopFile, kMapObliqueFile, kSliceFile};
  return files;
}

PictureSet makePictures(const std::string& dir, const PictureOptions& options, std::ostream* progress) {
  PictureSet set;
  const RunFiles run = readRunFiles(dir, &set.notes);
  const TrajectoryHeight height(run.map_path);
  // each picture on its own: one that fails costs only itself
  const std::pair<const char*, std::function<void()>> steps[] = {
      {"the trajectory figure", [&] { trajectoryPicture(dir, run, &set); }},
      {"the RGB map pictures", [&] { colourMapPictures(dir, run, height, options, &set); }},
      {"the OctoMap slice", [&] { octomapPicture(dir, run, height, options, &set); }},
  };
  for (const auto& [what, step] : steps) {
    const auto t0 = std::chrono::steady_clock::now();
    try {
      step();
    } catch (const std::exception& e) {
      set.notes.push_back(std::string("Could not draw ") + what + ": " + e.what() + ".");
    }
    if (progress)
      *progress << "livo-report pictures: " << what << ": "
                << formatFixed(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 2)
                << " s\n";
  }
  for (const std::string& f : pictureFiles()) {
    bool drawn = false;
    for (const Picture& p : set.pictures) drawn = drawn || p.file == f;
    std::error_code ec;
    if (!drawn) fs::remove(inDir(dir, f), ec);  // an earlier run's
  }
  return set;
}

}  // namespace livo::report
