// The ground-map thickness on synthetic registered scans of a 5 % graded ground with a wall: a
// planted vertical drift thickens the ground by what the drift's spread says, a perfect estimate
// shows the truth floor, a cell seen by one scan does not count; and through livo-evaluate
// --ground-map on an LCM log, with clear errors on bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "evaluate_command_runner.hpp"
#include "lcm_log_writer.hpp"
#include "livo/evaluate/evaluate_command.hpp"
#include "livo/evaluate/ground_map.hpp"
#include "livo/messages.hpp"
#include "livo/pose_t.hpp"
#include "livo/registered_scan_t.hpp"
#include "livo/time.hpp"
#include "temp_path.hpp"

using namespace livo;
using namespace livo::evaluate;

namespace {

constexpr double kGrade = 0.05;         // ground height z = 0.05 x
constexpr double kWallX = 5.25;         // a wall across the ground, 2 m high
constexpr int kScans = 10;              // 0.1 s apart from t = 100 s
constexpr double kDriftPerScan = 0.01;  // the planted vertical drift: 1 cm more every scan

double groundHeight(double x) { return kGrade * x; }

/// The true scene, the same in every scan: the ground on a 0.1 m grid (x 0.05..5.95, y -1.95..1.95:
/// 5 x 5 points in each of the 12 x 8 cells of 0.5 m) and a wall at x = 5.25 (the same 40 columns,
/// 20 rows 0.1 m apart from 5 cm above the ground).
std::vector<Vec3> scene() {
  std::vector<Vec3> points;
  for (int i = 0; i < 60; ++i)
    for (int j = 0; j < 40; ++j) {
      const double x = 0.05 + 0.1 * i, y = -1.95 + 0.1 * j;
      points.emplace_back(x, y, groundHeight(x));
    }
  for (int j = 0; j < 40; ++j)
    for (int k = 0; k < 20; ++k) points.emplace_back(kWallX, -1.95 + 0.1 * j, groundHeight(kWallX) + 0.05 + 0.1 * k);
  return points;
}

double scanTime(int k) { return 100.0 + 0.1 * k + 0.025; }  // between two ground-truth poses

/// The vehicle climbing the grade along x at 5 m/s, pitched with it and yawed a little.
Pose3 truePose(double t) {
  Pose3 T = Pose3::Identity();
  T.linear() = so3::Exp(Vec3(0, 0, 0.1)) * so3::Exp(Vec3(0, -std::atan(kGrade), 0));
  const double x = 5.0 * (t - 100.0);
  T.translation() = Vec3(x, 0.3, groundHeight(x) + 1.5);
  return T;
}

/// Ground truth at 20 Hz over the scans (linear motion: interpolating it is exact).
Trajectory groundTruth() {
  Trajectory gt;
  for (int i = -2; i < 2 * kScans + 2; ++i) gt.push_back({100.0 + 0.05 * i, truePose(100.0 + 0.05 * i)});
  return gt;
}

/// A registered scan as an estimator would publish it: the points where its pose puts them,
/// p_w = T_est T_gt^-1 q (in floats), with that pose.
struct Scan {
  int64_t utime = 0;
  Pose3 T_est = Pose3::Identity();
  int32_t epoch = 0;
  std::vector<float> x, y, z;

