// A camera auto-exposure controller as camera drivers run it: it meters the mean grey level of the
// previous image and moves the total brightness (exposure x gain) toward the target in the log
// domain, a fraction `rate` of the error per frame; the new total is taken by the exposure time
// first and by the analogue gain only once the exposure is at its limit (less noise than gain).
#pragma once

#include <cstdint>
#include <vector>

namespace livo::sim {

struct AutoExposureOptions {
  bool enabled = false;
  double target_mean = 110.0;  // grey levels (0..255) of the mean image brightness
  double min_exposure = 2e-5;  // s
  double max_exposure = 0.02;  // s
  double min_gain = 1.0;       // linear analogue gain
  double max_gain = 16.0;
  double rate = 0.5;  // fraction of the log-brightness error corrected per frame, (0, 1]
};

struct ExposureSetting {
  double exposure = 0.005;  // s
  double gain = 1.0;        // linear
};

class AutoExposure {
 public:
  /// Starts at `initial_exposure` (clamped to the limits) and the lowest gain.
  AutoExposure(const AutoExposureOptions& options, double initial_exposure);

  /// The setting for the next image.
  const ExposureSetting& setting() const { return setting_; }
  /// Meters an image taken with setting() (its mean grey level) and sets the next setting.
  void update(double measured_mean);

  /// Mean of all samples of an 8-bit image.
  static double meanLevel(const std::vector<uint8_t>& data);

 private:
  AutoExposureOptions options_;
  ExposureSetting setting_;
};

}  // namespace livo::sim
