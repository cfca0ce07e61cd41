// livo-evaluate end to end: the table, JSON, SVG and Markdown outputs, EuRoC csv input, and exit
// codes with clear messages on bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <sstream>

#include <nlohmann/json.hpp>

#include "evaluate_command_runner.hpp"
#include "livo/evaluate/evaluate_command.hpp"
#include "livo/trajectory_io.hpp"
#include "synthetic_trajectory.hpp"
#include "temp_path.hpp"

using namespace livo;

namespace {

const std::string kTrajectories = std::string(LIVO_SHARED_DATA) + "/trajectories/";

using evaluate::test::CommandResult;
CommandResult run(std::vector<std::string> args) { return evaluate::test::runEvaluate(std::move(args)); }

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

}  // namespace

TEST(EvaluateCommand, WritesTableJsonSvgAndReport) {
  const std::string dir = livo_test::tempDir();
  const CommandResult r = run({"--est", kTrajectories + "freiburg1_xyz-rgbdslam.txt", "--gt",
                               kTrajectories + "freiburg1_xyz-groundtruth.txt", "--align", "sim3", "--json",
                               dir + "/fr1.json", "--plot", dir + "/fr1.svg", "--report", dir + "/fr1.md"});
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("ATE translation (m)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("0.0133894"), std::string::npos) << r.out;  // evo_ape tum ... -as: rmse 0.013389...
  EXPECT_NE(r.out.find("KITTI drift: no segment"), std::string::npos) << r.out;

  const auto j = nlohmann::json::parse(readFile(dir + "/fr1.json"));
  // evo_ape tum freiburg1_xyz-groundtruth.txt freiburg1_xyz-rgbdslam.txt -as (see test_evo_agreement.cpp)
  EXPECT_NEAR(j["ate"]["rmse"].get<double>(), 0.013389384904168198, 1e-6 * 0.0134);
  for (const char* key : {"rmse", "mean", "median", "max", "coverage"}) EXPECT_TRUE(j["ate"][key].is_number()) << key;
  // The estimate starts 3.49 s into the 30.09 s of ground truth: at most 88.4 % coverage.
  EXPECT_GT(j["ate"]["coverage"].get<double>(), 0.85);
  EXPECT_LT(j["ate"]["coverage"].get<double>(), 0.884);
  for (const char* key : {"rmse", "mean", "median", "max"}) {
    EXPECT_TRUE(j["rpe"]["translation"][key].is_number()) << key;
    EXPECT_TRUE(j["rpe"]["rotation"][key].is_number()) << key;
  }
  EXPECT_EQ(j["rpe"]["rotation_unit"], "deg");
  EXPECT_EQ(j["association"]["method"], "time");
  EXPECT_EQ(j["association"]["pairs"], 785);
  EXPECT_EQ(j["alignment"]["mode"], "sim3");
  EXPECT_TRUE(j["drift"]["translation_percent"].is_null());  // a 2 m path has no 100 m segment
  EXPECT_EQ(j["drift"]["segments"], 0);

  const std::string svg = readFile(dir + "/fr1.svg");
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("<svg xmlns=\"http://www.w3.org/2000/svg\""), std::string::npos);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
  EXPECT_GT(count(svg, "<polyline"), 5u);  // ground truth, coloured estimate runs, three series
  EXPECT_EQ(count(svg, "<svg"), 1u);
  EXPECT_EQ(count(svg, "nan"), 0u);
  EXPECT_EQ(count(svg, "inf"), 0u);
  for (const char* label : {"ATE (m)", "RPE (m)", "RPE (deg)", "x (m)", "y (m)", "ground truth"})
    EXPECT_NE(svg.find(label), std::string::npos) << label;

  const std::string md = readFile(dir + "/fr1.md");
  EXPECT_NE(md.find("| ATE translation (m) |"), std::string::npos) << md;
  EXPECT_NE(md.find("](fr1.svg)"), std::string::npos) << md;
}

