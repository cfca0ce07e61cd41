// Conversions between the LCM messages the VIO reads and writes and the core's types (the
// filter_state_t <-> FilterState conversion itself is common/filter_state_message.hpp).
#pragma once

#include <cstdint>
#include <string>

#include "livo/filter_state.hpp"
#include "livo/filter_state_t.hpp"
#include "livo/loop_correction_t.hpp"

namespace livo::vio {

/// A STATE_PRIOR as the node keeps it, decoded on arrival: what it refers to, the state and
/// covariance the update starts from and the body rate there, or why it cannot be used.
struct StatePrior {
  int64_t utime = 0;
  int64_t request_id = 0;
  int32_t epoch = 0;
  int64_t correction_id = 0;
  FilterState x;
  StateCovariance P = StateCovariance::Zero();
  Vec3 body_rate = Vec3::Zero();  // bias-corrected angular rate (the rolling shutter's rows, the time shift)
  std::string problem;            // non-empty: not usable (priorFromMessage's reason)
  filter_state_t message;         // as received: an answer valid = 0 echoes its numbers
};

/// Decodes a STATE_PRIOR (the one place the node reads one).
StatePrior decodePrior(const filter_state_t& m);

/// The state and covariance (symmetrised) of a STATE_PRIOR; false with the reason if a number is
/// not finite, the quaternion is degenerate or the pose covariance is not positive definite.
bool priorFromMessage(const filter_state_t& m, FilterState* x, StateCovariance* P, std::string* why);

/// A STATE_POSTERIOR answering `prior` (same utime and request id) with state x and covariance P.
filter_state_t toPosterior(const filter_state_t& prior, const std::string& source, const FilterState& x,
                           const StateCovariance& P, bool valid, int iterations, int num_measurements);
/// valid = 0: the prior's own numbers echoed.
filter_state_t keptPrior(const filter_state_t& prior, const std::string& source);

}  // namespace livo::vio