  void add(const Vec3& p) {
    x.push_back(static_cast<float>(p.x()));
    y.push_back(static_cast<float>(p.y()));
    z.push_back(static_cast<float>(p.z()));
  }
};

Scan registered(int k, const std::vector<Vec3>& truth, const Pose3& est_error) {
  Scan s;
  s.utime = toUtime(scanTime(k));
  const Pose3 T_gt = truePose(scanTime(k));
  s.T_est = est_error * T_gt;
  for (const Vec3& q : truth) s.add(s.T_est * (T_gt.inverse() * q));
  return s;
}

Pose3 lifted(double dz) {
  Pose3 T = Pose3::Identity();
  T.translation().z() = dz;
  return T;
}

/// kScans scans of the scene, scan k lifted by k * drift_per_scan.
std::vector<Scan> drifting(double drift_per_scan) {
  std::vector<Scan> scans;
  const std::vector<Vec3> truth = scene();
  for (int k = 0; k < kScans; ++k) scans.push_back(registered(k, truth, lifted(drift_per_scan * k)));
  return scans;
}

GroundScanSource sourceOf(const std::vector<Scan>& scans) {
  return [&scans](const GroundScanVisitor& visit) {
    for (const Scan& s : scans) {
      GroundScan g;
      g.utime = s.utime;
      g.T_W_I = s.T_est;
      g.epoch = s.epoch;
      g.x = s.x.data();
      g.y = s.y.data();
      g.z = s.z.data();
      g.size = s.x.size();
      visit(g);
    }
  };
}

double populationStd(const std::vector<double>& v) {
  double mean = 0.0, squares = 0.0;
  for (double x : v) mean += x / static_cast<double>(v.size());
  for (double x : v) squares += (x - mean) * (x - mean);
  return std::sqrt(squares / static_cast<double>(v.size()));
}

/// The truth floor of a plain ground cell: 5 columns of heights 0.005 m apart (the grade over the
/// 0.1 m grid), 5 points each.
double groundCellTruth() {
  std::vector<double> heights;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) heights.push_back(0.005 * i);
  return populationStd(heights);  // sqrt(0.005^2 (25 - 1) / 12) = sqrt(5e-5)
}

/// Variance of the planted drift over the scans: k * d for k = 0..K-1, d^2 (K^2 - 1) / 12.
double driftVariance(double d) { return d * d * (kScans * kScans - 1) / 12.0; }

}  // namespace

TEST(GroundMap, GroundTruthInterpolatedOnlyBetweenNearPoses) {
  const Trajectory gt = groundTruth();
  Pose3 T;
  ASSERT_TRUE(groundTruthAt(gt, 100.025, 0.05, &T));
  EXPECT_TRUE(T.isApprox(truePose(100.025), 1e-12));
  ASSERT_TRUE(groundTruthAt(gt, gt[3].stamp, 0.0, &T));  // a pose at the very stamp needs no neighbour
  EXPECT_TRUE(T.isApprox(gt[3].pose, 1e-15));
  EXPECT_FALSE(groundTruthAt(gt, 100.025, 0.02, &T));  // each neighbour 25 ms away
  EXPECT_FALSE(groundTruthAt(gt, 99.8, 1.0, &T));      // before the first pose
  EXPECT_FALSE(groundTruthAt(gt, 102.0, 1.0, &T));     // after the last
}

// Every scan sees the same true points, lifted by k cm: within a cell the estimated heights are
// the true ones plus the scan's lift, so their variance is the truth's plus the lift's over the
// scans, 1e-4 (10^2 - 1) / 12 = 8.25e-4 m^2.
TEST(GroundMap, PlantedVerticalDriftThickensTheGroundByItsSpread) {
  const std::vector<Scan> scans = drifting(kDriftPerScan);
  const GroundMapThickness g = groundMapThickness(sourceOf(scans), groundTruth(), GroundMapOptions{});

  EXPECT_EQ(g.scans, 10u);
  EXPECT_EQ(g.scans_skipped, 0u);
  EXPECT_EQ(g.cells, 96u);  // 12 x 8 cells of 0.5 m
  // The ground (2400 a scan) and, in the 8 wall cells, its 2 lowest rows (10 points a cell, 5 and 15 cm
  // above the ground) are in the band; the 18 rows above are not.
  EXPECT_EQ(g.points, 10u * (2400u + 80u));
  EXPECT_EQ(g.points_binned, 10u * (2400u + 800u));

  const double truth = groundCellTruth();
  EXPECT_NEAR(truth, std::sqrt(5e-5), 1e-12);
  EXPECT_NEAR(g.truth.median, truth, 1e-6);  // 88 of the 96 cells are plain ground
  EXPECT_NEAR(g.thickness.median, std::sqrt(truth * truth + driftVariance(kDriftPerScan)), 1e-6);
  EXPECT_NEAR(g.thickness.median, 0.0295804, 1e-6);
  for (size_t c = 0; c < g.cells; ++c)
    EXPECT_NEAR(g.thickness_m[c] * g.thickness_m[c] - g.truth_m[c] * g.truth_m[c], driftVariance(kDriftPerScan), 1e-7)
        << "cell " << c;
  EXPECT_NEAR(g.thickness.rmse * g.thickness.rmse - g.truth.rmse * g.truth.rmse, driftVariance(kDriftPerScan), 1e-7);

  // A wall cell's ground layer: the 25 ground points and the wall's 2 lowest rows, 5 points each.
  std::vector<double> wall_cell;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) wall_cell.push_back(groundHeight(5.05 + 0.1 * i));
  for (int j = 0; j < 5; ++j)
    wall_cell.push_back(groundHeight(kWallX) + 0.05), wall_cell.push_back(groundHeight(kWallX) + 0.15);
  EXPECT_NEAR(g.truth.max, populationStd(wall_cell), 1e-6);  // about 5 cm, not the 2 m wall's half-metre spread
}