TEST(EvaluateCommand, EurocCsvGroundTruthGivesTheTumNumbers) {
  // V101_gt.txt rewritten as an EuRoC csv (nanosecond stamps, w x y z quaternion order).
  const Trajectory gt = readTum(kTrajectories + "V101_gt.txt");
  const std::string csv = livo_test::tempPath("V101_gt.csv");
  {
    std::ofstream out(csv);
    out << "#timestamp [ns],p_RS_R_x [m],p_RS_R_y [m],p_RS_R_z [m],q_RS_w [],q_RS_x [],q_RS_y [],q_RS_z []\n";
    out << std::setprecision(17);
    for (const auto& s : gt) {
      const Quat q(s.pose.linear());
      const Vec3 p = s.pose.translation();
      out << std::llround(s.stamp * 1e9) << "," << p.x() << "," << p.y() << "," << p.z() << "," << q.w() << "," << q.x()
          << "," << q.y() << "," << q.z() << "\n";
    }
  }
  const std::string dir = livo_test::tempDir();
  const std::string est = kTrajectories + "V101_openvins.txt";
  ASSERT_EQ(run({"--est", est, "--gt", csv, "--json", dir + "/csv.json", "--quiet"}).code, 0);
  ASSERT_EQ(run({"--est", est, "--gt", kTrajectories + "V101_gt.txt", "--json", dir + "/tum.json", "--quiet"}).code, 0);
  const auto a = nlohmann::json::parse(readFile(dir + "/csv.json"));
  const auto b = nlohmann::json::parse(readFile(dir + "/tum.json"));
  EXPECT_EQ(a["ground_truth"]["format"], "euroc-csv");
  EXPECT_EQ(a["association"]["pairs"], b["association"]["pairs"]);
  EXPECT_NEAR(a["ate"]["rmse"].get<double>(), b["ate"]["rmse"].get<double>(), 1e-12);
  EXPECT_NEAR(a["rpe"]["rotation"]["rmse"].get<double>(), b["rpe"]["rotation"]["rmse"].get<double>(), 1e-9);
  // evo_ape tum V101_gt.txt V101_openvins.txt -a (see test_evo_agreement.cpp)
  EXPECT_NEAR(b["ate"]["rmse"].get<double>(), 0.052101965251271695, 1e-6 * 0.0521);
}

TEST(EvaluateCommand, KittiDriftOnKitti00) {
  // Reference: an independent numpy implementation of the KITTI devkit's segment loop
  // (evaluate_odometry.cpp: segments of 100..800 m from every 10th pose, error pose
  // (P_i^-1 P_j)^-1 (Q_i^-1 Q_j), translation / length and acos((trace - 1) / 2) / length averaged),
  // in double precision, on the unaligned ORB estimate: 3283 segments.
  const std::string json = livo_test::tempPath("kitti.json");
  const CommandResult r = run({"--est", kTrajectories + "KITTI_00_ORB.txt", "--gt", kTrajectories + "KITTI_00_gt.txt",
                               "--align", "none", "--json", json});
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(readFile(json));
  EXPECT_EQ(j["association"]["method"], "index");
  EXPECT_EQ(j["drift"]["per_length"].size(), 8u);
  EXPECT_EQ(j["drift"]["segments"], 3283);
  EXPECT_NEAR(j["drift"]["translation_percent"].get<double>(), 0.6997289189481147, 1e-9 * 0.7);
  EXPECT_NEAR(j["drift"]["rotation_deg_per_m"].get<double>(), 0.0025356001677448938, 1e-9 * 0.0025);
  EXPECT_NE(r.out.find("KITTI drift (segments from every 10 poses)"), std::string::npos) << r.out;
}

