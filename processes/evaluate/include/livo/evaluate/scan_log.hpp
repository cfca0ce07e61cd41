// Registered scans (livo.registered_scan_t) recorded in an LCM log, streamed for the ground map:
// the log is read on every pass, one message in memory at a time.
#pragma once

#include <stdexcept>
#include <string>

#include "livo/evaluate/ground_map.hpp"

namespace livo::evaluate {

class ScanLogError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ScanLogInput {
  std::string spec;  // as given
  std::string path;
  std::string channel;
};

/// "LOG" (channel `default_channel`) or "LOG:CHANNEL". Throws InputError for no such file, an
/// empty channel name, or a file that is not an LCM log.
ScanLogInput scanLogInput(const std::string& spec, const std::string& default_channel);

/// The scans on the input's channel, read from the log on every call. A call throws ScanLogError
/// naming the file, the event (1-based over the whole log) and the channel for a message of
/// another type than livo.registered_scan_t, one that does not decode, arrays that disagree with
/// num_points, a non-finite or unnormalisable pose, or a cloud not in the world frame W; and naming
/// the channels present when the channel has no message. Empty scans are passed on (the thickness
/// counts them); NaN points too (it skips and counts them).
GroundScanSource registeredScanSource(const ScanLogInput& input);

}  // namespace livo::evaluate