TEST(GroundMap, PerfectEstimateShowsTheTruthFloor) {
  const std::vector<Scan> scans = drifting(0.0);
  const GroundMapThickness g = groundMapThickness(sourceOf(scans), groundTruth(), GroundMapOptions{});
  ASSERT_EQ(g.cells, 96u);
  for (size_t c = 0; c < g.cells; ++c) EXPECT_NEAR(g.thickness_m[c], g.truth_m[c], 1e-6) << "cell " << c;
  EXPECT_NEAR(g.thickness.rmse, g.truth.rmse, 1e-7);
  EXPECT_NEAR(g.thickness.median, groundCellTruth(), 1e-6);
  EXPECT_GT(g.truth.rmse, 0.007);  // real relief: the grade across a cell
}

// A cell counts with 10 ground points from 2 scans: a patch only the first scan sees (30 points)
// does not, nor one the first two scans see with 9 points between them; a scan the ground truth
// does not bracket and a NaN point are skipped and counted.
TEST(GroundMap, CellsOfOneScanOrFewPointsDoNotCount) {
  std::vector<Scan> scans = drifting(kDriftPerScan);
  const Pose3 T_gt0 = truePose(scanTime(0)), T_gt1 = truePose(scanTime(1));
  for (int i = 0; i < 30; ++i) scans[0].add(scans[0].T_est * (T_gt0.inverse() * Vec3(20.1 + 0.01 * i, 0.1, 0.0)));
  for (int i = 0; i < 5; ++i) scans[0].add(scans[0].T_est * (T_gt0.inverse() * Vec3(30.1 + 0.01 * i, 0.1, 0.0)));
  for (int i = 0; i < 4; ++i) scans[1].add(scans[1].T_est * (T_gt1.inverse() * Vec3(30.1 + 0.01 * i, 0.1, 0.0)));
  scans[1].x[7] = std::numeric_limits<float>::quiet_NaN();
  Scan late = registered(0, scene(), Pose3::Identity());
  late.utime = toUtime(120.0);  // the ground truth ends at 101.05 s
  scans.push_back(late);
  Scan empty;
  empty.utime = toUtime(scanTime(3));
  scans.push_back(empty);

  const GroundMapThickness g = groundMapThickness(sourceOf(scans), groundTruth(), GroundMapOptions{});
  EXPECT_EQ(g.cells, 96u);
  EXPECT_EQ(g.points, 10u * 2480u - 1u);  // the NaN point was a ground point
  EXPECT_EQ(g.scans, 10u);
  EXPECT_EQ(g.scans_skipped, 2u);
  EXPECT_EQ(g.scans_empty, 1u);
  EXPECT_EQ(g.points_skipped, 1u);
  EXPECT_NEAR(g.thickness.median, std::sqrt(5e-5 + driftVariance(kDriftPerScan)), 1e-6);
}