TEST(EvaluateCommand, FailsClearlyOnBadInput) {
  const std::string dir = livo_test::tempDir();
  // Nothing associates: the estimate is on another time base.
  Trajectory shifted = readTum(kTrajectories + "freiburg1_xyz-rgbdslam.txt");
  for (auto& s : shifted) s.stamp -= 1.0e9;
  writeTum(dir + "/shifted.tum", shifted);
  CommandResult r = run({"--est", dir + "/shifted.tum", "--gt", kTrajectories + "freiburg1_xyz-groundtruth.txt"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("no estimated pose lies within 0.01 s of a ground-truth pose"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty());

  // A malformed line.
  {
    std::ofstream bad(dir + "/bad.tum");
    bad << "# t x y z qx qy qz qw\n1 0 0 0 0 0 0 1\n2 0 0 zero 0 0 0 1\n";
  }
  r = run({"--est", dir + "/bad.tum", "--gt", kTrajectories + "freiburg1_xyz-groundtruth.txt"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("bad.tum:3: 'zero' is not a number"), std::string::npos) << r.err;

  // KITTI poses of different lengths cannot be paired by index.
  {
    std::ofstream k(dir + "/short_kitti.txt");
    k << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n";
  }
  r = run({"--est", dir + "/short_kitti.txt", "--gt", kTrajectories + "KITTI_00_gt.txt"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("cannot pair poses by index: the estimate has 2 poses, the ground truth 4541"),
            std::string::npos)
      << r.err;
  {
    std::ofstream k(dir + "/bad_kitti.txt");
    k << "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1\n";
  }
  r = run({"--est", dir + "/bad_kitti.txt", "--gt", kTrajectories + "KITTI_00_gt.txt"});
  EXPECT_NE(r.err.find("bad_kitti.txt:2: expected 12 numbers"), std::string::npos) << r.err;

  r = run({"--est", dir + "/missing.tum", "--gt", kTrajectories + "V101_gt.txt"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("missing.tum: no such file"), std::string::npos) << r.err;

  // Usage errors.
  r = run({"--est", kTrajectories + "V101_openvins.txt", "--gt", kTrajectories + "V101_gt.txt", "--align", "affine"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--align: expected se3, sim3 or none"), std::string::npos) << r.err;
  r = run({"--est", kTrajectories + "V101_openvins.txt", "--gt", kTrajectories + "V101_gt.txt", "--gt-offset", "1,2"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--gt-offset: expected x,y,z"), std::string::npos) << r.err;
  r = run({"--gt", kTrajectories + "V101_gt.txt"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--est and --gt are both required"), std::string::npos) << r.err;
}

// --marks (a pipeline run's weak_spots.json): degenerate and predicted stretches overlaid on the
// path and shaded on the time axes, loop closures joining their keyframes, each in the legend;
// without marks none of it.
TEST(EvaluateCommand, PlotMarksWeakStretchesAndLoops) {
  const std::string dir = livo_test::tempDir();
  const Trajectory gt = fixtures::wigglyTrajectory(300);  // 30 s from t = 1000 s
  writeTum(dir + "/gt.tum", gt);
  writeTum(dir + "/est.tum", gt);
  {
    std::ofstream marks(dir + "/weak_spots.json");
    marks << R"({"degenerate": {"spans": [{"from": 1005.0, "to": 1009.0}, {"from": 1020.0, "to": 1020.0}]},
                 "predicted": {"spans": [{"from": 1012.0, "to": 1012.5}]},
                 "loops": [{"time": 1025.0, "from_time": 1025.0, "to_time": 1001.0},
                           {"time": 1026.0, "from_time": 1026.0, "to_time": null}]})";
  }
  const CommandResult plain =
      run({"--est", dir + "/est.tum", "--gt", dir + "/gt.tum", "--plot", dir + "/plain.svg", "--quiet"});
  ASSERT_EQ(plain.code, 0) << plain.err;
  const CommandResult marked = run({"--est", dir + "/est.tum", "--gt", dir + "/gt.tum", "--plot", dir + "/marked.svg",
                                    "--marks", dir + "/weak_spots.json", "--quiet"});
  ASSERT_EQ(marked.code, 0) << marked.err;
  const std::string a = readFile(dir + "/plain.svg"), b = readFile(dir + "/marked.svg");
  for (const char* mark : {"degenerate sweeps", "predicted, no LiDAR update", "loop closure", "#ff8c00", "#c51b7d"}) {
    EXPECT_EQ(count(a, mark), 0u) << mark;
    EXPECT_GT(count(b, mark), 0u) << mark;
  }
  // two overlay runs, the legend's sample, two shaded stretches on each of the three panels
  EXPECT_EQ(count(b, "stroke=\"#ff8c00\""), 3u);
  EXPECT_EQ(count(b, "fill=\"#ff8c00\""), 6u);
  // the loop with both keyframes: a line, two dots, a line on each panel; the one without: only its time
  EXPECT_EQ(count(b, "r=\"3.5\" fill=\"#c51b7d\""), 4u);  // two on the path, two in the legend
  EXPECT_EQ(count(b, "stroke=\"#c51b7d\""), 1u + 1u + 3u * 2u);
  EXPECT_EQ(count(b, "nan"), 0u);

  const CommandResult no_plot =
      run({"--est", dir + "/est.tum", "--gt", dir + "/gt.tum", "--marks", dir + "/weak_spots.json"});
  EXPECT_EQ(no_plot.code, 1);
  EXPECT_NE(no_plot.err.find("--marks draws on the figure"), std::string::npos) << no_plot.err;
  { std::ofstream(dir + "/bad.json") << R"({"degenerate": {}})"; }
  const CommandResult bad = run({"--est", dir + "/est.tum", "--gt", dir + "/gt.tum", "--plot", dir + "/bad.svg",
                                 "--marks", dir + "/bad.json", "--quiet"});
  EXPECT_EQ(bad.code, 1);
  EXPECT_NE(bad.err.find(dir + "/bad.json: not a weak_spots.json"), std::string::npos) << bad.err;
}

// --align 4dof, and the ground-vehicle metrics whatever the alignment: named in the JSON, the
// terminal summary and the Markdown report.
TEST(EvaluateCommand, FourDofAlignmentAndGroundVehicleMetrics) {
  const std::string dir = livo_test::tempDir();
  const Trajectory gt = fixtures::wigglyTrajectory(300);
  Trajectory est = gt;
  for (size_t i = 0; i < est.size(); ++i)
    est[i].pose.translation().z() += 0.3 * static_cast<double>(i) / 299.0;  // climbing 0.3 m too much
  writeTum(dir + "/gt.tum", gt);
  writeTum(dir + "/est.tum", est);
  const CommandResult r = run({"--est", dir + "/est.tum", "--gt", dir + "/gt.tum", "--align", "4dof", "--json",
                               dir + "/4dof.json", "--report", dir + "/4dof.md"});
  ASSERT_EQ(r.code, 0) << r.err;
  const std::string vertical = "Vertical drift (z error, heights anchored at the first pose): +0.3000 m at the end";
  const std::vector<std::string> lines = {
      "4dof (yaw about z and translation), yaw ", "ATE after a 4-DoF alignment (yaw about z and translation): rmse ",
      vertical + ", +0.", "Roll / pitch error (gravity direction in the body, rmse): roll "};
  for (const std::string& line : lines) EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;
  const auto j = nlohmann::json::parse(readFile(dir + "/4dof.json"));
  EXPECT_EQ(j["alignment"]["mode"], "4dof");
  EXPECT_EQ(j["ate_4dof"].get<double>(), j["ate"]["rmse"].get<double>());
  EXPECT_NEAR(j["vertical"]["end_m"].get<double>(), 0.3, 1e-6);  // TUM files keep about 9 digits
  EXPECT_NEAR(j["vertical"]["max_abs_m"].get<double>(), 0.3, 1e-6);
  EXPECT_NEAR(j["vertical"]["per_100m"].get<double>(), 0.3 / (j["vertical"]["path_length_m"].get<double>() / 100.0),
              1e-12);
  EXPECT_EQ(j["vertical"]["path_length_m"], j["end_point"]["path_length_m"]);
  for (const char* key : {"roll_rmse_deg", "pitch_rmse_deg", "tilt_rmse_deg", "tilt_max_deg"})
    EXPECT_LT(j["attitude"][key].get<double>(), 1e-5) << key;
  const std::string md = readFile(dir + "/4dof.md");
  EXPECT_NE(md.find("| alignment | 4dof (yaw about z and translation), yaw "), std::string::npos) << md;
  EXPECT_NE(md.find("ATE after 4dof alignment"), std::string::npos) << md;
  EXPECT_NE(md.find("\n\n" + vertical), std::string::npos) << md;

  // With the default SE(3) alignment the JSON carries the 4-DoF ATE beside it.
  const CommandResult se3_run =
      run({"--est", dir + "/est.tum", "--gt", dir + "/gt.tum", "--json", dir + "/se3.json", "--quiet"});
  ASSERT_EQ(se3_run.code, 0) << se3_run.err;
  const auto se3 = nlohmann::json::parse(readFile(dir + "/se3.json"));
  EXPECT_EQ(se3["alignment"]["mode"], "se3");
  EXPECT_EQ(se3["ate_4dof"], j["ate_4dof"]);
  EXPECT_LE(se3["ate"]["rmse"].get<double>(), j["ate_4dof"].get<double>());  // SE(3) has more freedom
}
