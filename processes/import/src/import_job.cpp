#include "livo/import/import_job.hpp"

#include <ostream>
#include <stdexcept>

#include "livo/import/rosbag_presets.hpp"
#include "livo/import/sorted_log_writer.hpp"

namespace livo::import {

void applyPreset(ImportJob& job) {
  if (job.preset.empty()) return;
  const RosbagPreset* p = findRosbagPreset(job.preset);
  if (!p) {
    std::string names;
    for (const RosbagPreset& q : rosbagPresets()) names += " " + q.name;
    throw std::invalid_argument("unknown preset '" + job.preset + "' (known:" + names + ")");
  }
  if (job.format != "rosbag") throw std::invalid_argument("preset '" + job.preset + "' is for the rosbag format");
  RosbagImportOptions& r = job.rosbag;
  auto fill = [](std::string& topic, const std::string& value) {
    if (topic.empty()) topic = value;
  };
  fill(r.imu_topic, p->imu_topic);
  fill(r.lidar_topic, p->lidar_topic);
  fill(r.camera_topic, p->camera_topic);
  fill(r.camera_right_topic, p->camera_right_topic);
  fill(r.depth_topic, p->depth_topic);
  if (r.ground_truth_file.empty()) fill(r.ground_truth_topic, p->ground_truth_topic);
  r.ground_truth_child_frame = p->ground_truth_child_frame;
  r.lidar.stamp = p->lidar_stamp;
  r.lidar.sweep_duration = p->sweep_duration;
  if (r.lidar.num_rings == 0) r.lidar.num_rings = p->num_rings;
}

ImportOutcome runImport(const ImportJob& job, std::ostream* summary) {
  ImportOutcome out;
  ImportReport& report = out.report;
  report.setQuiet(job.quiet);
  const ChannelNames& ch = job.channels;
  out.channel_types = {{ch.imu, "livo.imu_t"},
                       {ch.lidar, "livo.point_cloud_t"},
                       {ch.camera, "livo.image_t"},
                       {ch.camera_right, "livo.image_t"},
                       {ch.depth, "livo.image_t"},
                       {ch.ground_truth, "livo.pose_t"}};
  SortedLogWriterOptions wo;
  wo.max_buffer_bytes = job.max_buffer_mb << 20;
  SortedLogWriter writer(job.out, wo);
  if (!job.preset.empty()) {
    report.metadataString("preset", job.preset);
    if (const RosbagPreset* p = findRosbagPreset(job.preset))
      for (const auto& [k, v] : p->metadata) report.metadata(k, v);
  }
  try {
    if (job.format == "rosbag") {
      RosbagImportOptions o = job.rosbag;
      o.channels = ch;
      o.progress = !job.quiet;
      importRosbag({job.input}, o, writer, report);
    } else if (job.format == "kitti") {
      KittiImportOptions o = job.kitti;
      o.channels = ch;
      o.progress = !job.quiet;
      importKitti(job.input, o, writer, report);
    } else if (job.format == "euroc") {
      EurocImportOptions o = job.euroc;
      o.channels = ch;
      o.progress = !job.quiet;
      importEuroc(job.input, o, writer, report);
    } else if (job.format == "ouster") {
      OusterImportOptions o = job.ouster;
      o.channels = ch;
      o.progress = !job.quiet;
      importOuster(job.input, o, writer, report);
    } else {
      report.error("unknown format '" + job.format + "' (rosbag, kitti, euroc, ouster)");
    }
  } catch (const std::exception& e) {
    report.error(e.what());
  }
  try {
    writer.finish();
    out.wrote_log = true;
    out.channel_counts = writer.counts();
    report.writeSidecar(job.out + ".meta.yaml", job.format, job.input, job.out, out.channel_counts);
  } catch (const std::exception& e) {
    report.error(e.what());
  }
  if (summary) {
    *summary << "livo-import " << job.format << " " << job.input << " -> " << job.out << "\n";
    report.print(*summary, out.channel_counts, out.channel_types);
    if (out.wrote_log) *summary << "sidecar: " << job.out << ".meta.yaml\n";
  }
  return out;
}

}  // namespace livo::import
