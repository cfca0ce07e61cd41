#include "real_scans.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace livo::loop::testing {

Points readXyzBin(const std::string& path) {
  Points out;
  std::ifstream in2(path, std::ios::binary);
  if (!in2) throw std::runtime_error("cannot open " + path);
  in2.seekg(0, std::ios::end);
  const size_t n = static_cast<size_t>(in2.tellg()) / (3 * sizeof(float));
  in2.seekg(0);
  std::vector<float> buf(3 * n);
  in2.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(buf.size() * sizeof(float)));
  for (size_t i = 0; i < n; ++i) out.push_back(Vec3(buf[3 * i], buf[3 * i + 1], buf[3 * i + 2]));
  return out;
}

Points readFloatPly(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot open " + path);
  std::string line;
  size_t vertices = 0, properties = 0;
  while (std::getline(in, line)) {
    std::istringstream ss(line);
    std::string word;
    ss >> word;
    if (word == "element") {
      std::string what;
      ss >> what >> vertices;
    } else if (word == "property") {
      std::string type;
      ss >> type;
      if (type != "float") throw std::runtime_error(path + ": only float properties are supported");
      ++properties;
    } else if (word == "end_header") {
      break;
    }
  }
  std::vector<float> buf(vertices * properties);
  in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(buf.size() * sizeof(float)));
  if (!in) throw std::runtime_error(path + ": truncated");
  Points out;
  for (size_t i = 0; i < vertices; ++i)
    out.push_back(Vec3(buf[i * properties], buf[i * properties + 1], buf[i * properties + 2]));
  return out;
}

std::vector<Pose3> readGraphPoses(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  std::vector<Pose3> out;
  std::string name;
  double x, y, z, qx, qy, qz, qw;
  while (in >> name >> x >> y >> z >> qx >> qy >> qz >> qw) {
    Pose3 T = Pose3::Identity();
    T.linear() = Quat(qw, qx, qy, qz).normalized().toRotationMatrix();
    T.translation() = Vec3(x, y, z);
    out.push_back(T);
  }
  return out;
}

Pose3 readMatrix4(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  Eigen::Matrix4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) in >> m(r, c);
  Pose3 T(m);
  T.linear() = so3::normalize(T.linear());
  return T;
}

}  // namespace livo::loop::testing
