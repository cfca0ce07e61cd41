#include "livo/import/ouster_import.hpp"

#include <cmath>
#include <memory>
#include <optional>

#include "livo/import/file_utils.hpp"
#include "livo/import/imu_units.hpp"
#include "livo/import/ouster_packets.hpp"
#include "livo/import/pcap_reader.hpp"
#include "livo/import/progress_line.hpp"
#include "livo/import/stamp_conversion.hpp"
#include "livo/imu_t.hpp"
#include "livo/messages.hpp"
#include "livo/point_cloud_t.hpp"

namespace livo::import {

namespace {

/// Per (column, beam) unit direction and offset, so a point is offset + range * direction (mm),
/// already in the sensor frame.
class OusterGeometry {
 public:
  explicit OusterGeometry(const OusterMetadata& m) : W_(m.columns_per_frame), H_(m.pixels_per_column) {
    const Eigen::Matrix4d& b2l = m.beam_to_lidar;
    const double n = std::hypot(b2l(0, 3), b2l(2, 3));
    const Eigen::Matrix3d R = m.lidar_to_sensor.topLeftCorner<3, 3>();
    const Vec3 t = m.lidar_to_sensor.topRightCorner<3, 1>();
    dir_.resize(static_cast<size_t>(W_) * H_);
    off_.resize(dir_.size());
    for (int col = 0; col < W_; ++col) {
      const double theta_e = 2.0 * M_PI * (1.0 - static_cast<double>(col) / W_);
      for (int i = 0; i < H_; ++i) {
        const double theta_a = -2.0 * M_PI * m.beam_azimuth_angles_deg[i] / 360.0;
        const double phi = 2.0 * M_PI * m.beam_altitude_angles_deg[i] / 360.0;
        const Vec3 d(std::cos(theta_e + theta_a) * std::cos(phi), std::sin(theta_e + theta_a) * std::cos(phi),
                     std::sin(phi));
        const Vec3 o = Vec3(n * std::cos(theta_e), n * std::sin(theta_e), b2l(2, 3)) - n * d;
        dir_[index(col, i)] = R * d;
        off_[index(col, i)] = R * o + t;
      }
    }
  }
  /// Point in metres, sensor frame.
  Vec3 point(int col, int beam, double range_mm) const {
    const size_t k = index(col, beam);
    return (off_[k] + range_mm * dir_[k]) * 1e-3;
  }

 private:
  size_t index(int col, int beam) const { return static_cast<size_t>(col) * H_ + beam; }
  int W_, H_;
  std::vector<Vec3> dir_, off_;
};

class SweepAssembler {
 public:
  SweepAssembler(const OusterMetadata& m, const OusterImportOptions& o, SortedLogWriter& w, ImportReport& r)
      : meta_(m), geometry_(m), options_(o), writer_(w), report_(r) {
    expected_columns_ = m.column_window_last >= m.column_window_first
                            ? m.column_window_last - m.column_window_first + 1
                            : m.columns_per_frame - m.column_window_first + m.column_window_last + 1;
  }

  void add(const OusterLidarPacket& p, const std::string& where) {
    if (current_frame_ && *current_frame_ != p.frame_id) flush();
    if (!current_frame_) {
      current_frame_ = p.frame_id;
      where_ = where;
    }
    for (const OusterColumn& c : p.columns) {
      if (!c.valid) {
        ++invalid_columns_;
        continue;
      }
      if (c.measurement_id >= meta_.columns_per_frame) {
        report_.skip("column with measurement_id beyond columns_per_frame", where);
        continue;
      }
      columns_.push_back(c);
    }
  }

  void flush() {
    if (!current_frame_) return;
    const int received = static_cast<int>(columns_.size());
    const bool partial = received < expected_columns_;
    if (partial) {
      report_.skip("partial sweep (" + std::string(options_.keep_partial_sweeps ? "kept" : "dropped") +
                       "): fewer columns than the column window",
                   where_ + ": frame " + std::to_string(*current_frame_) + " has " + std::to_string(received) + " of " +
                       std::to_string(expected_columns_) + " columns",
                   1, false);
    }
    if (received > 0 && (!partial || options_.keep_partial_sweeps)) write();
    columns_.clear();
    current_frame_.reset();
  }

  int64_t invalidColumns() const { return invalid_columns_; }

