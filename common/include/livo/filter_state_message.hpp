// The filter hand-off message (filter_state_t: STATE_PRIOR / STATE_POSTERIOR) and FilterState.
#pragma once

#include <cstdint>
#include <string>

#include "livo/filter_state.hpp"
#include "livo/filter_state_t.hpp"

namespace livo {

/// State and covariance at utime as a message (valid = 1, no iterations or measurements), with
/// the body rate at that time.
filter_state_t toFilterState(int64_t utime, const FilterState& x, const StateCovariance& P, int64_t request_id,
                             const std::string& source, const Vec3& body_rate = Vec3::Zero());
/// False for a message with non-finite numbers or a quaternion far from unit length.
bool fromFilterState(const filter_state_t& m, FilterState* x, StateCovariance* P);

}  // namespace livo