// After a reset (a new epoch) the estimate's world is another one, 100 m higher here: its cells
// are its own, and the jump does not thicken the ground.
TEST(GroundMap, EpochsKeepTheirOwnCells) {
  std::vector<Scan> scans = drifting(0.0);
  for (int k = kScans / 2; k < kScans; ++k) {
    scans[static_cast<size_t>(k)] = registered(k, scene(), lifted(100.0));
    scans[static_cast<size_t>(k)].epoch = 1;
  }
  const GroundMapThickness g = groundMapThickness(sourceOf(scans), groundTruth(), GroundMapOptions{});
  EXPECT_EQ(g.cells, 2u * 96u);
  EXPECT_NEAR(g.thickness.rmse, g.truth.rmse, 1e-5);  // float rounding of heights near 100 m
}

TEST(GroundMap, RefusesBadOptions) {
  const std::vector<Scan> scans = drifting(0.0);
  GroundMapOptions o;
  o.cell_m = 0.0;
  EXPECT_THROW(groundMapThickness(sourceOf(scans), groundTruth(), o), std::invalid_argument);
  o = GroundMapOptions{};
  o.band_m = std::nan("");
  EXPECT_THROW(groundMapThickness(sourceOf(scans), groundTruth(), o), std::invalid_argument);
}

