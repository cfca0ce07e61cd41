#include "livo/import/rig_survey.hpp"

#include <algorithm>
#include <cmath>

#include "livo/import/image_encoding.hpp"

namespace livo::import {

namespace {

template <class T>
T median(std::vector<T> v) {
  if (v.empty()) return T{};
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

const char* encodingName(int8_t e) {
  switch (e) {
    case image_t::ENCODING_GRAY8: return "GRAY8";
    case image_t::ENCODING_RGB8: return "RGB8";
    case image_t::ENCODING_BGR8: return "BGR8";
    case image_t::ENCODING_JPEG: return "JPEG";
    case image_t::ENCODING_PNG: return "PNG";
    default: return "other";
  }
}

/// A rate as the sidecar writes it: whole hertz when within 0.5 % of one, else two decimals.
std::string rateText(double hz) {
  const double whole = std::round(hz);
  if (whole > 0 && std::abs(hz - whole) <= 0.005 * whole) return yamlNumber(whole);
  return yamlNumber(std::round(hz * 100.0) / 100.0);
}

}  // namespace

MeasuredRate measureRate(std::vector<int64_t> stamps) {
  MeasuredRate r;
  r.messages = static_cast<int64_t>(stamps.size());
  if (stamps.size() < 2) return r;
  std::sort(stamps.begin(), stamps.end());
  std::vector<int64_t> dt;
  dt.reserve(stamps.size() - 1);
  for (size_t i = 1; i < stamps.size(); ++i)
    if (stamps[i] > stamps[i - 1]) dt.push_back(stamps[i] - stamps[i - 1]);  // duplicates are no interval
  if (dt.empty()) return r;
  r.hz = 1e6 / static_cast<double>(median(dt));
  return r;
}

void RigSurvey::observe(const std::string& channel, const imu_t& m) {
  if (channel != channels_.imu) return;
  imu_stamps_.push_back(m.utime);
  const double a = std::sqrt(m.linear_acceleration[0] * m.linear_acceleration[0] +
                             m.linear_acceleration[1] * m.linear_acceleration[1] +
                             m.linear_acceleration[2] * m.linear_acceleration[2]);
  imu_accel_norms_.emplace_back(m.utime, static_cast<float>(a));
}

void RigSurvey::observe(const std::string& channel, const point_cloud_t& m) {
  if (channel != channels_.lidar) return;
  lidar_stamps_.push_back(m.utime);
  int rings = m.num_rings;
  if (rings <= 0)
    for (int16_t r : m.ring) rings = std::max(rings, r + 1);
  lidar_rings_ = std::max(lidar_rings_, rings);
  lidar_solid_state_ = lidar_solid_state_ || m.pattern == point_cloud_t::PATTERN_SOLID_STATE;
  if (!lidar_point_times_)
    lidar_point_times_ = std::any_of(m.time_offset.begin(), m.time_offset.end(), [](float t) { return t > 0.0f; });
  sweep_durations_.push_back(m.sweep_duration);
  sweep_points_.push_back(m.num_points);
}

void RigSurvey::observe(const std::string& channel, const image_t& m) {
  if (channel == channels_.depth) {
    ++depth_images_;
    return;
  }
  if (channel != channels_.camera) return;
  camera_stamps_.push_back(m.utime);
  if (camera_) {
    if (m.width != camera_->width || m.height != camera_->height) ++camera_->other_sizes;
    return;
  }
  CameraSurvey c;
  c.width = m.width;
  c.height = m.height;
  c.encoding = encodingName(m.encoding);
  if (m.encoding == image_t::ENCODING_GRAY8)
    c.channels = 1;
  else if (m.encoding == image_t::ENCODING_RGB8 || m.encoding == image_t::ENCODING_BGR8)
    c.channels = 3;
  else if (m.encoding == image_t::ENCODING_JPEG || m.encoding == image_t::ENCODING_PNG)
    c.channels = sniffCompressedImage(m.data.data(), m.data.size()).channels;
  camera_ = c;
}

void RigSurvey::observe(const std::string& channel, const pose_t&) {
  if (channel == channels_.ground_truth) ++ground_truth_poses_;
}

SensorSurvey RigSurvey::result() const {
  SensorSurvey s;
  if (!imu_stamps_.empty()) {
    ImuSurvey imu;
    imu.rate = measureRate(imu_stamps_);
    std::vector<std::pair<int64_t, float>> norms = imu_accel_norms_;
    std::sort(norms.begin(), norms.end());
    double sum = 0.0, sum2 = 0.0;
    for (const auto& [t, a] : norms) {
      if (t > norms.front().first + 1000000) break;
      sum += a;
      sum2 += static_cast<double>(a) * a;
      ++imu.first_second_samples;
    }
    const double n = static_cast<double>(imu.first_second_samples);
    imu.first_second_accel_norm = sum / n;
    imu.first_second_accel_std =
        std::sqrt(std::max(0.0, sum2 / n - imu.first_second_accel_norm * imu.first_second_accel_norm));
    s.imu = imu;
  }
  if (!lidar_stamps_.empty()) {
    LidarSurvey l;
    l.rate = measureRate(lidar_stamps_);
    l.rings = lidar_rings_;
    l.solid_state = lidar_solid_state_;
    l.sweep_duration_s = median(sweep_durations_);
    l.point_times = lidar_point_times_;
    l.median_points = median(sweep_points_);
    s.lidar = l;
  }
  if (camera_) {
    s.camera = *camera_;
    s.camera->rate = measureRate(camera_stamps_);
  }
  s.depth_images = depth_images_;
  s.ground_truth_poses = ground_truth_poses_;
  return s;
}

void addSurveyMetadata(const SensorSurvey& s, const ChannelNames& ch, ImportReport& report) {
  std::string rates;
  auto rate = [&](const std::string& channel, const MeasuredRate& r) {
    if (r.hz > 0) rates += (rates.empty() ? "" : ", ") + yamlQuote(channel) + ": " + rateText(r.hz);
  };
  if (s.imu) rate(ch.imu, s.imu->rate);
  if (s.lidar) rate(ch.lidar, s.lidar->rate);
  if (s.camera) rate(ch.camera, s.camera->rate);
  if (!rates.empty()) report.metadata("measured_rate_hz", "{" + rates + "}");
  if (s.imu && s.imu->first_second_samples > 1)
    report.metadata("imu_first_second_accel_norm",
                    "{mean: " + yamlNumber(std::round(s.imu->first_second_accel_norm * 1e4) / 1e4) +
                        ", std: " + yamlNumber(std::round(s.imu->first_second_accel_std * 1e4) / 1e4) + "}");
  if (s.lidar) {
    report.metadata("lidar_rings", std::to_string(s.lidar->rings));
    report.metadata("lidar_sweep_duration", yamlNumber(std::round(s.lidar->sweep_duration_s * 1e5) / 1e5));
  }
  if (s.camera) {
    report.metadata("camera_resolution",
                    "[" + std::to_string(s.camera->width) + ", " + std::to_string(s.camera->height) + "]");
    if (s.camera->channels) report.metadata("camera_color", s.camera->channels >= 3 ? "true" : "false");
  }
}

}  // namespace livo::import
