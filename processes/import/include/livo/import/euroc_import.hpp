// EuRoC / ASL folders -> LCM log: mav0/imu0/data.csv -> IMU, mav0/cam0 -> CAMERA and mav0/cam1 ->
// CAMERA_RIGHT (the images present in data/, not the csv rows), ground truth from
// mav0/state_groundtruth_estimate0/data.csv, a file given with --ground-truth, or a
// groundtruth.tum beside mav0. Calibration from each sensor.yaml goes into the metadata.
#pragma once

#include <string>

#include "livo/import/channel_names.hpp"
#include "livo/import/import_report.hpp"
#include "livo/import/sorted_log_writer.hpp"

namespace livo::import {

struct EurocImportOptions {
  ChannelNames channels;
  std::string ground_truth_file;  // overrides the folder's own ground truth
  bool decode_png = false;        // false: keep PNG compressed (ENCODING_PNG); true: GRAY8 / BGR8
  bool progress = true;
};

/// `root` is the dataset folder holding mav0/, or mav0 itself.
void importEuroc(const std::string& root, const EurocImportOptions& options, SortedLogWriter& writer,
                 ImportReport& report);

}  // namespace livo::import