// ---- livo-evaluate --ground-map on an LCM log ----
namespace {

using evaluate::test::CommandResult;
CommandResult run(std::vector<std::string> args) { return evaluate::test::runEvaluate(std::move(args)); }

registered_scan_t scanMessage(const Scan& s, const std::string& frame = "W") {
  registered_scan_t m{};
  m.utime = s.utime;
  poseTo(s.T_est, m.position, m.orientation);
  m.epoch = s.epoch;
  m.cloud.utime = s.utime;
  m.cloud.frame = frame;
  m.cloud.num_points = static_cast<int32_t>(s.x.size());
  m.cloud.x = s.x;
  m.cloud.y = s.y;
  m.cloud.z = s.z;
  m.cloud.intensity.assign(s.x.size(), 0.0f);
  m.cloud.time_offset.assign(s.x.size(), 0.0f);
  m.cloud.ring.assign(s.x.size(), -1);
  return m;
}

/// GROUND_TRUTH (pose_t, 20 Hz) and the drifting scans on REGISTERED_SCAN (one in frame L when asked).
std::string writeLog(const std::string& name, bool one_scan_in_lidar_frame = false) {
  const std::string path = livo_test::tempPath(name);
  lcm::LogFile log(path, "w");
  EXPECT_TRUE(log.good());
  for (const StampedPose& s : groundTruth()) {
    pose_t m{};
    m.utime = toUtime(s.stamp);
    m.parent_frame = "W";
    m.child_frame = "I";
    poseTo(s.pose, m.position, m.orientation);
    fixtures::writeMessage(log, "GROUND_TRUTH", m.utime, m);
  }
  const std::vector<Scan> scans = drifting(kDriftPerScan);
  for (size_t k = 0; k < scans.size(); ++k)
    fixtures::writeMessage(log, "REGISTERED_SCAN", scans[k].utime,
                           scanMessage(scans[k], one_scan_in_lidar_frame && k == 4 ? "L" : "W"));
  return path;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST(GroundMapCommand, ReportsTheThicknessInJsonSummaryAndReport) {
  const std::string log = writeLog("ground.lcmlog");
  const std::string json = livo_test::tempPath("ground.json"), md = livo_test::tempPath("ground.md");
  const CommandResult r = run({"--est", log + ":GROUND_TRUTH", "--gt", log, "--align", "none", "--ground-map", log,
                               "--json", json, "--report", md});
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(readFile(json))["ground_map"];
  EXPECT_EQ(j["cells"], 96);
  EXPECT_EQ(j["scans"], 10);
  EXPECT_EQ(j["scans_skipped"], 0);
  EXPECT_EQ(j["points"], 24800);
  EXPECT_NEAR(j["thickness_median_m"].get<double>(), 0.0295804, 1e-6);
  EXPECT_NEAR(j["truth_median_m"].get<double>(), std::sqrt(5e-5), 1e-6);
  EXPECT_TRUE(j["thickness_rms_m"].is_number());
  EXPECT_TRUE(j["truth_rms_m"].is_number());
  EXPECT_EQ(j["source"], log + ":REGISTERED_SCAN");
  EXPECT_EQ(j["cell_m"], 0.5);
  EXPECT_NE(r.out.find("Ground-map thickness (" + log +
                       ":REGISTERED_SCAN, 0.5 m cells, the lowest 0.2 m of each): "
                       "rms "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("median 0.0296 m; truth floor rms"), std::string::npos) << r.out;
  EXPECT_NE(readFile(md).find("Ground-map thickness ("), std::string::npos);

  // Coarser cells hold more of the grade: a 1 m cell's truth floor is twice a 0.5 m cell's.
  const CommandResult coarse = run({"--est", log + ":GROUND_TRUTH", "--gt", log, "--align", "none", "--ground-map",
                                    log + ":REGISTERED_SCAN", "--ground-cell", "1", "--json", json, "--quiet"});
  ASSERT_EQ(coarse.code, 0) << coarse.err;
  EXPECT_TRUE(coarse.out.empty());
  const auto c = nlohmann::json::parse(readFile(json))["ground_map"];
  EXPECT_EQ(c["cells"], 24);
  EXPECT_NEAR(c["truth_median_m"].get<double>(), 0.005 * std::sqrt((10.0 * 10.0 - 1.0) / 12.0), 1e-6);

  // Not asked for: null, and no line.
  const CommandResult plain = run({"--est", log + ":GROUND_TRUTH", "--gt", log, "--align", "none", "--json", json});
  ASSERT_EQ(plain.code, 0) << plain.err;
  EXPECT_TRUE(nlohmann::json::parse(readFile(json))["ground_map"].is_null());
  EXPECT_EQ(plain.out.find("Ground-map"), std::string::npos);
}

TEST(GroundMapCommand, FailsClearlyOnBadInput) {
  const std::string log = writeLog("ground_bad.lcmlog");
  const std::vector<std::string> base = {"--est", log + ":GROUND_TRUTH", "--gt", log, "--align", "none", "--quiet"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = base;
    args.insert(args.end(), extra.begin(), extra.end());
    return run(args);
  };
  CommandResult r = with({"--ground-map", log + ":NOPE"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(log + ": no messages on channel NOPE (channels in the log: GROUND_TRUTH (24), "
                             "REGISTERED_SCAN (10))"),
            std::string::npos)
      << r.err;
  r = with({"--ground-map", log + ":GROUND_TRUTH"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(log + ": event 1 on GROUND_TRUTH: is livo.pose_t, expected livo.registered_scan_t"),
            std::string::npos)
      << r.err;
  r = with({"--ground-map", livo_test::tempPath("missing.lcmlog")});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("missing.lcmlog: no such file"), std::string::npos) << r.err;
  r = with({"--ground-map", log, "--ground-band", "0"});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("--ground-band must be a positive number of metres"), std::string::npos) << r.err;

  const std::string lidar_frame = writeLog("ground_frame.lcmlog", true);
  r = with({"--ground-map", lidar_frame});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find(lidar_frame + ": event 29 on REGISTERED_SCAN: cloud frame is 'L', expected W"),
            std::string::npos)
      << r.err;

  {
    std::ofstream text(livo_test::tempPath("not_a_log.txt"));
    text << "hello\n";
  }
  r = with({"--ground-map", livo_test::tempPath("not_a_log.txt")});
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.err.find("not_a_log.txt: not an LCM log"), std::string::npos) << r.err;
}
