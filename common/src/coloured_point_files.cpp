#include "livo/coloured_point_files.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string_view>

#include "livo/file_output.hpp"

namespace livo {

namespace {

bool readHeader(std::ifstream& in, const std::string& end_marker, std::vector<std::string>* lines) {
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines->push_back(line);
    if (line.rfind(end_marker, 0) == 0) return true;
    if (lines->size() > 200) return false;
  }
  return false;
}

uint32_t packRgb(const std::array<uint8_t, 3>& c) {
  return (uint32_t(c[0]) << 16) | (uint32_t(c[1]) << 8) | uint32_t(c[2]);
}

}  // namespace

namespace {
// The points after a header, streamed; false (with error) if the stream is not `count` points long.
bool writePoints(const std::string& path, const std::string& header, const PointStream& pts, bool pcd,
                 std::string* error) {
  size_t visited = 0;
  const bool ok = writeFileAtomically(
      path,
      [&](std::ostream& out) {
        out << header;
        char record[16];
        pts.visit([&](const Eigen::Vector3f& p, const std::array<uint8_t, 3>& c) {
          ++visited;
          std::memcpy(record, p.data(), 12);
          if (pcd) {
            const uint32_t rgb = packRgb(c);  // the bits of PCL's packed float rgb
            std::memcpy(record + 12, &rgb, 4);
          } else {
            std::memcpy(record + 12, c.data(), 3);
          }
          out.write(record, pcd ? 16 : 15);
        });
        return visited == pts.count && static_cast<bool>(out);
      },
      error);
  if (!ok && visited != pts.count && error)
    *error = path + ": the map gave " + std::to_string(visited) + " points, not the " + std::to_string(pts.count) +
             " the header announced";
  return ok;
}

PointStream streamOf(const ColouredPoints& pts) {
  return {pts.size(), [&pts](const auto& emit) {
            for (size_t i = 0; i < pts.size(); ++i) emit(pts.position[i], pts.rgb[i]);
          }};
}
}  // namespace

bool writePly(const std::string& path, const PointStream& pts, std::string* error) {
  std::ostringstream h;
  h << "ply\nformat binary_little_endian 1.0\ncomment livo-colour map, world frame W, metres\n"
    << "element vertex " << pts.count << "\nproperty float x\nproperty float y\nproperty float z\n"
    << "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  return writePoints(path, h.str(), pts, false, error);
}

bool writePcd(const std::string& path, const PointStream& pts, std::string* error) {
  std::ostringstream h;
  h << "# .PCD v0.7 - livo-colour map, world frame W\nVERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\n"
    << "TYPE F F F F\nCOUNT 1 1 1 1\nWIDTH " << pts.count << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << pts.count
    << "\nDATA binary\n";
  return writePoints(path, h.str(), pts, true, error);
}

bool writePly(const std::string& path, const ColouredPoints& pts, std::string* error) {
  return writePly(path, streamOf(pts), error);
}

bool writePcd(const std::string& path, const ColouredPoints& pts, std::string* error) {
  return writePcd(path, streamOf(pts), error);
}

bool readPly(const std::string& path, ColouredPoints* pts, std::string* error) {
  std::ifstream in(path, std::ios::binary);
  std::vector<std::string> header;
  if (!in || !readHeader(in, "end_header", &header) || header.empty() || header[0] != "ply") {
    *error = path + ": not a PLY file";
    return false;
  }
  size_t n = 0;
  std::string props;
  bool binary = false;
  for (const std::string& l : header) {
    std::istringstream s(l);
    std::string w, a, b;
    s >> w;
    if (w == "format") binary = (l.find("binary_little_endian") != std::string::npos);
    if (w == "element" && (s >> a >> n) && a != "vertex") n = 0;
    if (w == "property" && (s >> a >> b)) props += a + ":" + b + " ";
  }
  if (!binary || props != "float:x float:y float:z uchar:red uchar:green uchar:blue ") {
    *error = path + ": unsupported PLY layout (" + props + ")";
    return false;
  }
  pts->position.resize(n);
  pts->rgb.resize(n);
  for (size_t i = 0; i < n; ++i) {
    in.read(reinterpret_cast<char*>(pts->position[i].data()), 12);
    in.read(reinterpret_cast<char*>(pts->rgb[i].data()), 3);
  }
  if (!in) {
    *error = path + ": truncated";
    return false;
  }
  return true;
}

bool readPcd(const std::string& path, ColouredPoints* pts, std::string* error) {
  std::ifstream in(path, std::ios::binary);
  std::vector<std::string> header;
  if (!in || !readHeader(in, "DATA", &header)) {
    *error = path + ": not a PCD file";
    return false;
  }
  size_t n = 0;
  std::string fields, data;
  for (const std::string& l : header) {
    std::istringstream s(l);
    std::string w;
    s >> w;
    if (w == "FIELDS") fields = l;
    if (w == "POINTS") s >> n;
    if (w == "DATA") s >> data;
  }
  if (fields != "FIELDS x y z rgb" || data != "binary") {
    *error = path + ": unsupported PCD layout";
    return false;
  }
  pts->position.resize(n);
  pts->rgb.resize(n);
  for (size_t i = 0; i < n; ++i) {
    uint32_t c = 0;
    in.read(reinterpret_cast<char*>(pts->position[i].data()), 12);
    in.read(reinterpret_cast<char*>(&c), 4);
    pts->rgb[i] = {uint8_t(c >> 16), uint8_t(c >> 8), uint8_t(c)};
  }
  if (!in) {
    *error = path + ": truncated";
    return false;
  }
  return true;
}

}  // namespace livo