 private:
  void write() {
    int64_t start_ns = columns_.front().timestamp_ns;
    for (const OusterColumn& c : columns_) start_ns = std::min(start_ns, c.timestamp_ns);
    point_cloud_t cloud;
    cloud.utime = start_ns / 1000;
    cloud.frame = "L";
    cloud.pattern = point_cloud_t::PATTERN_SPINNING;
    cloud.num_rings = static_cast<int16_t>(meta_.pixels_per_column);
    cloud.sweep_duration = static_cast<float>(1.0 / meta_.frames_per_second);
    const int64_t utime_ns = cloud.utime * 1000;
    float max_offset = 0.0f;
    for (const OusterColumn& c : columns_) {
      const float offset = static_cast<float>((c.timestamp_ns - utime_ns) * 1e-9);
      max_offset = std::max(max_offset, offset);
      for (int i = 0; i < meta_.pixels_per_column; ++i) {
        if (c.range_mm[i] == 0) continue;
        const Vec3 p = geometry_.point(c.measurement_id, i, c.range_mm[i]);
        cloud.x.push_back(static_cast<float>(p.x()));
        cloud.y.push_back(static_cast<float>(p.y()));
        cloud.z.push_back(static_cast<float>(p.z()));
        cloud.intensity.push_back(static_cast<float>(c.reflectivity[i]));
        cloud.time_offset.push_back(offset);
        cloud.ring.push_back(static_cast<int16_t>(i));
      }
    }
    if (max_offset >= cloud.sweep_duration) cloud.sweep_duration = std::nextafter(max_offset, 1e9f);
    cloud.num_points = static_cast<int32_t>(cloud.x.size());
    writer_.add(options_.channels.lidar, cloud);
  }

  const OusterMetadata& meta_;
  OusterGeometry geometry_;
  const OusterImportOptions& options_;
  SortedLogWriter& writer_;
  ImportReport& report_;
  int expected_columns_ = 0;
  std::optional<int> current_frame_;
  std::vector<OusterColumn> columns_;
  std::string where_;
  int64_t invalid_columns_ = 0;
};

std::string matrixYaml(const Eigen::Matrix4d& T_mm) {
  Eigen::Matrix4d T = T_mm;
  T.topRightCorner<3, 1>() *= 1e-3;
  std::vector<double> v;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) v.push_back(T(r, c));
  return yamlList(v);
}

/// The sensor's metadata, frames and extrinsics into the sidecar, and for the starter rig
/// (--rig-out) T_I_L in metres and the model from the product line ("OS-1-128" -> OS1-128).
void reportOusterSensor(const OusterMetadata& meta, const std::string& meta_path, ImportReport& report) {
  report.metadataString("ouster_metadata", meta_path);
  report.metadataString("ouster_product", meta.prod_line + " " + meta.lidar_mode + " firmware " + meta.firmware);
  report.metadataString("ouster_udp_profile_lidar", meta.udp_profile_lidar);
  report.metadataString("lidar_frame", "L = Ouster sensor frame (os_sensor)");
  report.metadataString("imu_frame", "I = Ouster IMU frame (os_imu)");
  report.metadata("T_sensor_imu", matrixYaml(meta.imu_to_sensor));
  report.metadata("T_sensor_lidar", matrixYaml(meta.lidar_to_sensor));
  // Points are in the sensor frame, so the body(IMU)-from-LiDAR extrinsic is inv(T_sensor_imu).
  report.metadata("extrinsic_imu_lidar", matrixYaml(Eigen::Matrix4d(meta.imu_to_sensor.inverse())));
  Pose3 T_I_L;
  T_I_L.matrix() = meta.imu_to_sensor.inverse();
  T_I_L.translation() *= 1e-3;
  report.calibration().T_I_L = KnownExtrinsic{T_I_L, "", "the metadata's imu_to_sensor_transform, inverted (mm -> m)"};
  std::string model = meta.prod_line;
  if (model.rfind("OS-", 0) == 0 && model.size() > 4 && model[4] == '-')
    model = "OS" + model.substr(3, 1) + model.substr(4);
  report.calibration().lidar_model = model;
  report.calibration().lidar_model_source = "Ouster metadata prod_line " + meta.prod_line;
}

/// An IMU packet as imu_t (g -> m/s^2, deg/s -> rad/s), stamped by its gyro timestamp.
imu_t imuSampleOf(const OusterImuPacket& p) {
  imu_t m;
  m.utime = nsToUtime(p.gyro_ts_ns);
  for (int i = 0; i < 3; ++i) {
    m.linear_acceleration[i] = p.accel_g[i] * kStandardGravity;
    m.angular_velocity[i] = p.gyro_deg_s[i] * M_PI / 180.0;
  }
  return m;
}

struct OusterPacketCounts {
  int64_t lidar = 0, imu = 0;
};

/// Reads the capture: LiDAR packets into `sweeps`, IMU packets into the log; other datagrams and
/// undecodable packets are skipped, a capture that cannot be read to its end is an error.
OusterPacketCounts readCapture(const std::string& pcap, const OusterMetadata& meta, const OusterPacketFormat& format,
                               const OusterImportOptions& o, SweepAssembler& sweeps, SortedLogWriter& writer,
                               ImportReport& report) {
  OusterPacketCounts packets;
  try {
    PcapReader reader(pcap);
    ProgressLine progress("livo-import " + pcap, static_cast<double>(reader.fileSize()) / 1e6, "MB", o.progress);
    reader.readAll([&](const UdpDatagram& u) {
      progress.update(static_cast<double>(reader.position()) / 1e6);
      const std::string where = pcap + ": record " + std::to_string(u.record_number);
      try {
        if (u.dst_port == meta.udp_port_lidar) {
          ++packets.lidar;
          sweeps.add(format.decodeLidar(u.payload.data(), u.payload.size()), where);
        } else if (u.dst_port == meta.udp_port_imu) {
          ++packets.imu;
          writer.add(o.channels.imu, imuSampleOf(decodeOusterImu(u.payload.data(), u.payload.size())));
        } else {
          report.skip("UDP datagram to port " + std::to_string(u.dst_port) + " (neither LiDAR nor IMU port)", where, 1,
                      false);
        }
      } catch (const std::exception& e) {
        report.skip("undecodable Ouster packet", where + ": " + e.what());
      }
    });
    progress.finish();
    const PcapStats& s = reader.stats();
    report.metadata("pcap_records", std::to_string(s.records));
    report.metadata("pcap_ipv4_fragments", std::to_string(s.fragments));
    if (s.non_ipv4 + s.non_udp) report.skip("pcap frames that are not IPv4/UDP", pcap, s.non_ipv4 + s.non_udp, false);
    if (s.incomplete_datagrams) report.skip("IPv4 datagrams with missing fragments", pcap, s.incomplete_datagrams);
  } catch (const std::exception& e) {
    report.error(e.what());
  }
  return packets;
}

}  // namespace

