#include "livo/import/import_job.hpp"

#include <iostream>
#include <ostream>
#include <stdexcept>

#include "livo/config.hpp"
#include "livo/import/rig_survey.hpp"
#include "livo/import/rosbag2_import.hpp"
#include "livo/import/rosbag_presets.hpp"
#include "livo/import/sorted_log_writer.hpp"
#include "livo/import/starter_rig_config.hpp"

namespace livo::import {

void applyPreset(ImportJob& job) {
  if (job.preset.empty()) return;
  const RosbagPreset* p = findRosbagPreset(job.preset);
  if (!p) {
    std::string names;
    for (const RosbagPreset& q : rosbagPresets()) names += " " + q.name;
    throw std::invalid_argument("unknown preset '" + job.preset + "' (known:" + names + ")");
  }
  if (job.format != "rosbag" && job.format != "rosbag2")
    throw std::invalid_argument("preset '" + job.preset + "' is for the rosbag and rosbag2 formats");
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

ChannelNames channelNamesOf(const SensorRig& rig, ChannelNames names) {
  names.imu = rig.channels.imu;
  names.lidar = rig.channels.lidar;
  names.camera = rig.channels.camera;
  names.depth = rig.channels.depth;
  names.ground_truth = rig.channels.ground_truth;
  return names;
}

namespace {

/// A preset's extrinsics, for the LiDAR and camera topics the preset names (another topic of the
/// dataset, e.g. NTU VIRAL's vertical LiDAR, has another extrinsic).
void presetCalibration(const RosbagPreset& p, const RosbagImportOptions& r, ImportReport& report) {
  InputCalibration& cal = report.calibration();
  cal.calibrated_rig = p.calibrated_rig;
  auto extrinsic = [&](const std::string& yaml) {
    const Pose3 T = Config::fromString("T: " + yaml, "preset " + p.name).get<Pose3>("T");
    return KnownExtrinsic{T, yaml, "preset " + p.name + ": " + p.extrinsics_source};
  };
  if (!p.T_I_L.empty() && r.lidar_topic == p.lidar_topic) cal.T_I_L = extrinsic(p.T_I_L);
  if (!p.T_I_C.empty() && r.camera_topic == p.camera_topic) cal.T_I_C = extrinsic(p.T_I_C);
}

void printRigFindings(const std::vector<RigFinding>& findings, const std::string& rig_file, std::ostream* summary,
                      bool quiet) {
  if (summary)
    *summary << "rig check against " << rig_file << ": " << (findings.empty() ? "the log fits it" : "") << "\n";
  for (const RigFinding& f : findings) {
    const std::string line = std::string(f.error ? "error: " : "warning: ") + f.message;
    if (summary) *summary << "  " << line << "\n";
    if (!quiet || f.error) std::cerr << "livo-import: rig check: " << line << "\n";
  }
}

/// The LCM type written on each channel.
std::map<std::string, std::string> channelTypes(const ChannelNames& ch) {
  return {{ch.imu, "livo.imu_t"},      {ch.lidar, "livo.point_cloud_t"},
          {ch.camera, "livo.image_t"}, {ch.camera_right, "livo.image_t"},
          {ch.depth, "livo.image_t"},  {ch.ground_truth, "livo.pose_t"}};
}

/// The preset's name, metadata and extrinsics into the report.
void reportPreset(const std::string& preset, const RosbagImportOptions& r, ImportReport& report) {
  report.metadataString("preset", preset);
  if (const RosbagPreset* p = findRosbagPreset(preset)) {
    for (const auto& [k, v] : p->metadata) report.metadata(k, v);
    presetCalibration(*p, r, report);
  }
}

/// The format's importer, writing to `writer` (an unknown format or an importer's exception is an
/// error in the report).
void runImporter(const ImportJob& job, SortedLogWriter& writer, ImportReport& report) {
  try {
    if (job.format == "rosbag") {
      RosbagImportOptions o = job.rosbag;
      o.channels = job.channels;
      o.progress = !job.quiet;
      importRosbag({job.input}, o, writer, report);
    } else if (job.format == "rosbag2") {
      RosbagImportOptions o = job.rosbag;
      o.channels = job.channels;
      o.progress = !job.quiet;
      importRosbag2(job.input, o, writer, report);
    } else if (job.format == "kitti") {
      KittiImportOptions o = job.kitti;
      o.channels = job.channels;
      o.progress = !job.quiet;
      importKitti(job.input, o, writer, report);
    } else if (job.format == "euroc") {
      EurocImportOptions o = job.euroc;
      o.channels = job.channels;
      o.progress = !job.quiet;
      importEuroc(job.input, o, writer, report);
    } else if (job.format == "ouster") {
      OusterImportOptions o = job.ouster;
      o.channels = job.channels;
      o.progress = !job.quiet;
      importOuster(job.input, o, writer, report);
    } else {
      report.error("unknown format '" + job.format + "' (rosbag, rosbag2, kitti, euroc, ouster)");
    }
  } catch (const std::exception& e) {
    report.error(e.what());
  }
}

/// What the starter rig config is written from: the job, the log's counts and survey, the
/// report's calibration and LiDAR layout.
StarterRigInputs starterRigInputs(const ImportJob& job, const ImportOutcome& out) {
  StarterRigInputs in;
  in.format = job.format;
  in.input = job.input;
  in.log = job.out;
  in.preset = job.preset;
  in.channels = job.channels;
  in.channel_counts = out.channel_counts;
  in.survey = out.survey;
  in.calibration = out.report.calibration();
  const std::string layout = out.report.metadataValue("lidar_point_layout");
  in.lidar_layout = layout.size() >= 2 && layout.front() == '"' ? layout.substr(1, layout.size() - 2) : layout;
  return in;
}

void writeStarterRig(const ImportJob& job, const StarterRigInputs& in, ImportReport& report, std::ostream* summary) {
  try {
    writeStarterRigConfig(job.rig_out, in);
    if (summary) *summary << "starter rig: " << job.rig_out << "\n";
  } catch (const std::exception& e) {
    report.error(e.what());
  }
}

}  // namespace

ImportOutcome runImport(const ImportJob& job, std::ostream* summary) {
  ImportOutcome out;
  ImportReport& report = out.report;
  report.setQuiet(job.quiet);
  const ChannelNames& ch = job.channels;
  out.channel_types = channelTypes(ch);
  SortedLogWriterOptions wo;
  wo.max_buffer_bytes = job.max_buffer_mb << 20;
  SortedLogWriter writer(job.out, wo);
  RigSurvey survey(ch);
  writer.setObserver(&survey);
  if (!job.preset.empty()) reportPreset(job.preset, job.rosbag, report);
  runImporter(job, writer, report);
  try {
    writer.finish();
    out.wrote_log = true;
    out.channel_counts = writer.counts();
    out.survey = survey.result();
    addSurveyMetadata(out.survey, ch, report);
    report.writeSidecar(job.out + ".meta.yaml", job.format, job.input, job.out, out.channel_counts);
  } catch (const std::exception& e) {
    report.error(e.what());
  }
  if (summary) {
    *summary << "livo-import " << job.format << " " << job.input << " -> " << job.out << "\n";
    report.print(*summary, out.channel_counts, out.channel_types);
    if (out.wrote_log) *summary << "sidecar: " << job.out << ".meta.yaml\n";
  }
  if (!out.wrote_log) return out;
  if (!job.rig_out.empty()) writeStarterRig(job, starterRigInputs(job, out), report, summary);
  if (job.rig) {
    out.rig_findings = checkRigAgainstLog(*job.rig, job.rig_file, out.survey, report.calibration(), ch);
    printRigFindings(out.rig_findings, job.rig_file, summary, job.quiet);
  }
  return out;
}

}  // namespace livo::import
