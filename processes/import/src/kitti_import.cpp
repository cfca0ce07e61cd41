#include "livo/import/kitti_import.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "livo/import/file_utils.hpp"
#include "livo/import/image_encoding.hpp"
#include "livo/import/kitti_oxts.hpp"
#include "livo/import/progress_line.hpp"
#include "livo/import/stamp_conversion.hpp"
#include "livo/imu_t.hpp"
#include "livo/messages.hpp"
#include "livo/pose_t.hpp"
#include "livo/trajectory_io.hpp"

namespace livo::import {

int64_t parseKittiTimestamp(const std::string& text) {
  int Y, M, D, h, m, consumed = 0;
  double sec_unused;
  (void)sec_unused;
  if (std::sscanf(text.c_str(), "%d-%d-%d %d:%d:%n", &Y, &M, &D, &h, &m, &consumed) != 5 || consumed == 0)
    throw std::invalid_argument("'" + text + "' is not 'YYYY-MM-DD HH:MM:SS.fraction'");
  const std::string rest = text.substr(consumed);
  const size_t dot = rest.find('.');
  const std::string whole = rest.substr(0, dot);
  std::string frac = dot == std::string::npos ? "" : rest.substr(dot + 1);
  while (!frac.empty() && (frac.back() == ' ' || frac.back() == '\r')) frac.pop_back();
  if (whole.empty() || whole.find_first_not_of("0123456789") != std::string::npos ||
      frac.find_first_not_of("0123456789") != std::string::npos || frac.size() > 9)
    throw std::invalid_argument("'" + text + "' is not 'YYYY-MM-DD HH:MM:SS.fraction'");
  std::tm tm{};
  tm.tm_year = Y - 1900, tm.tm_mon = M - 1, tm.tm_mday = D, tm.tm_hour = h, tm.tm_min = m;
  tm.tm_sec = std::stoi(whole);
  const int64_t seconds = static_cast<int64_t>(timegm(&tm));
  frac.resize(9, '0');
  return seconds * 1000000000LL + std::stoll(frac);
}

namespace {

/// Stamps of a KITTI timestamps.txt (one per line); a bad line is recorded and left as INT64_MIN.
std::vector<int64_t> readKittiTimestamps(const std::string& path, ImportReport& report) {
  std::vector<int64_t> out;
  int ln = 0;
  for (const std::string& line : readLines(path)) {
    ++ln;
    if (line.find_first_not_of(" \t") == std::string::npos) continue;
    try {
      out.push_back(parseKittiTimestamp(line));
    } catch (const std::exception& e) {
      report.skip("malformed timestamp line", path + ":" + std::to_string(ln) + ": " + e.what());
      out.push_back(INT64_MIN);
    }
  }
  return out;
}

/// Frame index from a KITTI file name ("0000000123.bin" -> 123), -1 if not numeric.
long frameIndex(const std::string& name) {
  const std::string stem = name.substr(0, name.find('.'));
  if (stem.empty() || stem.find_first_not_of("0123456789") != std::string::npos) return -1;
  return std::stol(stem);
}

struct ScanStamp {
  int64_t start_utime;
  double duration;
};

void writeScans(const std::string& dir, const std::vector<std::string>& files,
                const std::function<bool(long, ScanStamp*)>& stamp_of, const KittiImportOptions& o,
                SortedLogWriter& writer, ImportReport& report) {
  ProgressLine progress("livo-import " + dir, static_cast<double>(files.size()), "scans", o.progress);
  bool noted = false;
  for (size_t i = 0; i < files.size(); ++i) {
    progress.update(static_cast<double>(i));
    const std::string path = joinPath(dir, files[i]);
    const long index = frameIndex(files[i]);
    ScanStamp st{};
    if (index < 0 || !stamp_of(index, &st)) {
      report.skip("LiDAR scan without a timestamp line", path);
      continue;
    }
    KittiScan scan;
    try {
      KittiPointFields used = KittiPointFields::kAuto;
      if (files[i].size() > 4 && files[i].substr(files[i].size() - 4) == ".txt") {
        scan = readKittiText(path);
      } else {
        scan = readKittiBin(path, o.point_fields, &used);
        if (!noted) {
          report.metadataString("kitti_point_fields", used == KittiPointFields::kXyzi ? "x y z reflectance" : "x y z");
          noted = true;
        }
      }
    } catch (const std::exception& e) {
      report.skip("unreadable LiDAR scan", e.what());
      continue;
    }
    int64_t dropped = 0;
    point_cloud_t cloud = kittiScanToCloud(scan, st.start_utime, st.duration, &dropped);
    if (dropped) report.skip("LiDAR points with a NaN/inf coordinate", path, dropped, false);
    writer.add(o.channels.lidar, cloud);
  }
}

void importImages(const std::string& dir, const std::string& channel, const std::string& frame, ImportReport& report,
                  SortedLogWriter& writer) {
  const std::string ts_path = joinPath(dir, "timestamps.txt");
  if (!isFile(ts_path)) {
    report.skip("camera folder without timestamps.txt", dir);
    return;
  }
  const std::vector<int64_t> stamps = readKittiTimestamps(ts_path, report);
  for (const std::string& name : listFiles(joinPath(dir, "data"), ".png")) {
    const std::string path = joinPath(joinPath(dir, "data"), name);
    const long index = frameIndex(name);
    if (index < 0 || index >= static_cast<long>(stamps.size()) || stamps[index] == INT64_MIN) {
      report.skip("image without a timestamp line", path);
      continue;
    }
    std::vector<uint8_t> bytes;
    try {
      bytes = readFileBytes(path);
    } catch (const std::exception& e) {
      report.skip("unreadable image file", e.what());
      continue;
    }
    const CompressedImageInfo info = sniffCompressedImage(bytes.data(), bytes.size());
    if (info.encoding < 0 || info.width <= 0) {
      report.skip("image file is not a readable PNG/JPEG", path);
      continue;
    }
    image_t img;
    img.utime = nsToUtime(stamps[index]);
    img.frame = frame;
    img.width = info.width, img.height = info.height, img.row_stride = 0;
    img.encoding = info.encoding;
    img.exposure_time = 0.0f;
    img.size = static_cast<int32_t>(bytes.size());
    img.data = std::move(bytes);
    writer.add(channel, img);
  }
}

void importOxts(const std::string& dir, const KittiImportOptions& o, SortedLogWriter& writer, ImportReport& report) {
  const std::string ts_path = joinPath(dir, "timestamps.txt");
  if (!isFile(ts_path)) {
    report.error(dir + ": no timestamps.txt: OXTS not imported");
    return;
  }
  const std::vector<int64_t> stamps = readKittiTimestamps(ts_path, report);
  std::unique_ptr<OxtsLocalFrame> local;
  for (const std::string& name : listFiles(joinPath(dir, "data"), ".txt")) {
    const std::string path = joinPath(joinPath(dir, "data"), name);
    const long index = frameIndex(name);
    if (index < 0 || index >= static_cast<long>(stamps.size()) || stamps[index] == INT64_MIN) {
      report.skip("OXTS packet without a timestamp line", path);
      continue;
    }
    OxtsPacket p;
    try {
      p = readOxtsFile(path);
    } catch (const std::exception& e) {
      report.skip("unreadable OXTS packet", e.what());
      continue;
    }
    const int64_t utime = nsToUtime(stamps[index]);
    imu_t imu;
    imu.utime = utime;
    vec3To(p.gyro(), imu.angular_velocity);
    vec3To(p.accel(), imu.linear_acceleration);
    writer.add(o.channels.imu, imu);
    if (!local) {
      local = std::make_unique<OxtsLocalFrame>(p);
      report.metadata("oxts_origin_lat_lon_alt", yamlList({p.lat(), p.lon(), p.alt()}));
    }
    pose_t gt;
    gt.utime = utime;
    gt.parent_frame = "W";
    gt.child_frame = "I";
    poseTo(local->pose(p), gt.position, gt.orientation);
    writer.add(o.channels.ground_truth, gt);
  }
  report.metadataString("body_frame", "I = OXTS packet frame (x forward, y left, z up)");
  report.metadataString("world_frame", "W = local Mercator frame at the first fix (x east, y north, z up)");
}

void importRawDrive(const std::string& folder, const KittiImportOptions& o, SortedLogWriter& writer,
                    ImportReport& report) {
  report.metadataString("kitti_layout", "raw drive");
  const std::string velo = joinPath(folder, "velodyne_points");
  if (isDirectory(velo)) {
    std::vector<int64_t> mid, start, end;
    if (isFile(joinPath(velo, "timestamps.txt"))) mid = readKittiTimestamps(joinPath(velo, "timestamps.txt"), report);
    if (isFile(joinPath(velo, "timestamps_start.txt")))
      start = readKittiTimestamps(joinPath(velo, "timestamps_start.txt"), report);
    if (isFile(joinPath(velo, "timestamps_end.txt")))
      end = readKittiTimestamps(joinPath(velo, "timestamps_end.txt"), report);
    report.metadataString("lidar_sweep_start",
                          start.empty() ? "timestamps.txt - sweep_duration / 2" : "timestamps_start.txt");
    auto stamp_of = [&](long i, ScanStamp* st) {
      const size_t k = static_cast<size_t>(i);
      st->duration = o.sweep_duration;
      if (k < start.size() && start[k] != INT64_MIN) {
        if (k < end.size() && end[k] != INT64_MIN && end[k] > start[k] && end[k] - start[k] < 500000000)
          st->duration = (end[k] - start[k]) * 1e-9;
        st->start_utime = nsToUtime(start[k]);
        return true;
      }
      if (k < mid.size() && mid[k] != INT64_MIN) {
        st->start_utime = nsToUtime(mid[k] - std::llround(o.sweep_duration * 0.5e9));
        return true;
      }
      return false;
    };
    const std::string data = joinPath(velo, "data");
    std::vector<std::string> files = listFiles(data, ".bin");
    if (files.empty()) files = listFiles(data, ".txt");
    writeScans(data, files, stamp_of, o, writer, report);
  }
  if (isDirectory(joinPath(folder, "oxts"))) importOxts(joinPath(folder, "oxts"), o, writer, report);
  if (isDirectory(joinPath(folder, "image_02")))
    importImages(joinPath(folder, "image_02"), o.channels.camera, "C", report, writer);
  if (isDirectory(joinPath(folder, "image_03")))
    importImages(joinPath(folder, "image_03"), o.channels.camera_right, "C1", report, writer);
}

/// "Tr: 12 numbers" of an odometry calib.txt as T_cam0_velo; false if absent.
bool readVeloToCam(const std::string& calib, Pose3* T) {
  if (!isFile(calib)) return false;
  for (const std::string& line : readLines(calib)) {
    if (line.rfind("Tr:", 0) != 0) continue;
    std::istringstream ss(line.substr(3));
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c)
        if (!(ss >> m(r, c))) return false;
    T->matrix() = m;
    return true;
  }
  return false;
}

void importOdometry(const std::string& folder, const std::string& velo_dir, const KittiImportOptions& o,
                    SortedLogWriter& writer, ImportReport& report) {
  const std::string times_path = o.times_file.empty() ? joinPath(folder, "times.txt") : o.times_file;
  std::vector<double> times;
  if (isFile(times_path)) {
    report.metadataString("kitti_layout", "odometry sequence");
    readNumericRows(times_path, [&](int, const std::vector<double>& v) { times.push_back(v.at(0)); });
  } else {
    report.metadataString("kitti_layout", "scan folder without timestamps");
    report.note("no times.txt: scans stamped at " + yamlNumber(o.lidar_rate_hz) + " Hz from 0 s");
  }
  auto stamp_of = [&](long i, ScanStamp* st) {
    st->duration = o.sweep_duration;
    double t;
    if (!times.empty()) {
      if (static_cast<size_t>(i) >= times.size()) return false;
      t = times[static_cast<size_t>(i)];
    } else {
      t = static_cast<double>(i) / o.lidar_rate_hz;
    }
    // Odometry times are the raw data's forward-facing (mid-sweep) stamps.
    st->start_utime = secondsToUtime(t - (times.empty() ? 0.0 : 0.5 * o.sweep_duration));
    return true;
  };
  writeScans(velo_dir, listFiles(velo_dir, ".bin"), stamp_of, o, writer, report);

  std::string poses = o.poses_file;
  if (poses.empty()) {
    std::string seq = folder;
    while (!seq.empty() && seq.back() == '/') seq.pop_back();
    const std::string name = seq.substr(seq.find_last_of('/') + 1);
    const std::string guess = joinPath(seq, "../../poses/" + name + ".txt");
    if (isFile(guess)) poses = guess;
  }
  if (poses.empty()) return;
  Trajectory traj;
  try {
    traj = readKittiPoses(poses);
  } catch (const std::exception& e) {
    report.error(e.what());
    return;
  }
  Pose3 T_cam_velo = Pose3::Identity();
  const bool to_lidar = readVeloToCam(joinPath(folder, "calib.txt"), &T_cam_velo);
  report.metadataString("ground_truth_file", poses);
  report.metadataString("ground_truth_frame",
                        to_lidar ? "LiDAR (velodyne) poses in the first LiDAR frame, from cam0 poses and calib.txt Tr"
                                 : "cam0 poses as given (no calib.txt Tr): child frame C");
  for (size_t i = 0; i < traj.size(); ++i) {
    double t;
    if (!times.empty()) {
      if (i >= times.size()) {
        report.skip("pose without a times.txt line", poses + ":" + std::to_string(i + 1));
        continue;
      }
      t = times[i];
    } else {
      t = static_cast<double>(i) / o.lidar_rate_hz + 0.5 * o.sweep_duration;
    }
    pose_t gt;
    gt.utime = secondsToUtime(t);
    gt.parent_frame = "W";
    gt.child_frame = to_lidar ? "I" : "C";
    const Pose3 T = to_lidar ? Pose3(T_cam_velo.inverse() * traj[i].pose * T_cam_velo) : traj[i].pose;
    poseTo(T, gt.position, gt.orientation);
    writer.add(o.channels.ground_truth, gt);
  }
  if (to_lidar) report.metadataString("body_frame", "I = LiDAR (KITTI odometry has no IMU)");
  if (times.empty()) report.note("ground-truth poses stamped at the scans' mid-sweep instants (no times.txt)");
}

}  // namespace

void importKitti(const std::string& folder, const KittiImportOptions& o, SortedLogWriter& writer,
                 ImportReport& report) {
  if (!isDirectory(folder)) {
    report.error(folder + ": not a folder");
    return;
  }
  if (isDirectory(joinPath(folder, "velodyne_points")) || isDirectory(joinPath(folder, "oxts")) ||
      isDirectory(joinPath(folder, "image_02"))) {
    importRawDrive(folder, o, writer, report);
  } else if (isDirectory(joinPath(folder, "velodyne"))) {
    importOdometry(folder, joinPath(folder, "velodyne"), o, writer, report);
  } else if (!listFiles(folder, ".bin").empty()) {
    importOdometry(folder, folder, o, writer, report);
  } else {
    report.error(folder + ": no KITTI layout found (velodyne_points/, oxts/, image_02/, velodyne/ or *.bin)");
  }
}

}  // namespace livo::import