std::string findOusterMetadata(const std::string& pcap) {
  const size_t dot = pcap.rfind('.');
  const size_t slash = pcap.rfind('/');
  const std::string dir = slash == std::string::npos ? "." : pcap.substr(0, slash);
  const std::string stem =
      dot == std::string::npos || (slash != std::string::npos && dot < slash) ? pcap : pcap.substr(0, dot);
  if (isFile(stem + ".json")) return stem + ".json";
  // Captures named "<metadata stem>_<suffix>.pcap" (e.g. the SDK's test files): the longest
  // .json stem that prefixes the pcap's name.
  const std::string name = stem.substr(slash == std::string::npos ? 0 : slash + 1);
  std::string best;
  const std::vector<std::string> jsons = listFiles(dir, ".json");
  for (const std::string& j : jsons) {
    const std::string js = j.substr(0, j.size() - 5);
    if (name.rfind(js, 0) == 0 && js.size() > best.size()) best = j;
  }
  if (!best.empty()) return joinPath(dir, best);
  if (jsons.size() == 1) return joinPath(dir, jsons.front());
  return "";
}

void importOuster(const std::string& pcap, const OusterImportOptions& o, SortedLogWriter& writer,
                  ImportReport& report) {
  const std::string meta_path = o.metadata_file.empty() ? findOusterMetadata(pcap) : o.metadata_file;
  if (meta_path.empty()) {
    report.error(pcap + ": no metadata JSON found beside it (give one with --metadata FILE)");
    return;
  }
  OusterMetadata meta;
  std::unique_ptr<OusterPacketFormat> format;
  try {
    meta = readOusterMetadata(meta_path);
    format = std::make_unique<OusterPacketFormat>(meta);
  } catch (const std::exception& e) {
    report.error(meta_path + ": " + e.what());
    return;
  }
  reportOusterSensor(meta, meta_path, report);
  SweepAssembler sweeps(meta, o, writer, report);
  const OusterPacketCounts packets = readCapture(pcap, meta, *format, o, sweeps, writer, report);
  sweeps.flush();
  if (sweeps.invalidColumns())
    report.skip("LiDAR columns flagged invalid by the sensor", pcap, sweeps.invalidColumns(), false);
  report.metadata("ouster_lidar_packets", std::to_string(packets.lidar));
  report.metadata("ouster_imu_packets", std::to_string(packets.imu));
}

}  // namespace livo::import
