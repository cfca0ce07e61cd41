#include "livo/asl_dataset.hpp"

#include <dirent.h>
#include <algorithm>
#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "livo/trajectory_io.hpp"

namespace livo {

std::vector<AslImuSample> readAslImuCsv(const std::string& path) {
  std::vector<AslImuSample> out;
  // The nanosecond stamp does not survive a double: read it as an integer from the line itself.
  std::ifstream in(path);
  if (!in) throw TrajectoryError(path + ": cannot open");
  std::string line;
  int ln = 0;
  while (std::getline(in, line)) {
    ++ln;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::stringstream ss(line);
    std::string field;
    std::vector<std::string> fields;
    while (std::getline(ss, field, ',')) fields.push_back(field);
    if (fields.size() < 7)
      throw TrajectoryError(path + ":" + std::to_string(ln) + ": expected 7 columns (t[ns], w xyz, a xyz), got " +
                            std::to_string(fields.size()));
    AslImuSample s;
    try {
      size_t used = 0;
      s.stamp_ns = std::stoll(fields[0], &used);
      for (int i = 0; i < 3; ++i) s.gyro[i] = std::stod(fields[1 + i]);
      for (int i = 0; i < 3; ++i) s.accel[i] = std::stod(fields[4 + i]);
    } catch (const std::exception&) {
      throw TrajectoryError(path + ":" + std::to_string(ln) + ": a field is not a number");
    }
    if (!out.empty() && s.stamp_ns <= out.back().stamp_ns)
      throw TrajectoryError(path + ":" + std::to_string(ln) + ": timestamp does not increase");
    out.push_back(s);
  }
  return out;
}

std::vector<AslImage> listAslImages(const std::string& camera_dir) {
  const std::string data_dir = camera_dir + "/data";
  DIR* d = opendir(data_dir.c_str());
  if (!d) throw TrajectoryError(data_dir + ": cannot open image folder");
  std::vector<AslImage> out;
  while (dirent* e = readdir(d)) {
    const std::string name = e->d_name;
    const size_t dot = name.rfind('.');
    if (dot == std::string::npos || dot == 0) continue;
    const std::string stem = name.substr(0, dot);
    if (stem.find_first_not_of("0123456789") != std::string::npos) continue;
    out.push_back({std::stoll(stem), data_dir + "/" + name});
  }
  closedir(d);
  std::sort(out.begin(), out.end(), [](const AslImage& a, const AslImage& b) { return a.stamp_ns < b.stamp_ns; });
  return out;
}

AslSensorYaml readAslSensorYaml(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw TrajectoryError(path + ": cannot open");
  std::stringstream ss;
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("%YAML", 0) != 0) ss << line << "\n";  // OpenCV-style header
  YAML::Node y;
  try {
    y = YAML::Load(ss.str());
  } catch (const YAML::Exception& e) {
    throw TrajectoryError(path + ": invalid YAML: " + e.msg);
  }
  AslSensorYaml s;
  try {
    if (y["T_BS"]) {
      const auto d = y["T_BS"]["data"].as<std::vector<double>>();
      if (d.size() != 16) throw TrajectoryError(path + ": T_BS.data must hold 16 numbers");
      Eigen::Matrix4d M = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(d.data());
      s.T_body_sensor.linear() = Quat(Mat3(M.topLeftCorner<3, 3>())).normalized().toRotationMatrix();
      s.T_body_sensor.translation() = M.topRightCorner<3, 1>();
    }
    if (y["rate_hz"]) s.rate_hz = y["rate_hz"].as<double>();
    if (y["intrinsics"]) s.intrinsics = y["intrinsics"].as<std::vector<double>>();
    if (y["distortion_coefficients"]) s.distortion = y["distortion_coefficients"].as<std::vector<double>>();
    if (y["distortion_model"]) {
      const std::string model = y["distortion_model"].as<std::string>();
      if (model == "radial-tangential" || model == "radtan")
        s.distortion_model = DistortionModel::kRadtan;
      else if (model == "equidistant")
        s.distortion_model = DistortionModel::kEquidistant;
      else
        throw TrajectoryError(path + ": distortion_model '" + model + "' is neither radial-tangential nor equidistant");
    }
    if (y["resolution"]) {
      const auto r = y["resolution"].as<std::vector<int>>();
      if (r.size() == 2) s.width = r[0], s.height = r[1];
    }
    if (y["gyroscope_noise_density"]) s.gyro_noise_density = y["gyroscope_noise_density"].as<double>();
    if (y["gyroscope_random_walk"]) s.gyro_random_walk = y["gyroscope_random_walk"].as<double>();
    if (y["accelerometer_noise_density"]) s.accel_noise_density = y["accelerometer_noise_density"].as<double>();
    if (y["accelerometer_random_walk"]) s.accel_random_walk = y["accelerometer_random_walk"].as<double>();
  } catch (const YAML::Exception& e) {
    throw TrajectoryError(path + ": " + e.msg);
  }
  return s;
}

CameraRig aslCameraRig(const AslSensorYaml& s, const std::string& path) {
  if (s.intrinsics.size() != 4 || s.width <= 0 || s.height <= 0 || s.distortion.size() != 4)
    throw TrajectoryError(path +
                          ": not a pinhole camera's sensor.yaml (needs intrinsics [fu, fv, cu, cv], resolution "
                          "and four distortion_coefficients)");
  CameraRig c;
  c.width = s.width;
  c.height = s.height;
  c.fx = s.intrinsics[0];
  c.fy = s.intrinsics[1];
  c.cx = s.intrinsics[2];
  c.cy = s.intrinsics[3];
  c.distortion_model = s.distortion_model;
  std::copy(s.distortion.begin(), s.distortion.end(), c.distortion.begin());
  if (s.rate_hz > 0.0) c.rate_hz = s.rate_hz;
  c.T_I_C = s.T_body_sensor;
  return c;
}

}  // namespace livo
