#include "livo/import/input_calibration.hpp"

#include <algorithm>
#include <cctype>

#include "livo/import/import_report.hpp"

namespace livo::import {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

std::optional<CameraIntrinsics> intrinsicsFromCameraInfo(const RosCameraInfo& m, const std::string& topic) {
  if (m.K[0] == 0.0 || m.K[4] == 0.0) return std::nullopt;
  CameraIntrinsics c;
  c.width = static_cast<int>(m.width);
  c.height = static_cast<int>(m.height);
  c.fx = m.K[0];
  c.fy = m.K[4];
  c.cx = m.K[2];
  c.cy = m.K[5];
  c.source = "camera_info " + topic;
  const std::string model = lower(m.distortion_model);
  std::string note;
  if (model == "equidistant" || model == "fisheye" || model == "kannala_brandt") {
    c.distortion_model = DistortionModel::kEquidistant;
  } else {
    c.distortion_model = DistortionModel::kRadtan;
    if (model != "plumb_bob" && model != "radtan" && !(model.empty() && m.D.empty()))
      note = "distortion model '" + m.distortion_model +
             "' is not radtan or equidistant: its first four coefficients "
             "are written as radtan";
  }
  for (size_t i = 0; i < 4 && i < m.D.size(); ++i) c.distortion[i] = m.D[i];
  if (m.D.size() > 4) {
    bool extra = false;
    std::vector<double> rest(m.D.begin() + 4, m.D.end());
    for (double v : rest) extra = extra || v != 0.0;
    if (extra && note.empty())
      note = "D holds " + std::to_string(m.D.size()) + " coefficients; the rig holds four, so " + yamlList(rest) +
             " (k3 ...) is dropped";
  }
  if ((m.binning_x > 1 || m.binning_y > 1))
    note += std::string(note.empty() ? "" : "; ") + "binning " + std::to_string(m.binning_x) + "x" +
            std::to_string(m.binning_y) + ": the images are smaller than the calibration";
  if (m.roi_width || m.roi_height)
    note += std::string(note.empty() ? "" : "; ") + "a region of interest is set: the images are a crop";
  c.note = note;
  return c;
}

std::string extrinsicYaml(const Pose3& T) {
  const Vec3 t = T.translation();
  const std::string translation = yamlList({t.x(), t.y(), t.z()});
  if (T.linear() == Mat3::Identity()) return "{translation: " + translation + ", rpy_deg: [0, 0, 0]}";
  std::vector<double> v;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) v.push_back(T.matrix()(r, c));
  return yamlList(v);
}

}  // namespace livo::import
