// What an import did: messages written per channel, records skipped with their reasons (the
// first occurrence of each reason is kept as an example naming file, record and field), read
// errors that stopped an input early, notes, and metadata that has no message type (written to
// the summary and to the `<log>.meta.yaml` sidecar); and the calibration the input's own metadata
// gives (input_calibration.hpp), for a starter rig.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "livo/import/input_calibration.hpp"

namespace livo::import {

class ImportReport {
 public:
  /// A record was not imported. `reason` groups counts ("unsupported ROS type foo/Bar");
  /// `where` names the file, record and field of this occurrence. The first occurrence of each
  /// reason is printed on stderr at once (unless quiet), later ones only counted.
  /// `warn` false: counted and listed in the summary only (e.g. topics nobody asked for).
  void skip(const std::string& reason, const std::string& where, int64_t count = 1, bool warn = true);
  /// Reading stopped early (truncated or corrupt input); what was read before is kept.
  void error(const std::string& message);
  /// Something worth telling that changed nothing's meaning (a unit conversion, a default used).
  void note(const std::string& message);
  /// A metadata entry; `yaml_value` is a YAML scalar or flow sequence/map, e.g. "[1, 2, 3]".
  void metadata(const std::string& key, const std::string& yaml_value);
  /// A string metadata entry (quoted in the sidecar).
  void metadataString(const std::string& key, const std::string& value);

  void setQuiet(bool quiet) { quiet_ = quiet; }

  /// What the input's metadata says of the sensors' calibration (CameraInfo, sensor.yaml, ...).
  InputCalibration& calibration() { return calibration_; }
  const InputCalibration& calibration() const { return calibration_; }

  struct Skipped {
    int64_t count = 0;
    std::string first_where;
  };
  const std::map<std::string, Skipped>& skipped() const { return skipped_; }
  int64_t skippedTotal() const;
  const std::vector<std::string>& errors() const { return errors_; }
  const std::vector<std::string>& notes() const { return notes_; }
  const std::vector<std::pair<std::string, std::string>>& metadataEntries() const { return metadata_; }
  /// The YAML value of a metadata key, or "" if absent.
  std::string metadataValue(const std::string& key) const;

  /// Summary table: per channel count (and type), skipped records, errors, notes, metadata.
  void print(std::ostream& os, const std::map<std::string, int64_t>& channel_counts,
             const std::map<std::string, std::string>& channel_types) const;
  /// Writes the sidecar: format, input, output, channel counts, metadata, skipped, errors.
  void writeSidecar(const std::string& path, const std::string& format, const std::string& input,
                    const std::string& log_path, const std::map<std::string, int64_t>& channel_counts) const;

 private:
  std::map<std::string, Skipped> skipped_;
  std::vector<std::string> errors_;
  std::vector<std::string> notes_;
  std::vector<std::pair<std::string, std::string>> metadata_;
  InputCalibration calibration_;
  bool quiet_ = false;
};

/// YAML double-quoted string.
std::string yamlQuote(const std::string& s);
/// Shortest decimal text that reads back as exactly `v`.
std::string yamlNumber(double v);
/// "[a, b, c]", each number exact (yamlNumber).
std::string yamlList(const std::vector<double>& values);

}  // namespace livo::import
