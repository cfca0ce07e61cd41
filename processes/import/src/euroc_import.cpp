#include "livo/import/euroc_import.hpp"

#include <opencv2/imgcodecs.hpp>

#include "livo/asl_dataset.hpp"
#include "livo/import/file_utils.hpp"
#include "livo/import/ground_truth_file.hpp"
#include "livo/import/image_encoding.hpp"
#include "livo/import/progress_line.hpp"
#include "livo/import/stamp_conversion.hpp"
#include "livo/imu_t.hpp"

namespace livo::import {

namespace {

void sensorMetadata(const std::string& yaml, const std::string& prefix, ImportReport& report) {
  if (!isFile(yaml)) return;
  try {
    const AslSensorYaml s = readAslSensorYaml(yaml);
    const Eigen::Matrix4d T = s.T_body_sensor.matrix();
    const Eigen::Matrix4d Tr = T.transpose();  // column-major storage of the transpose = row-major
    const std::vector<double> t(Tr.data(), Tr.data() + 16);
    report.metadata(prefix + "_T_body_sensor", yamlList(t));
    if (!s.intrinsics.empty()) report.metadata(prefix + "_intrinsics_fu_fv_cu_cv", yamlList(s.intrinsics));
    if (!s.distortion.empty())
      report.metadata(prefix + "_distortion_" + distortionModelName(s.distortion_model), yamlList(s.distortion));
    if (s.width > 0) report.metadata(prefix + "_resolution", yamlList({double(s.width), double(s.height)}));
    if (s.gyro_noise_density > 0)
      report.metadata(prefix + "_noise_gyro_accel_density_walk",
                      yamlList({s.gyro_noise_density, s.accel_noise_density, s.gyro_random_walk, s.accel_random_walk}));
    // The starter rig's calibration (--rig-out): cam0 is the camera, the body is imu0.
    InputCalibration& cal = report.calibration();
    const std::string source = prefix + "/sensor.yaml";
    if (prefix == "imu0" && s.gyro_noise_density > 0)
      cal.imu_noise =
          ImuNoise{s.gyro_noise_density, s.gyro_random_walk, s.accel_noise_density, s.accel_random_walk, source};
    if (prefix == "cam0" && s.intrinsics.size() == 4 && s.width > 0) {
      CameraIntrinsics k;
      k.width = s.width;
      k.height = s.height;
      k.fx = s.intrinsics[0];
      k.fy = s.intrinsics[1];
      k.cx = s.intrinsics[2];
      k.cy = s.intrinsics[3];
      k.distortion_model = s.distortion_model;
      for (size_t i = 0; i < 4 && i < s.distortion.size(); ++i) k.distortion[i] = s.distortion[i];
      k.source = source;
      if (s.distortion.size() > 4) k.note = "the rig holds four distortion coefficients; the rest are dropped";
      cal.camera = k;
      cal.T_I_C = KnownExtrinsic{s.T_body_sensor, "", source + " T_BS"};
    }
  } catch (const std::exception& e) {
    report.skip("unreadable sensor.yaml (metadata not recorded)", e.what());
  }
}

void importCamera(const std::string& dir, const std::string& channel, const std::string& frame,
                  const EurocImportOptions& o, SortedLogWriter& writer, ImportReport& report) {
  std::vector<AslImage> images;
  try {
    images = listAslImages(dir);
  } catch (const std::exception& e) {
    report.error(e.what());
    return;
  }
  ProgressLine progress("livo-import " + dir, static_cast<double>(images.size()), "images", o.progress);
  for (size_t i = 0; i < images.size(); ++i) {
    const AslImage& a = images[i];
    progress.update(static_cast<double>(i));
    std::vector<uint8_t> bytes;
    try {
      bytes = readFileBytes(a.path);
    } catch (const std::exception& e) {
      report.skip("unreadable image file", e.what());
      continue;
    }
    const CompressedImageInfo info = sniffCompressedImage(bytes.data(), bytes.size());
    if (info.encoding < 0 || info.width <= 0) {
      report.skip("image file is not a readable PNG/JPEG", a.path);
      continue;
    }
    image_t img;
    img.utime = nsToUtime(a.stamp_ns);
    img.frame = frame;
    img.exposure_time = 0.0f;
    if (o.decode_png) {
      const cv::Mat m = cv::imdecode(bytes, cv::IMREAD_UNCHANGED);
      if (m.empty() || m.depth() != CV_8U || (m.channels() != 1 && m.channels() != 3)) {
        report.skip("image does not decode to 8-bit gray or colour", a.path);
        continue;
      }
      img.width = m.cols;
      img.height = m.rows;
      img.encoding = m.channels() == 1 ? image_t::ENCODING_GRAY8 : image_t::ENCODING_BGR8;
      img.row_stride = m.cols * m.channels();
      img.data.resize(static_cast<size_t>(img.row_stride) * m.rows);
      for (int r = 0; r < m.rows; ++r)
        std::copy(m.ptr<uint8_t>(r), m.ptr<uint8_t>(r) + img.row_stride, img.data.begin() + size_t(r) * img.row_stride);
    } else {
      img.width = info.width;
      img.height = info.height;
      img.encoding = info.encoding;
      img.row_stride = 0;
      img.data = std::move(bytes);
    }
    img.size = static_cast<int32_t>(img.data.size());
    writer.add(channel, img);
  }
}

}  // namespace

void importEuroc(const std::string& root, const EurocImportOptions& o, SortedLogWriter& writer, ImportReport& report) {
  const std::string mav0 = isDirectory(joinPath(root, "mav0")) ? joinPath(root, "mav0") : root;
  const std::string dataset_dir = mav0 == root ? root + "/.." : root;
  if (!isDirectory(joinPath(mav0, "imu0")) && !isDirectory(joinPath(mav0, "cam0"))) {
    report.error(root + ": not an EuRoC/ASL folder (no mav0/imu0 or mav0/cam0)");
    return;
  }
  // IMU
  const std::string imu_csv = joinPath(mav0, "imu0/data.csv");
  if (isFile(imu_csv)) {
    try {
      for (const AslImuSample& s : readAslImuCsv(imu_csv)) {
        imu_t m;
        m.utime = nsToUtime(s.stamp_ns);
        for (int i = 0; i < 3; ++i) {
          m.angular_velocity[i] = s.gyro[i];
          m.linear_acceleration[i] = s.accel[i];
        }
        writer.add(o.channels.imu, m);
      }
    } catch (const std::exception& e) {
      report.error(e.what());
    }
    sensorMetadata(joinPath(mav0, "imu0/sensor.yaml"), "imu0", report);
  } else {
    report.note(imu_csv + " not found: no IMU");
  }
  // Cameras
  const std::pair<const char*, const std::string*> cams[] = {{"cam0", &o.channels.camera},
                                                             {"cam1", &o.channels.camera_right}};
  for (const auto& [cam, channel] : cams) {
    const std::string dir = joinPath(mav0, cam);
    if (!isDirectory(joinPath(dir, "data"))) continue;
    importCamera(dir, *channel, std::string(cam) == "cam0" ? "C" : "C1", o, writer, report);
    sensorMetadata(joinPath(dir, "sensor.yaml"), cam, report);
  }
  // Ground truth
  std::string gt = o.ground_truth_file;
  if (gt.empty() && isFile(joinPath(mav0, "state_groundtruth_estimate0/data.csv")))
    gt = joinPath(mav0, "state_groundtruth_estimate0/data.csv");
  if (gt.empty() && isFile(joinPath(dataset_dir, "groundtruth.tum"))) {
    gt = joinPath(dataset_dir, "groundtruth.tum");
    report.note("ground truth from " + gt + " (no state_groundtruth_estimate0/data.csv)");
  }
  if (!gt.empty())
    importGroundTruthFile(gt, o.channels.ground_truth, "I", writer, report);
  else
    report.note("no ground truth found (give one with --ground-truth FILE)");
  report.metadataString("body_frame", "I = IMU (imu0); camera poses in the body: camN_T_body_sensor");
}

}  // namespace livo::import
