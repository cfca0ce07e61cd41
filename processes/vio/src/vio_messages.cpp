#include "livo/vio/vio_messages.hpp"

#include <cmath>

#include <Eigen/Cholesky>

#include "livo/filter_state_message.hpp"
#include "livo/messages.hpp"

namespace livo::vio {

bool priorFromMessage(const filter_state_t& m, FilterState* x, StateCovariance* P, std::string* why) {
  if (!fromFilterState(m, x, P)) {
    *why = "prior has non-finite numbers or a degenerate quaternion";
    return false;
  }
  *P = (0.5 * (*P + P->transpose())).eval();  // .eval(): the right side reads what the left writes
  if (!isUsableCovariance(*P)) {
    *why = "prior covariance is not positive definite";
    return false;
  }
  return true;
}

filter_state_t toPosterior(const filter_state_t& prior, const std::string& source, const FilterState& x,
                           const StateCovariance& P, bool valid, int iterations, int num_measurements) {
  filter_state_t m = toFilterState(prior.utime, x, P, prior.request_id, source);
  m.epoch = prior.epoch;
  m.correction_id = prior.correction_id;
  m.valid = valid ? 1 : 0;
  m.iterations = iterations;
  m.num_measurements = num_measurements;
  return m;
}

filter_state_t keptPrior(const filter_state_t& prior, const std::string& source) {
  filter_state_t m = prior;
  m.source = source;
  m.valid = 0;
  m.iterations = 0;
  m.num_measurements = 0;
  return m;
}

}  // namespace livo::vio
