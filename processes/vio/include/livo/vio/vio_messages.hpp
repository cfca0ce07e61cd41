// Conversions between the LCM messages the VIO reads and writes and the core's types (the
// filter_state_t <-> FilterState conversion itself is common/filter_state_message.hpp).
#pragma once

#include <string>

#include "livo/filter_state.hpp"
#include "livo/filter_state_t.hpp"
#include "livo/loop_correction_t.hpp"

namespace livo::vio {

/// The state and covariance (symmetrised) of a STATE_PRIOR; false with the reason if a number is
/// not finite, the quaternion is degenerate or the pose covariance is not positive definite.
bool priorFromMessage(const filter_state_t& m, FilterState* x, StateCovariance* P, std::string* why);

/// A STATE_POSTERIOR answering `prior` (same utime and request id) with state x and covariance P.
filter_state_t toPosterior(const filter_state_t& prior, const std::string& source, const FilterState& x,
                           const StateCovariance& P, bool valid, int iterations, int num_measurements);
/// valid = 0: the prior's own numbers echoed.
filter_state_t keptPrior(const filter_state_t& prior, const std::string& source);

}  // namespace livo::vio
