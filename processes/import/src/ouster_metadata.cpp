#include "livo/import/ouster_metadata.hpp"

#include <fstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

namespace livo::import {

namespace {

using nlohmann::json;

/// The key at the top level or in one of the SDK's nested sections.
const json* lookup(const json& root, const std::string& key) {
  if (root.contains(key)) return &root[key];
  for (const char* section : {"beam_intrinsics", "lidar_data_format", "data_format", "config_params", "sensor_info",
                              "imu_intrinsics", "lidar_intrinsics", "calibration_status"}) {
    if (root.contains(section) && root[section].is_object() && root[section].contains(key)) return &root[section][key];
  }
  return nullptr;
}

Eigen::Matrix4d matrixOf(const json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 16) throw std::runtime_error(where + ": expected 16 numbers (row-major 4x4)");
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = j[r * 4 + c].get<double>();
  return m;
}

}  // namespace

OusterMetadata readOusterMetadata(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  json root;
  try {
    root = json::parse(in);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": not valid JSON: " + e.what());
  }
  OusterMetadata m;
  auto need = [&](const std::string& key) -> const json& {
    const json* j = lookup(root, key);
    if (!j) throw std::runtime_error(path + ": key '" + key + "' missing");
    return *j;
  };
  auto optional = [&](const std::string& key) { return lookup(root, key); };
  try {
    if (auto j = optional("prod_line")) m.prod_line = j->get<std::string>();
    if (auto j = optional("prod_sn")) m.prod_sn = j->is_string() ? j->get<std::string>() : j->dump();
    if (auto j = optional("build_rev")) m.firmware = j->get<std::string>();
    if (auto j = optional("lidar_mode")) m.lidar_mode = j->get<std::string>();
    m.columns_per_frame = need("columns_per_frame").get<int>();
    m.pixels_per_column = need("pixels_per_column").get<int>();
    if (auto j = optional("columns_per_packet")) m.columns_per_packet = j->get<int>();
    if (auto j = optional("udp_profile_lidar")) m.udp_profile_lidar = j->get<std::string>();
    if (auto j = optional("udp_profile_imu")) m.udp_profile_imu = j->get<std::string>();
    m.column_window_first = 0, m.column_window_last = m.columns_per_frame - 1;
    if (auto j = optional("column_window")) {
      m.column_window_first = (*j)[0].get<int>();
      m.column_window_last = (*j)[1].get<int>();
    }
    m.beam_altitude_angles_deg = need("beam_altitude_angles").get<std::vector<double>>();
    m.beam_azimuth_angles_deg = need("beam_azimuth_angles").get<std::vector<double>>();
    m.lidar_origin_to_beam_origin_mm = need("lidar_origin_to_beam_origin_mm").get<double>();
    if (auto j = optional("beam_to_lidar_transform")) {
      m.beam_to_lidar = matrixOf(*j, path + ": beam_to_lidar_transform");
    } else {
      m.beam_to_lidar(0, 3) = m.lidar_origin_to_beam_origin_mm;
    }
    if (auto j = optional("lidar_to_sensor_transform"))
      m.lidar_to_sensor = matrixOf(*j, path + ": lidar_to_sensor_transform");
    if (auto j = optional("imu_to_sensor_transform"))
      m.imu_to_sensor = matrixOf(*j, path + ": imu_to_sensor_transform");
    if (auto j = optional("udp_port_lidar")) m.udp_port_lidar = j->is_number() ? j->get<int>() : m.udp_port_lidar;
    if (auto j = optional("udp_port_imu")) m.udp_port_imu = j->is_number() ? j->get<int>() : m.udp_port_imu;
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(path + ": a key has the wrong type: " + e.what());
  }
  const size_t x = m.lidar_mode.find('x');
  if (x != std::string::npos) {
    try {
      m.frames_per_second = std::stod(m.lidar_mode.substr(x + 1));
    } catch (const std::exception&) {
    }
  }
  if (m.columns_per_frame <= 0 || m.pixels_per_column <= 0 || m.columns_per_packet <= 0)
    throw std::runtime_error(path + ": columns_per_frame, pixels_per_column and columns_per_packet must be positive");
  if (static_cast<int>(m.beam_altitude_angles_deg.size()) != m.pixels_per_column ||
      static_cast<int>(m.beam_azimuth_angles_deg.size()) != m.pixels_per_column)
    throw std::runtime_error(path + ": beam_altitude_angles / beam_azimuth_angles need pixels_per_column (" +
                             std::to_string(m.pixels_per_column) + ") entries");
  return m;
}

}  // namespace livo::import
